"""The user's files (issue 12 item 6): one record written by Python (csv module, scipy.io) as
comma, semicolon, tab, whitespace, BOM, decimal-comma and MAT (one N×4 matrix) files gives the
same estimate through `lash estimate` (JSON identical but for nothing); columns by 0-based index
equal columns by name; non-finite rows are skipped and counted (an error with --strict); a gap in
t is reported; bad input exits 2 naming file:line:column; a MAT file without the variable lists
the variables it holds."""
import json, os, subprocess, sys, tempfile

import numpy as np
import scipy.io

lash = os.environ["LASH"]
fails = 0


def check(ok, what):
    global fails
    print(("ok   " if ok else "FAIL ") + what)
    fails += 0 if ok else 1


def run(*args):
    return subprocess.run([lash, *args], capture_output=True, text=True)


d = tempfile.mkdtemp()
base = os.path.join(d, "rec.csv")
r = run("simulate", os.path.join(os.environ["LASH_SOURCE_DIR"], "config/plants/thesis_eq34.toml"), "--input", "sine",
        "--amplitude", "600", "--frequency", "1", "--duration", "20", "--noise-variance", "200", "-o", base)
check(r.returncode == 0, f"simulate: {r.stderr.strip()}")
rows = [line.split(",") for line in open(base).read().splitlines()]
header, data = rows[0], rows[1:]
col = {n: i for i, n in enumerate(header)}
t, v, y = (np.array([float(x[col[n]]) for x in data]) for n in ("t", "v", "y"))
spare = np.arange(len(t), dtype=float)  # an extra column the reader must step over


def write(name, text, encoding="utf-8"):
    p = os.path.join(d, name)
    with open(p, "w", encoding=encoding, newline="") as f:
        f.write(text)
    return p


def table(sep, dec=".", crlf=False):
    nl = "\r\n" if crlf else "\n"
    out = [sep.join(["t", "spare", "v", "y"])]
    for a, b, c, e in zip(t, spare, v, y):
        out.append(sep.join(repr(float(x)).replace(".", dec) for x in (a, b, c, e)))
    return nl.join(out) + nl


files = {
    "comma": write("comma.csv", table(",")),
    "semicolon": write("semi.csv", table(";")),
    "tab": write("tab.tsv", table("\t")),
    "spaces": write("spaces.txt", "# logger export\n" + table("   ")),
    "bom_crlf": write("bom.csv", table(","), encoding="utf-8-sig"),
    "decimal_comma": write("dec.csv", table(";", dec=",", crlf=True)),
}
mat = os.path.join(d, "rec.mat")
scipy.io.savemat(mat, {"rec": np.column_stack([t, spare, v, y])})

args = ["--model", "deadzone-deadband", "--guess-left", "-350", "--guess-right", "350", "--json"]
ref = None
for name, path in files.items():
    r = run("estimate", path, "--columns", "t,v,y", *args)
    check(r.returncode == 0, f"{name}: exit {r.returncode} {r.stderr.strip()}")
    if r.returncode:
        continue
    j = json.loads(r.stdout)
    if ref is None:
        ref = j
        check(j["samples"] == len(t) and j["rows_skipped"] == 0 and j["gaps"] == 0, "comma: every row read")
    check(j == ref, f"{name}: the same estimate as the comma file")
for cols, path in (("0,2,3", files["semicolon"]), ("0,2,3", mat)):
    r = run("estimate", path, "--columns", cols, *args)
    j = json.loads(r.stdout) if r.returncode == 0 else None
    check(j == ref, f"--columns {cols} on {os.path.basename(path)}: the same estimate ({r.stderr.strip()})")

# Non-finite rows: skipped and counted, or an error with --strict.
lines = table(",").splitlines()
lines[5] = lines[5].split(",")[0] + ",0,nan,1"
lines[9] = lines[9].split(",")[0] + ",0,1,"
p = write("nan.csv", "\n".join(lines) + "\n")
r = run("estimate", p, *args)
j = json.loads(r.stdout) if r.returncode == 0 else {}
check(j.get("rows_skipped") == 2 and j.get("samples") == len(t) - 2, f"two non-finite rows skipped: {j.get('rows_skipped')}")
r = run("estimate", p, "--strict", *args)
check(r.returncode == 2 and "nan.csv:6: 'v'" in r.stderr, f"--strict: exit {r.returncode} {r.stderr.strip()}")

# A 10 s gap is found and reported, never averaged into dt.
tg = t.copy()
tg[len(t) // 2:] += 10.0
p = write("gap.csv", "t,v,y\n" + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(tg, v, y)))
r = run("estimate", p, *args)
j = json.loads(r.stdout) if r.returncode == 0 else {}
check(j.get("gaps") == 1, f"one gap reported: {j.get('gaps')}")
r = run("estimate", p, *args[:-1])
check("dt = 0.005 s" in r.stdout and "data: 1 gaps in t" in r.stdout, f"text report: {r.stdout.splitlines()[:2]}")

# Bad input: exit 2, file:line:column.
p = write("junk.csv", "t;v;y\n0;1;2\n0,005;x1;2\n")
r = run("estimate", p, *args)
check(r.returncode == 2 and "junk.csv:3: 'v'" in r.stderr, f"junk cell: {r.stderr.strip()}")
r = run("estimate", files["comma"], "--columns", "t,v,t", *args)
check(r.returncode == 2 and "chosen twice" in r.stderr, f"duplicate column: {r.stderr.strip()}")
r = run("estimate", mat, "--columns", "time,v,y", *args)
check(r.returncode == 2 and "rec.mat" in r.stderr and "it holds: rec" in r.stderr, f"MAT missing variable: {r.stderr.strip()}")
sys.exit(1 if fails else 0)
