"""Issue 13 item 4 and the live default-loop must-show (docs/compensation.md, docs/hil.md):
 - `lash hil simulate --scenario` and `lash hil run --scenario` on the valve drift scenario give the
   tracking figures of `lash closed-loop --scenario` on the same file (the same nodes run both);
   live: on every attempt 0 kPa from the simulation on the observed schedule; bit-identical when every step used its own frame
   (off_schedule_steps == 0); with a few late frames (<= 1 % of the steps) the RMS figures of the
   windows without a degraded or safe-state episode (of either node) within 20 % (the adaptive law holds on a stale sample); up to four attempts on a
   busy host; the master's TET mean with adaptation on is printed (a timing figure, not asserted);
 - a coupled_carts scenario, or --compensation without --scenario, is refused with exit 2;
 - the default `lash hil run --duration 5` (live, two processes in the run's own network
   namespace): equal to its observed-schedule simulation on every attempt; on an attempt with at
   most 1 % of its steps off schedule and no degraded or safe-state episode, overshoot <= 10 % and,
   from 1 s after the step, the current's std <= 50 mA, recomputed here from slave.csv / master.csv."""
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
import hil_netns  # noqa: E402

lash = hil_netns.lash()
src = hil_netns.source_dir()
scen = os.path.join(src, "config", "scenarios", "closed_loop")
drift = os.path.join(scen, "valve_deadzone_drift.toml")
fail = []
RT = ["--fifo", "50", "--lock-memory", "--spin-us", "200"]


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        fail.append(what)


