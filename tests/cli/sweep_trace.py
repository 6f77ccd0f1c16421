#!/usr/bin/env python3
"""`lash sweep --trace RUN FILE` writes every sample of one run. Checked against an identity:
the NRMSE recomputed here from the trace's y and y_sim over the campaign window,
RMS(y - y_sim) / max|y|, equals the run's `nrmse` in the results CSV, and the trace's last
parameters are the run's reported ones. On the valve (E4) and the coupled carts (E5, where y
is the free-cart velocity). A RUN that does not exist is an input error (exit 2, no file)."""
import csv, math, os, subprocess, sys, tempfile

LASH = os.environ["LASH"]
SRC = os.environ["LASH_SOURCE_DIR"]
fail = 0


def check(campaign, run, dt, window):
    global fail
    with tempfile.TemporaryDirectory() as d:
        res, tr = os.path.join(d, "r.csv"), os.path.join(d, "t.csv")
        subprocess.run([LASH, "sweep", os.path.join(SRC, "config/campaigns", campaign), "-q", "-o", res,
                        "--trace", str(run), tr], check=True, capture_output=True)
        row = [r for r in csv.DictReader(open(res)) if int(r["run"]) == run][0]
        t = list(csv.DictReader(open(tr)))
    y = [float(r["y"]) for r in t]
    ys = [float(r["y_sim"]) for r in t]
    k0, k1 = round(window[0] / dt), min(len(y) - 1, round(window[1] / dt))
    ks = range(k0, k1 + 1)
    nrmse = math.sqrt(sum((y[k] - ys[k]) ** 2 for k in ks) / len(ks)) / max(abs(y[k]) for k in ks)
    want = float(row["nrmse"])
    ok = len(t) == round(30.0 / dt) and abs(nrmse - want) <= 1e-12 * max(1.0, want)
    for s in ("r", "l"):
        for p in ("a1", "b1", "c"):
            a, b = float(t[-1][f"{p}_{s}"]), float(row[f"{p}_{s}"])
            if row[f"identified_{s}"] == "1":
                ok &= a == b
    print(f"{'ok  ' if ok else 'FAIL'} {campaign} run {run}: {len(t)} samples, NRMSE from the trace {nrmse!r}, "
          f"results {want!r}")
    fail |= not ok


check("e4_pilot_valve_lash.toml", 1, 0.005, (7.5, 30.0))
check("e4_pilot_valve_lash.toml", 100, 0.005, (7.5, 30.0))
check("e5_coupled_carts_lash.toml", 0, 0.001, (8.0, 30.0))
with tempfile.TemporaryDirectory() as d:
    r = subprocess.run([LASH, "sweep", os.path.join(SRC, "config/campaigns/e4_pilot_valve_lash.toml"), "-q", "-o",
                        os.path.join(d, "r.csv"), "--trace", "164", os.path.join(d, "t.csv")],
                       capture_output=True, text=True)
    ok = r.returncode == 2 and "'--trace'" in r.stderr and "0..163" in r.stderr and not os.listdir(d)
    print(f"{'ok  ' if ok else 'FAIL'} --trace 164 on a 164-run campaign: exit {r.returncode}: {r.stderr.strip()}")
    fail |= not ok
sys.exit(1 if fail else 0)
