#!/usr/bin/python3
"""How much do a few late frames move the HIL tracking figures? (docs/compensation.md)

Writes synthetic observed schedules for the valve drift scenario (ideal schedule, with n_master
sensor frames late by one step -- the master holds that step -- and n_slave commands late by one
step, at random steps), replays each with `lash hil simulate --schedule`, and prints the ratios of
the tracking figures (score window, before and after the drift; RMS and max |error|) to the ideal
schedule's (= `lash closed-loop`).

  /usr/bin/python3 scripts/late_frame_study.py build/bin/lash [n_master n_slave seeds ...]
  default: 80 0 10  40 40 10
"""
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile

lash = sys.argv[1] if len(sys.argv) > 1 else "build/bin/lash"
args = [int(a) for a in sys.argv[2:]] or [80, 0, 10, 40, 40, 10]
scenario = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config", "scenarios", "closed_loop",
                        "valve_deadzone_drift.toml")
N = 8000  # 40 s at 5 ms


def write_schedule(d, seed, n_master, n_slave):
    rnd = random.Random(seed)
    mseq, sseq = list(range(N)), [s - 1 for s in range(N)]
    for m in rnd.sample(range(5, N - 2), n_master):
        if mseq[m] == m and mseq[m + 1] == m + 1:
            mseq[m] = -1  # frame m arrives after master step m: held; step m+1 takes m+1
    for s in rnd.sample(range(5, N - 2), n_slave):
        if sseq[s] == s - 1 and sseq[s + 1] == s:
            sseq[s] = -1  # command s-1 arrives after slave step s: held; step s+1 takes s
    with open(os.path.join(d, "master.csv"), "w") as f:
        f.write("control_step,sensor_seq,dropped,measured_kPa,current_mA\n")
        f.writelines(f"{m},{mseq[m]},0,0,0\n" for m in range(N))
    with open(os.path.join(d, "slave.csv"), "w") as f:
        f.write("step,command_counter,command_fresh,dropped\n")
        f.writelines(f"{s},{max(sseq[s], 0)},{int(sseq[s] >= 0)},0\n" for s in range(N))


def figures(d):
    cmd = [lash, "hil", "simulate", "--scenario", scenario, "--compensation", "adaptive", "-o",
           os.path.join(d, "sim.csv")]
    if os.path.exists(os.path.join(d, "master.csv")):
        cmd += ["--schedule", os.path.join(d, "master.csv")]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    return [float(x) for pair in re.findall(r"rms error ([0-9.e+-]+) kPa, max \|error\| ([0-9.e+-]+)", out)
            for x in pair]


ideal = figures(tempfile.mkdtemp())
names = ["window rms", "window max", "before rms", "before max", "after rms", "after max"]
print("ideal schedule:", dict(zip(names, ideal)))
ratios = []
for i in range(0, len(args), 3):
    n_master, n_slave, seeds = args[i:i + 3]
    for seed in range(seeds):
        d = tempfile.mkdtemp()
        write_schedule(d, seed, n_master, n_slave)
        ratios.append([a / b for a, b in zip(figures(d), ideal)])
print(f"{len(ratios)} schedules, ratio to the ideal schedule's figure: min / median / max")
for j, n in enumerate(names):
    c = [r[j] for r in ratios]
    print(f"  {n:11s} {min(c):.3f} / {statistics.median(c):.3f} / {max(c):.3f}")
