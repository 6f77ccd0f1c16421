"""`lash simulate` output contract: header begins t,v,y; every number is the shortest
text that parses back to the same double; t_k = k*T; the eq-34 plant's first samples
match a hand computation."""
import math, os, subprocess, sys, tempfile

lash, src = os.environ["LASH"], os.environ["LASH_SOURCE_DIR"]
with tempfile.TemporaryDirectory() as d:
    out = os.path.join(d, "o.csv")
    subprocess.run([lash, "simulate", f"{src}/config/plants/thesis_eq34.toml", "--input", "sine",
                    "--amplitude", "600", "--frequency", "1", "--duration", "200", "-o", out], check=True)
    lines = open(out).read().splitlines()
    header = lines[0].split(",")
    assert header[:3] == ["t", "v", "y"], header
    assert len(lines) == 1 + 40000, len(lines)
    def sig_digits(cell):
        m = cell.lstrip("-").split("e")[0].replace(".", "").lstrip("0").rstrip("0")
        return max(1, len(m))
    def shortest(x):  # fewest significant digits that parse back to x
        return next(p for p in range(1, 18) if float(f"{x:.{p - 1}e}") == x)
    checked = 0
    for line in lines[1:3000] + lines[-5:]:
        for cell in line.split(","):
            x = float(cell)
            assert sig_digits(cell) == shortest(x), (cell, shortest(x))
            checked += 1
    rows = [list(map(float, l.split(","))) for l in lines[1:]]
    T = 0.005
    for k in (0, 1, 777, 39999):
        assert rows[k][0] == k * T, (k, rows[k][0])
        assert rows[k][1] == 600 * math.sin(k * T), (k, rows[k][1])
    # hand computation of eq. (34): u = DZ(v), w(k) = 0.96 w(k-1) + 0.1 u(k-1) while v >= 0, y = DB_30(w)
    w = y = u_prev = 0.0
    for k in range(0, 120):
        v = 600 * math.sin(k * T)
        w = 0.96 * w + 0.1 * u_prev   # v(k-1) >= 0 over this stretch -> right side
        u_prev = v - 200 if v > 200 else 0.0
        if w > y + 30: y = w - 30
        elif w < y - 30: y = w + 30
        assert abs(rows[k][2] - y) <= 1e-12 * max(1.0, abs(y)), (k, rows[k][2], y)
    print("header", header, "rows", len(rows), "cells checked", checked, "y[119] =", rows[119][2])
