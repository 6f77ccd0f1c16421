"""Issue 13 item 4 and the live default-loop must-show (docs/compensation.md, docs/hil.md):
 - `lash hil simulate --scenario` and `lash hil run --scenario` on the valve drift scenario give the
   tracking figures of `lash closed-loop --scenario` on the same file (the same nodes run both);
   live: on every attempt 0 kPa from the simulation on the observed schedule; bit-identical when every step used its own frame
   (off_schedule_steps == 0), up to three attempts on a busy host; the master's TET mean with
   adaptation on is printed (a timing figure, not asserted);
 - a coupled_carts scenario, or --compensation without --scenario, is refused with exit 2;
 - the default `lash hil run --duration 5` (live, two processes in the run's own network
   namespace): overshoot <= 10 % and, from 1 s after the step, the current's std <= 50 mA,
   recomputed here from slave.csv / master.csv."""
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

# Live: hil run on the drift scenario (40 s), bit-identical to closed-loop when no frame was off schedule.
clean = None
tets = []
for attempt in range(3):
    out = tempfile.mkdtemp(prefix="lash_hil_comp_")
    r = subprocess.run([lash, "hil", "run", "--scenario", drift, "--compensation", "adaptive", "--json", *RT,
                        "--out-dir", out], capture_output=True, text=True, timeout=200)
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    for k in ("tracking", "tracking_before_drift", "tracking_after_drift", "compensation", "adaptation"):
        assert k in rep, f"report has no {k}"
    print(f"attempt {attempt}: off-schedule {rep['off_schedule_steps']}, late {rep['frames']['late']}, lost "
          f"{rep['frames']['lost']}, tracking {rep['tracking']}, after drift {rep['tracking_after_drift']['rms_error']}, "
          f"final {rep['compensation']['final']}, updates {rep['adaptation']['updates']}, master TET mean "
          f"{rep['master']['tet_us']['mean']:.3f} us")
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
    # Every run, late frames or not: the bench equals its simulation on the schedule it observed
    # (hil simulate --schedule). The tracking figures themselves do depend on the schedule: late
    # frames feed the adaptive law stale pressures (docs/compensation.md gives measured figures).
    check(rep["max_abs_diff_vs_observed_schedule_kPa"] == 0,
          f"hil run == its observed-schedule simulation ({rep['max_abs_diff_vs_observed_schedule_kPa']} kPa)")
    tets.append(rep["master"]["tet_us"]["mean"])
    if rep["off_schedule_steps"] == 0:
        clean = rep
        break
# The master's TET with adaptation on is a timing figure, reported here and in docs/compensation.md,
# not asserted (a host stall or a build beside the test inflates it).
print(f"master TET mean with adaptation on, best attempt: {min(tets):.3f} us (goal <= 5 us)")
if clean is None:
    print("live part: every attempt had off-schedule frames; bit-identity with closed-loop not checked "
          "(the observed-schedule identity above was)")
else:
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
    if rep["off_schedule_steps"] == 0:
        clean_default = True
        check(r0 == 500 and r1 == 1500, "default reference: the 500 -> 1500 kPa step")
        check(overshoot <= 10.0, f"live default loop: overshoot {overshoot:.2f} % <= 10 %")
        check(sd <= 50.0, f"live default loop: current std {sd:.2f} mA <= 50 mA")
        break
if not clean_default:
    print("skip (live default loop): every attempt had off-schedule frames")

for f in fail:
    print("FAIL", f)
if fail:
    sys.exit(1)
sys.exit(0 if clean is not None and clean_default else hil_netns.SKIP)
