#!/usr/bin/env python3
"""Must-show checks of issue 4 on the virtual rigs (docs/sweep.md), recomputed from the CSV:
 - E3 >= 94 % and E4 >= 91 % of runs with NRMSE < 10 % (lash's settings; the thesis's settings
   are run too and their shares printed),
 - E5 (issue 4: "NRMSE <= 5 % for sine and triangle at 2 rad/s"): with lash's settings every
   sine and triangle run at 2 rad/s (3, 4, 6 V, all 3 repeats) has NRMSE <= 5 %; with the
   thesis's settings the 6 V runs do (all repeats) and the 2 rad/s table is printed,
 - on every run of every campaign: c_l <= c_r (and c_l <= 0 <= c_r) or the side is reported
   not identified; no identified parameter (a1, b1, c, K; E5 also tau and d) is non-finite;
   E5: every NRMSE is finite (the free run never blows up),
 - summary JSON agrees with the CSV (share recomputed here), one row per run."""
import csv, json, math, os, subprocess, sys, tempfile

lash = os.environ["LASH"]
src = os.environ["LASH_SOURCE_DIR"]
fail = []


def sweep(name):
    d = tempfile.mkdtemp()
    out = os.path.join(d, name + ".csv")
    p = subprocess.run([lash, "sweep", os.path.join(src, "config", "campaigns", name + ".toml"), "--json", "-o", out],
                       capture_output=True, text=True)
    if p.returncode != 0:
        print(p.stderr)
        sys.exit(1)
    summary = json.loads(p.stdout)
    rows = list(csv.DictReader(open(out)))
    return summary, rows, p.stderr


def f(x):
    return float(x) if x not in ("nan", "") else math.nan


def check_common(name, summary, rows, expected_runs):
    if len(rows) != expected_runs:
        fail.append(f"{name}: {len(rows)} CSV rows, want {expected_runs}")
    good = sum(1 for r in rows if f(r["nrmse"]) < 0.10)
    share = good / len(rows)
    if abs(share - summary["share_good"]) > 1e-12 or good != summary["good"]:
        fail.append(f"{name}: summary share {summary['share_good']} != CSV {share}")
    if summary["identified_with_cl_gt_cr"] != 0:
        fail.append(f"{name}: {summary['identified_with_cl_gt_cr']} runs present c_l > c_r as identified")
    for r in rows:
        cr, cl = f(r["c_r"]), f(r["c_l"])
        if r["identified_r"] == "1" and not cr >= 0:
            fail.append(f"{name} run {r['run']}: identified c_r = {cr} < 0")
        if r["identified_l"] == "1" and not cl <= 0:
            fail.append(f"{name} run {r['run']}: identified c_l = {cl} > 0")
        if r["identified_r"] == "1" and r["identified_l"] == "1" and not cl <= cr:
            fail.append(f"{name} run {r['run']}: identified c_l = {cl} > c_r = {cr}")
        for sd in ("r", "l"):
            if r["identified_" + sd] == "1":
                bad = [k for k in ("a1", "b1", "c", "K") if not math.isfinite(f(r[f"{k}_{sd}"]))]
                if bad:
                    fail.append(f"{name} run {r['run']}: identified side {sd} with non-finite {bad}")
    # identified sides within 5 % of the true K, tau, c (and d where identified), recomputed here;
    # the valve's tau is not a rig constant (it falls with pressure: docs/rigs.md), so its sides
    # are scored on K and c
    with_tau = summary["rig"] != "pilot_valve"
    within = above = ident = 0
    for r in rows:
        for sd in ("r", "l"):
            if r["identified_" + sd] != "1":
                continue
            ident += 1
            pairs = [(f"K_{sd}", f"true_K_{sd}"), (f"c_{sd}", f"true_c_{sd}")]
            if with_tau:
                pairs.append((f"tau_{sd}_s", f"true_tau_{sd}_s"))
            if r["identified_d"] == "1":
                pairs.append(("d", "true_d"))
            errs = [abs(f(r[a]) - f(r[b])) / abs(f(r[b])) for a, b in pairs]
            e = math.inf if any(math.isnan(x) for x in errs) else max(errs)  # a NaN (no tau) is not within
            within += e <= 0.05
            above += not e <= 0.20
    if (within, above) != (summary["sides_within_tolerance"], summary["sides_above_20pct"]):
        fail.append(f"{name}: summary sides within 5 % / above 20 % {summary['sides_within_tolerance']}/"
                    f"{summary['sides_above_20pct']} != CSV {within}/{above}")
    print(f"{name}: identified sides within 5 % of the true K, {'tau, ' if with_tau else ''}c: {within}/{ident}"
          f" = {100 * within / max(ident, 1):.1f} %, above 20 %: {above} (issue 24 goal >= 95 % and 0: not asserted)")
    per = {w: f"{v['good']}/{v['runs']}" for w, v in summary["per_waveform"].items()}
    pc = lambda x: "nan" if x is None else f"{100 * x:.2f}"
    print(f"{name}: {good}/{len(rows)} = {100 * share:.1f} % NRMSE < 10 %  per waveform {per}  "
          f"median {pc(summary['median_nrmse'])} %  worst {pc(summary['worst_nrmse'])} % ({summary['worst_run']})  "
          f"params within 5 %: {summary['params_within_tolerance']}/{summary['params_checked']}")
    return share, ident


