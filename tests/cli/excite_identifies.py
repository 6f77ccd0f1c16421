#!/usr/bin/env python3
"""lash excite (default kind, sine) -> lash simulate --input-file -> lash estimate --model
deadzone-deadband: every parameter (a1, b1, c, d of both sides) within 5 % of the plant file's
values (the truth is read from the plant file, tests/data/plants/issue30_dz_g_db.toml: edges
-150/+220, given to lash excite only as the rough bounds -200,300). Also: the file has the
header t,v, t = k dt, and v spans twice the bounds."""
import csv, os, sys, tempfile

SRC = os.environ["LASH_SOURCE_DIR"]
sys.path.insert(0, os.path.join(SRC, "scripts"))
from excite_measure import identify, truth  # noqa: E402

LASH = os.environ["LASH"]
PLANT = os.path.join(SRC, "tests/data/plants/issue30_dz_g_db.toml")
fail = 0


def check(cond, what):
    global fail
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        fail = 1


with tempfile.TemporaryDirectory() as d:
    j, worst, err = identify(LASH, PLANT, "-200,300", "sine", 120, d)
    check("warning" not in err, f"no warning for the default kind: {err.strip()}")
    rows = list(csv.reader(open(os.path.join(d, "in.csv"))))
    check(rows[0] == ["t", "v"] and len(rows) == 1 + 24000, f"header t,v and 24000 rows ({len(rows) - 1})")
    t = [float(r[0]) for r in rows[1:]]
    v = [float(r[1]) for r in rows[1:]]
    check(all(t[k] == k * 0.005 for k in range(len(t))), "t = k dt")
    check(-400.0 <= min(v) < -399.0 and 599.0 < max(v) <= 600.0, f"v spans twice the bounds: [{min(v)}, {max(v)}]")
    tr = truth(PLANT)
    for side in ("right", "left"):
        check(j[side]["identified"], f"{side} identified ({j[side]['reason']})")
        for k, want in tr[side].items():
            got = j[side][k]
            check(got is not None and abs(got - want) <= 0.05 * abs(want), f"{side} {k} = {got} within 5 % of {want}")
    check(worst <= 0.05, f"worst relative error {100 * worst:.2f} %")
sys.exit(fail)
