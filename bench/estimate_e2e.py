#!/usr/bin/env python3
"""`lash estimate` end to end against the sum of its parts, in one run (issue 28 item 4).

  bench/estimate_e2e.py [--rows N] [--lash PATH] [--floor PATH] [--repeat R] [--keep FILE]

1. generates a t,v,y CSV of N rows (default 10^7) with `lash simulate` (the E1 plant of thesis
   eq. 34, a 600 sine, noise of variance 4 on y);
2. times the read+parse floor, bench/estimate_floor.cpp (reads the file in 1 MiB blocks and
   parses the three columns with std::from_chars, nothing else) [wall s];
3. times `lash estimate FILE --model deadzone-deadband --json --timing` whole-process (wall s
   and peak RSS of the child, getrusage) and reads the estimator's own time from --timing;
4. prints  ratio = whole-process / (floor + estimator)  (goal <= 1.3)
   and     peak RSS / needed columns (3 x 8 B x rows)  (goal <= 1.3).
Each figure is the median of R runs (default 3). Paths default to build/bin/lash and
build/bin/lash_estimate_floor (cmake --build build --target lash lash_estimate_floor).
"""
import argparse, os, re, resource, statistics, subprocess, sys, tempfile, time

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
ap = argparse.ArgumentParser()
ap.add_argument("--rows", type=int, default=10_000_000)
ap.add_argument("--lash", default=os.path.join(root, "build", "bin", "lash"))
ap.add_argument("--floor", default=os.path.join(root, "build", "bin", "lash_estimate_floor"))
ap.add_argument("--repeat", type=int, default=3)
ap.add_argument("--keep", help="use (or create and keep) this CSV instead of a temporary one")
a = ap.parse_args()


def timed(cmd):
    """wall time [s], peak RSS [bytes] (this child alone: run in a fresh helper), stdout, stderr"""
    wrapper = ("import resource,subprocess,sys,time;t=time.perf_counter();"
               "p=subprocess.run(sys.argv[1:],capture_output=True,text=True);w=time.perf_counter()-t;"
               "sys.stdout.write(p.stdout);sys.stderr.write(p.stderr);"
               "print('@@',w,resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss,p.returncode,file=sys.stderr)")
    p = subprocess.run([sys.executable, "-c", wrapper] + cmd, capture_output=True, text=True)
    m = re.search(r"@@ (\S+) (\d+) (-?\d+)\s*$", p.stderr)
    if not m or m.group(3) != "0":
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    return float(m.group(1)), int(m.group(2)) * 1024, p.stdout, p.stderr


with tempfile.TemporaryDirectory() as d:
    csv = a.keep or os.path.join(d, "e1.csv")
    if not (a.keep and os.path.exists(csv)):
        subprocess.run([a.lash, "simulate", os.path.join(root, "config", "plants", "thesis_eq34.toml"),
                        "--amplitude", "600", "--duration", str(a.rows * 0.005), "--noise-variance", "4",
                        "--seed", "1", "-o", csv], check=True, capture_output=True)
    rows = sum(1 for _ in open(csv, "rb")) - 1
    floor_s, est_s, e2e_s, rss = [], [], [], []
    for _ in range(a.repeat):
        w, _, out, _ = timed([a.floor, csv])
        if int(out.split()[1]) != rows:
            sys.exit(f"floor read {out.split()[1]} rows, the file has {rows}")
        floor_s.append(w)
        w, r, out, err = timed([a.lash, "estimate", csv, "--model", "deadzone-deadband", "--json", "--timing"])
        m = re.search(r"estimator ran (\d+) samples in (\S+) s", err)
        if not m or int(m.group(1)) != rows:
            sys.exit(f"no --timing line for {rows} samples: {err}")
        est_s.append(float(m.group(2)))
        e2e_s.append(w)
        rss.append(r)
    f, e, w, r = (statistics.median(x) for x in (floor_s, est_s, e2e_s, rss))
    ns = lambda s: s / rows * 1e9
    needed = 24 * rows
    print(f"rows {rows} (median of {a.repeat} runs)")
    print(f"read+parse floor   {ns(f):7.1f} ns/row   ({f:.3f} s)")
    print(f"estimator alone    {ns(e):7.1f} ns/row   ({e:.3f} s, lash estimate --timing)")
    print(f"lash estimate      {ns(w):7.1f} ns/row   ({w:.3f} s whole process)")
    print(f"ratio lash estimate / (floor + estimator) = {w / (f + e):.3f} (goal <= 1.3)")
    print(f"peak RSS {r / 1e6:.1f} MB = {r / needed:.2f} x the needed columns (3 x 8 B x rows = {needed / 1e6:.0f} MB; goal <= 1.3)")
