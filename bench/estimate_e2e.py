#!/usr/bin/env python3
"""`lash estimate` end to end against the sum of its parts, in one run (issue 28 item 4).

  bench/estimate_e2e.py [--rows N] [--lash PATH] [--floor PATH] [--repeat R] [--keep FILE]

1. generates a t,v,y CSV of N rows (default 10^7) with `lash simulate` (the E1 plant of thesis
   eq. 34, a 600 sine, noise of variance 4 on y);
2. times the read+parse floor, bench/estimate_floor.cpp (reads the file in 1 MiB blocks and
   parses the three columns with std::from_chars, nothing else) [wall s];
3. times `lash estimate FILE --model deadzone-deadband --json --timing` whole-process (wall s
   and peak RSS of the child, getrusage) and reads the default estimator's own time from --timing
   (the settings chosen from the data, the outlier gate, the guess search and the final run);
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
    """wall time [s], CPU time (user + system) [s], peak RSS [bytes] of the child (run from a fresh
    helper process, so that getrusage(RUSAGE_CHILDREN) sees this child alone), stdout, stderr"""
    wrapper = ("import resource,subprocess,sys,time;t=time.perf_counter();"
               "p=subprocess.run(sys.argv[1:],capture_output=True,text=True);w=time.perf_counter()-t;"
               "sys.stdout.write(p.stdout);sys.stderr.write(p.stderr);r=resource.getrusage(resource.RUSAGE_CHILDREN);"
               "print('@@',w,r.ru_utime+r.ru_stime,r.ru_maxrss,p.returncode,file=sys.stderr)")
    p = subprocess.run([sys.executable, "-c", wrapper] + cmd, capture_output=True, text=True)
    m = re.search(r"@@ (\S+) (\S+) (\d+) (-?\d+)\s*$", p.stderr)
    if not m or m.group(4) != "0":
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    return float(m.group(1)), float(m.group(2)), int(m.group(3)) * 1024, p.stdout, p.stderr


with tempfile.TemporaryDirectory() as d:
    csv = a.keep or os.path.join(d, "e1.csv")
    if not (a.keep and os.path.exists(csv)):
        subprocess.run([a.lash, "simulate", os.path.join(root, "config", "plants", "thesis_eq34.toml"),
                        "--amplitude", "600", "--duration", str(a.rows * 0.005), "--noise-variance", "4",
                        "--seed", "1", "-o", csv], check=True, capture_output=True)
    rows = sum(1 for _ in open(csv, "rb")) - 1
    runs = {k: [] for k in ("floor", "floor_cpu", "est", "est_cpu", "e2e", "e2e_cpu", "rss", "floor_rss")}
    for _ in range(a.repeat):
        w, c, r, out, _ = timed([a.floor, csv])
        if int(out.split()[1]) != rows:
            sys.exit(f"floor read {out.split()[1]} rows, the file has {rows}")
        runs["floor"].append(w)
        runs["floor_cpu"].append(c)
        runs["floor_rss"].append(r)
        w, c, r, out, err = timed([a.lash, "estimate", csv, "--model", "deadzone-deadband", "--json", "--timing"])
        m = re.search(r"estimator ran (\d+) samples in (\S+) s .*CPU time (\S+) s", err)
        if not m or int(m.group(1)) != rows:
            sys.exit(f"no --timing line for {rows} samples: {err}")
        runs["est"].append(float(m.group(2)))
        runs["est_cpu"].append(float(m.group(3)))
        runs["e2e"].append(w)
        runs["e2e_cpu"].append(c)
        runs["rss"].append(r)
    md = {k: statistics.median(v) for k, v in runs.items()}
    ns = lambda s: s / rows * 1e9
    needed = 24 * rows
    print(f"rows {rows} (median of {a.repeat} runs; wall time, and CPU time, which a loaded machine inflates less)")
    for what, sfx in (("wall", ""), ("cpu ", "_cpu")):
        f, e, w = md["floor" + sfx], md["est" + sfx], md["e2e" + sfx]
        print(f"{what}: floor {ns(f):6.1f} + estimator {ns(e):6.1f} = {ns(f + e):6.1f} ns/row; "
              f"lash estimate {ns(w):6.1f} ns/row; ratio lash estimate / (floor + estimator) = {w / (f + e):.3f} (goal <= 1.3)")
    r = md["rss"]
    print(f"floor peak RSS {md['floor_rss'] / 1e6:.1f} MB")
    print(f"peak RSS {r / 1e6:.1f} MB = {r / needed:.2f} x the needed columns (3 x 8 B x rows = {needed / 1e6:.0f} MB; goal <= 1.3)")
