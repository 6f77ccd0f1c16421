"""Must-show: `lash hil run --duration 5 --step-ms 5 --json` — slave and master as two
processes on the UDP bus in a private network namespace — gives max_abs_diff_vs_simulation_kPa
== 0 (the thesis: emulated and simulated results matched identically), and reports the
fields the issue names. Every difference must be explained by a late/lost frame: when a run
has none, the difference is exactly 0; a busy machine gets up to three attempts."""
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
import hil_netns  # noqa: E402

if os.geteuid() != 0 and subprocess.run(["unshare", "-rn", "true"], capture_output=True).returncode != 0:
    print("skip: no root and no user namespaces: lash hil run cannot isolate its bus")
    sys.exit(hil_netns.SKIP)

REQUIRED = [
    ("master", "tet_us", "mean"), ("master", "tet_us", "min"), ("master", "tet_us", "max"),
    ("master", "tet_us", "std"), ("master", "tet_us", "p99"), ("master", "overruns"),
    ("slave", "tet_us", "mean"), ("slave", "tet_us", "p99"), ("master", "wake_latency_us", "p99"),
    ("frames", "sent"), ("frames", "received"), ("frames", "late"), ("frames", "lost"),
    ("step_response", "rise_s"), ("step_response", "settling_s"), ("step_response", "overshoot_pct"),
    ("max_abs_diff_vs_simulation_kPa",),
]

clean = None
for attempt in range(3):
    out = tempfile.mkdtemp(prefix="lash_hil_run_")
    r = subprocess.run([hil_netns.lash(), "hil", "run", "--duration", "5", "--step-ms", "5", "--json", "--fifo", "50",
                        "--lock-memory", "--out-dir", out], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    for path in REQUIRED:
        node = rep
        for k in path:
            assert k in node, f"missing {'.'.join(path)} in {r.stdout}"
            node = node[k]
    assert "private network namespace" in rep["isolation"], rep["isolation"]
    assert rep["master"]["control_steps"] == 1000
    assert rep["compared_steps"] == 1000
    assert rep["frames"]["sent"] >= 2000 and rep["frames"]["received"] >= 1990
    # The emulation runs the controller: the step 500 -> 1500 kPa is followed.
    assert rep["step_response"]["to_kPa"] == 1500 and rep["step_response"]["rise_s"] < 0.3
    late = rep["frames"]["late"] + rep["frames"]["lost"]
    print(f"attempt {attempt}: late+lost {late}, overruns {rep['master']['overruns']}/{rep['slave']['overruns']}, "
          f"diff {rep['max_abs_diff_vs_simulation_kPa']} kPa, master TET mean {rep['master']['tet_us']['mean']:.2f} us, "
          f"wake-up p99 {rep['master']['wake_latency_us']['p99']:.1f} us")
    if late == 0:
        clean = rep
        break
    # A late frame may make the traces differ, but never before the first step that missed its frame.
    if rep["max_abs_diff_vs_simulation_kPa"] > 0:
        first = rep["first_diff_control_step"]
        m = hil_netns.read_csv(os.path.join(out, "master.csv"))
        missed = [int(cs) for cs, fr in zip(m["control_step"], m["sensor_fresh"]) if cs >= 0 and fr == 0]
        s = hil_netns.read_csv(os.path.join(out, "slave.csv"))
        missed += [int(st) for st, fr in zip(s["step"], s["command_fresh"]) if st > 0 and fr == 0]
        assert missed and min(missed) <= first, (first, sorted(missed)[:5])

if clean is None:
    print("skip: every attempt had late frames (machine too busy for a clean real-time run)")
    sys.exit(hil_netns.SKIP)
assert clean["max_abs_diff_vs_simulation_kPa"] == 0, clean
assert clean["max_abs_diff_vs_simulation_mA"] == 0, clean
print("max_abs_diff_vs_simulation_kPa == 0 over", clean["compared_steps"], "steps")