s, rows, err = sweep("e3_motor_cart")
check_common("E3 thesis settings", s, rows, 147)
if "147/147 runs" not in err:
    fail.append("E3: no progress bar with 147/147 runs on stderr")
s, rows, _ = sweep("e3_motor_cart_lash")
share, ident = check_common("E3 lash settings", s, rows, 147)
if share < 0.94:
    fail.append("E3 (lash settings): share of good runs below the thesis's 94 %")
# A regression floor, not issue 24's goal (>= 95 %, none above 20 %: docs/sweep.md): the 4-point
# moving average on the encoder velocity gave 200 of 294 identified sides within 5 % and 11 above
# 20 % (10-point: 160 and 63; unfiltered: 76 of 288 and 116); verdict check 2's held-level rule
# then reports the square waves' sides not_excited (they hold +-A on >= 92 % of a side's updates)
# and leaves 169 of 198 within 5 %, 1 above 20 %. The counts were checked against the CSV in
# check_common.
if not (s["sides_within_tolerance"] >= 0.84 * ident and s["sides_above_20pct"] <= 1):
    fail.append(f"E3 (lash settings): {s['sides_within_tolerance']}/{ident} identified sides within 5 %, "
                f"{s['sides_above_20pct']} above 20 % (floor: 84 % and at most 1)")
square_ident = [r["run"] for r in rows if r["waveform"] == "square" and "1" in (r["identified_r"], r["identified_l"])]
other_open = [r["run"] for r in rows if r["waveform"] != "square" and "1" not in (r["identified_r"], r["identified_l"])]
if square_ident or other_open:
    fail.append(f"E3 (lash settings): square-wave runs with a side identified {square_ident[:5]} "
                f"or other runs with none {other_open[:5]} (a square wave holds one level per side: not_excited)")
s, rows, _ = sweep("e4_pilot_valve")
check_common("E4 thesis settings", s, rows, 164)
s, rows, _ = sweep("e4_pilot_valve_lash")
share, ident = check_common("E4 lash settings", s, rows, 164)
if share < 0.91:
    fail.append("E4 (lash settings): share of good runs below the thesis's 91 %")
# A regression floor, not issue 24's goal: with the solenoid's lag as a dead time of 2 samples,
# 150 of 219 identified sides have K and c within 5 % and none is above 20 % (without it: 89 of
# 198 and 30 above 20 %, all at 5 and 10 rad/s). The counts were checked against the CSV above.
if not (s["sides_within_tolerance"] >= 0.65 * ident and s["sides_above_20pct"] == 0):
    fail.append(f"E4 (lash settings): {s['sides_within_tolerance']}/{ident} identified sides within 5 %, "
                f"{s['sides_above_20pct']} above 20 % (floor: 65 % and none)")


def check_e5(name, summary, rows, all_amplitudes):
    check_common(name, summary, rows, 108)
    if summary["nrmse_failed"] != 0:
        fail.append(f"{name}: summary reports {summary['nrmse_failed']} runs without an NRMSE")
    for r in rows:
        if not math.isfinite(f(r["nrmse"])):
            fail.append(f"{name} run {r['run']}: NRMSE {r['nrmse']}")
        for sd in ("r", "l"):
            if r["identified_" + sd] == "1" and not math.isfinite(f(r[f"tau_{sd}_s"])):
                fail.append(f"{name} run {r['run']}: identified side {sd} with tau {r[f'tau_{sd}_s']}")
        if r["identified_d"] == "1" and not (math.isfinite(f(r["d"])) and f(r["d"]) >= 0):
            fail.append(f"{name} run {r['run']}: identified d = {r['d']}")
    print(f"{name}: runs with the whole model identified {summary['runs_identified']}/{len(rows)}")
    for w in ("sine", "triangle"):
        at2 = sorted((f(r["amplitude"]), int(r["repeat"]), f(r["nrmse"])) for r in rows
                     if r["waveform"] == w and f(r["frequency_rad_s"]) == 2.0)
        print(f"  {w} at 2 rad/s: " + ", ".join(f"{a:g} V #{k} {100 * n:.2f} %" for a, k, n in at2))
        if len(at2) != 9:
            fail.append(f"{name} {w} at 2 rad/s: {len(at2)} runs, want 9")
        checked = [(a, k, n) for a, k, n in at2 if all_amplitudes or a == 6.0]
        over = [(a, k, n) for a, k, n in checked if not n <= 0.05]
        if over or not checked:
            fail.append(f"{name} {w} at 2 rad/s: NRMSE > 5 % in {over}")


s, rows, _ = sweep("e5_coupled_carts")
check_e5("E5 thesis settings", s, rows, all_amplitudes=False)
s, rows, _ = sweep("e5_coupled_carts_lash")
check_e5("E5 lash settings", s, rows, all_amplitudes=True)
for m in fail:
    print("FAIL", m)
sys.exit(1 if fail else 0)