def closed_loop(path, mode):
    p = subprocess.run([lash, "closed-loop", "--scenario", path, "--compensation", mode, "--json"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


# Bad input: the bench is the pilot valve.
for sub in (["run", "--duration", "1"], ["simulate", "-o", os.path.join(tempfile.mkdtemp(), "x.csv")]):
    p = subprocess.run([lash, "hil", *sub, "--scenario", os.path.join(scen, "carts_clearance_drift.toml")],
                       capture_output=True, text=True)
    check(p.returncode == 2 and "rig" in p.stderr and "pilot valve" in p.stderr,
          f"hil {sub[0]} refuses a coupled_carts scenario (rc {p.returncode}: {p.stderr.strip()})")
p = subprocess.run([lash, "hil", "simulate", "--compensation", "fixed"], capture_output=True, text=True)
check(p.returncode == 2 and "--scenario" in p.stderr, f"--compensation needs --scenario (rc {p.returncode})")

# The closed-loop figures, the reference for both faces of the bench.
cl = {m: closed_loop(drift, m) for m in ("none", "fixed", "adaptive")}
ref = cl["adaptive"]
print("closed-loop adaptive:", ref["tracking"], ref["compensation"]["final"], ref["adaptation"]["updates"])

# hil simulate prints the same figures (same nodes, no bus timing at all).
for mode in ("fixed", "adaptive"):
    p = subprocess.run([lash, "hil", "simulate", "--scenario", drift, "--compensation", mode, "-o",
                        os.path.join(tempfile.mkdtemp(), "s.csv")], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    t = cl[mode]["tracking"]
    want = f"rms error {t['rms_error']:.6g} kPa, max |error| {t['max_abs_error']:.6g} kPa"
    check(want in p.stdout, f"hil simulate {mode}: '{want}' as closed-loop")

# Live: hil run on the drift scenario (40 s, 8000 steps). On every attempt the bench equals its
# simulation on the schedule it observed (0 kPa). Then, against closed-loop (the ideal schedule):
#  (b) no step off schedule: every tracking figure, the final inverse and the update count
#      bit-identical;
#  (c) a few late frames (off-schedule steps <= 1 % = 80): each figure whose window saw no
#      safe-state episode (below) has its RMS within 20 % of closed-loop's and its max |error|
#      within 2x. Justification (docs/compensation.md, scripts/late_frame_study.py): synthetic
#      schedules with 40 to 80 late frames at random steps, replayed by lash hil simulate
#      --schedule, gave RMS ratios 0.96..1.15 and max ratios 0.55..1.40 against closed-loop: a
#      late frame holds the command for a step, and the adaptive law holds on it (the estimator
#      is restarted, the inverse keeps its edges).
#  A host stall of >= fault_missed_periods (3) steps sends the master to its safe state (0 mA,
#  PI reset, docs/hil.md), or the slave, without commands, to its degraded state (ramp to 0 mA):
#  a transient of up to ~370 kPa that is the safety rule's, not the law's. A window with such an
#  episode of either node in it (or in the 2 s before it) is not compared; the
#  test tries again until the score window was compared on an attempt (or bit-identical).
FEW = 80
WINDOWS = {"tracking": (24.0, 40.0), "tracking_before_drift": (0.0, 20.0), "tracking_after_drift": (20.0, 40.0)}
clean = None
few = []
tets = []
for attempt in range(4):
    out = tempfile.mkdtemp(prefix="lash_hil_comp_")
    r = subprocess.run([lash, "hil", "run", "--scenario", drift, "--compensation", "adaptive", "--json", *RT,
                        "--out-dir", out], capture_output=True, text=True, timeout=200)
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    for k in ("tracking", "tracking_before_drift", "tracking_after_drift", "compensation", "adaptation"):
        assert k in rep, f"report has no {k}"
    left_running = [e["event"] for e in rep["master"]["events"] if e["step"] > 1]
    print(f"attempt {attempt}: off-schedule {rep['off_schedule_steps']}, late {rep['frames']['late']}, lost "
          f"{rep['frames']['lost']}, master events {left_running or 'none'}, tracking {rep['tracking']}, "
          f"before drift {rep['tracking_before_drift']['rms_error']}, after drift "
          f"{rep['tracking_after_drift']['rms_error']}, final {rep['compensation']['final']}, updates "
          f"{rep['adaptation']['updates']}, master TET mean {rep['master']['tet_us']['mean']:.3f} us, wake latency "
          f"max {rep['master']['wake_latency_us']['max']:.0f} us")
    check(rep["master"]["control_steps"] == 8000, "hil run: the scenario's 40 s at 5 ms")
    # Steps that consumed another frame than their own (hil_run.py): the traces may differ from
    # the simulation, but never before the first of them.
    m = hil_netns.read_csv(os.path.join(out, "master.csv"))
    s = hil_netns.read_csv(os.path.join(out, "slave.csv"))
    off = [int(cs) for cs, sc, fr in zip(m["control_step"], m["sensor_counter"], m["sensor_fresh"])
           if cs >= 0 and (fr == 0 or int(sc) != int(cs) % 65536)]
    off += [int(st) for st, cc, fr in zip(s["step"], s["command_counter"], s["command_fresh"])
            if 0 < st < 8000 and (fr == 0 or int(cc) != int(st) - 1)]
    check(rep["off_schedule_steps"] == len(set(off)), "off_schedule_steps as recomputed from the logs")
    if off and rep["max_abs_diff_vs_simulation_kPa"] > 0:
        check(min(off) <= rep["first_diff_control_step"],
              f"first difference (step {rep['first_diff_control_step']}) not before the first off-schedule step {min(off)}")
    check(rep["max_abs_diff_vs_observed_schedule_kPa"] == 0,
          f"hil run == its observed-schedule simulation ({rep['max_abs_diff_vs_observed_schedule_kPa']} kPa)")
    tets.append(rep["master"]["tet_us"]["mean"])
    if rep["off_schedule_steps"] == 0:
        clean = rep
        break
    if rep["off_schedule_steps"] <= FEW:
        # a degraded or safe-state episode of either node (master: sensor timeout; slave: commands
        # stale for 3 periods -> ramp to 0 mA) is the safety rule's transient, not the law's
        safe_t = [(e["step"] - 1) * 0.005 for node in ("master", "slave") for e in rep[node]["events"]
                  if "degraded" in e["event"] or "safe_state" in e["event"]]
        for w, (t0, t1) in WINDOWS.items():
            if any(t0 - 2.0 <= t < t1 for t in safe_t):
                print(f"attempt {attempt}: {w} not compared (degraded or safe-state episode at {safe_t} s)")
                continue
            a, b = rep[w]["rms_error"], ref[w]["rms_error"]
            check(abs(a / b - 1.0) <= 0.2, f"attempt {attempt} ({rep['off_schedule_steps']} off-schedule): {w}.rms_error "
                  f"{a:.4g} within 20 % of closed-loop's {b:.4g} (ratio {a / b:.3f})")
            a, b = rep[w]["max_abs_error"], ref[w]["max_abs_error"]
            check(a <= 2.0 * b, f"attempt {attempt}: {w}.max_abs_error {a:.4g} <= 2 x closed-loop's {b:.4g}")
            few.append(w)
        if "tracking" in few:
            break
# The master's TET with adaptation on is a timing figure, reported here and in docs/compensation.md,
# not asserted (a host stall or a build beside the test inflates it).
print(f"master TET mean with adaptation on, best attempt: {min(tets):.3f} us (goal <= 5 us)")
if clean is None and "tracking" not in few:
    print("live part: every attempt had a host stall (degraded or safe state) in the score window or more than 1 % of the "
          "steps off schedule; tracking against closed-loop not checked (the observed-schedule identity above was)")
elif clean is not None:
    for k in ("rms_error", "max_abs_error"):
        check(clean["tracking"][k] == ref["tracking"][k],
              f"hil run tracking.{k} {clean['tracking'][k]} == closed-loop {ref['tracking'][k]}")
        for w in ("tracking_before_drift", "tracking_after_drift"):
            check(clean[w][k] == ref[w][k], f"hil run {w}.{k} == closed-loop")
    check(clean["compensation"]["final"] == ref["compensation"]["final"], "hil run compensation.final == closed-loop")
    check(clean["adaptation"]["updates"] == ref["adaptation"]["updates"], "hil run adaptation.updates == closed-loop")
    check(clean["max_abs_diff_vs_simulation_kPa"] == 0, "hil run == its simulation, every step")

# Live default loop: overshoot <= 10 %, current std <= 50 mA from 1 s after the step.
clean_default = False
for attempt in range(5):
    out = tempfile.mkdtemp(prefix="lash_hil_default_")
    r = subprocess.run([lash, "hil", "run", "--duration", "5", "--json", *RT, "--out-dir", out],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    m = hil_netns.read_csv(os.path.join(out, "master.csv"))
    s = hil_netns.read_csv(os.path.join(out, "slave.csv"))
    rows = [(int(cs), r_, i) for cs, r_, i in zip(m["control_step"], m["reference_kPa"], m["current_mA"]) if cs >= 0]
    rr = [x[1] for x in rows]
    k = next(j for j in range(1, len(rr)) if rr[j] > rr[j - 1])
    r0, r1, ts = rr[k - 1], rr[k], k * 0.005
    p = s["pressure_kPa"][:len(rr)]
    overshoot = (max(p[k:]) - r1) / (r1 - r0) * 100.0
    sd = statistics.pstdev([i for (cs, _, i) in rows if cs * 0.005 >= ts + 1.0])
    print(f"default attempt {attempt}: step {r0} -> {r1} kPa at {ts} s, overshoot {overshoot:.2f} % (report "
          f"{rep['step_response']['overshoot_pct']:.2f} %), current std from {ts + 1} s {sd:.2f} mA, off-schedule "
          f"{rep['off_schedule_steps']}")
    check(rep["max_abs_diff_vs_observed_schedule_kPa"] == 0,
          f"default attempt {attempt}: hil run == its observed-schedule simulation "
          f"({rep['max_abs_diff_vs_observed_schedule_kPa']} kPa)")
    # As the drift part (c): a few late frames (<= 1 % of the 1000 steps) with no degraded or
    # safe-state episode of either node while the loop ran hold the command for a step each;
    # overshoot and the current's spread are judged on such a run with the same bounds (the late-
    # frame study's RMS ratios 0.96..1.15 against the ideal schedule; the bounds are 15x and 6x
    # the clean run's 0.67 % and 7.9 mA).
    n_steps = rep["master"]["control_steps"]
    episodes = [e["event"] for node in ("master", "slave") for e in rep[node]["events"]
                if 1 < e["step"] <= n_steps and ("degraded" in e["event"] or "safe_state" in e["event"])]
    if episodes:
        print(f"default attempt {attempt}: not judged (degraded or safe-state episode: {episodes})")
    if rep["off_schedule_steps"] <= n_steps // 100 and not episodes:
        clean_default = True
        check(r0 == 500 and r1 == 1500, "default reference: the 500 -> 1500 kPa step")
        check(overshoot <= 10.0, f"live default loop: overshoot {overshoot:.2f} % <= 10 %")
        check(sd <= 50.0, f"live default loop: current std {sd:.2f} mA <= 50 mA")
        break
if not clean_default:
    print("skip (live default loop): every attempt had more than 1 % of its steps off schedule or a degraded or "
          "safe-state episode")

for f in fail:
    print("FAIL", f)
if fail:
    sys.exit(1)
sys.exit(0 if (clean is not None or "tracking" in few) and clean_default else hil_netns.SKIP)
