"""Must-show: `lash hil run --duration 5 --step-ms 5 --json` — slave and master as two
processes on the UDP bus in a private network namespace — gives max_abs_diff_vs_simulation_kPa
== 0 (the thesis: emulated and simulated results matched identically), and reports the
fields the issue names. Every difference must be explained by a late/lost frame: when a run
has none, the difference is exactly 0; a busy machine gets up to five attempts (a loaded host (ctest -j2) stalls a vCPU for milliseconds now and then: a frame is then late, whatever the scheduler)."""
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
    ("master", "io_us", "mean"), ("master", "cycle_us", "max"), ("slave", "io_us", "mean"),
    ("frames", "sent"), ("frames", "received"), ("frames", "late"), ("frames", "lost"),
    ("step_response", "rise_s"), ("step_response", "settling_s"), ("step_response", "overshoot_pct"),
    ("max_abs_diff_vs_simulation_kPa",),
]

clean = None
for attempt in range(5):
    out = tempfile.mkdtemp(prefix="lash_hil_run_")
    r = subprocess.run([hil_netns.lash(), "hil", "run", "--duration", "5", "--step-ms", "5", "--json", "--fifo", "50",
                        "--lock-memory", "--spin-us", "200", "--out-dir", out], capture_output=True, text=True, timeout=60)
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
    # Steps that consumed another frame than the one meant for them: master step m must use
    # the sensor frame of slave step m, slave step s the command of master step s - 1.
    m = hil_netns.read_csv(os.path.join(out, "master.csv"))
    s = hil_netns.read_csv(os.path.join(out, "slave.csv"))
    off = [int(cs) for cs, sc, fr in zip(m["control_step"], m["sensor_counter"], m["sensor_fresh"])
           if cs >= 0 and (fr == 0 or int(sc) != int(cs))]
    off += [int(st) for st, cc, fr in zip(s["step"], s["command_counter"], s["command_fresh"])
            if 0 < st < rep["master"]["control_steps"] and (fr == 0 or int(cc) != int(st) - 1)]
    assert rep["off_schedule_steps"] == len(set(off)), (rep["off_schedule_steps"], len(set(off)))
    # TET (the task) and CAN I/O (the emulated controller) are logged per step; the report's
    # means are those of the logs, and the cycle is their sum.
    for node, log in (("master", m), ("slave", s)):
        n = len(log["tet_us"])
        tet, io = sum(log["tet_us"]) / n, sum(log["io_us"]) / n
        assert abs(rep[node]["tet_us"]["mean"] - tet) < 1e-3 and abs(rep[node]["io_us"]["mean"] - io) < 1e-3, node
        assert abs(rep[node]["cycle_us"]["mean"] - (tet + io)) < 2e-3, node
        assert rep[node]["tet_us"]["min"] >= 0 and rep[node]["io_us"]["min"] > 0, node
    print(f"attempt {attempt}: late+lost {late}, off-schedule steps {len(set(off))}, overruns "
          f"{rep['master']['overruns']}/{rep['slave']['overruns']}, diff {rep['max_abs_diff_vs_simulation_kPa']} kPa, "
          f"master TET mean {rep['master']['tet_us']['mean']:.2f} us, wake-up p99 "
          f"{rep['master']['wake_latency_us']['p99']:.1f} us")
    if not off:
        # Every step used its own frame: the emulation must equal the simulation exactly.
        assert rep["max_abs_diff_vs_simulation_kPa"] == 0, rep
        clean = rep
        break
    # Otherwise the traces may differ, but never before the first off-schedule step.
    if rep["max_abs_diff_vs_simulation_kPa"] > 0:
        assert min(off) <= rep["first_diff_control_step"], (rep["first_diff_control_step"], sorted(off)[:5])

if clean is None:
    print("skip: every attempt had late frames (machine too busy for a clean real-time run)")
    sys.exit(hil_netns.SKIP)
assert clean["max_abs_diff_vs_simulation_kPa"] == 0, clean
assert clean["max_abs_diff_vs_simulation_mA"] == 0, clean
print("max_abs_diff_vs_simulation_kPa == 0 over", clean["compared_steps"], "steps")
