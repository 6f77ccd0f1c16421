#!/usr/bin/python3
"""`lash monitor` in file mode: its speed against `lash can decode` of the same log, and its peak
memory on a log and on one 10 times longer (docs/monitor.md, "Cost").

The logs are the emulated bench's frames: a `lash hil run` master_bus.log (40 s, 200 Hz, two
frames per sample) repeated end to end, each copy shifted by the log's span (its alive counters
jump once per copy: one regressor restart each, as a real counter jump). Every figure comes from
the same run of this script; times are CPU time (user + system) of the child from wait4(2), so
the other loads of a shared machine do not enter; peak memory is the child's ru_maxrss.

Printed per log: frames, `lash can decode --dbc DBC LOG > /dev/null` frames/s,
`lash monitor LOG ...` frames/s at --every 1 and --every 60 (the default 120 s window), their
ratios to decode, and the peak RSS of each; then the RSS ratio 10x / 1x of the monitor.

usage: bench/monitor_bench.py [--lash build/bin/lash] [--log master_bus.log] [--minutes 10]
                              [--every 1,60] [--no-decode]
       (without --log it runs `lash hil run` of the valve drift scenario first, 40 s)
"""
import argparse
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.join(HERE, "..")
ap = argparse.ArgumentParser()
ap.add_argument("--lash", default=os.path.join(SRC, "build", "bin", "lash"))
ap.add_argument("--log", help="a master_bus.log of the bench (default: a fresh lash hil run)")
ap.add_argument("--minutes", type=float, default=10.0, help="length of the 1x log [min] (the other is 10x)")
ap.add_argument("--every", default="1,60", help="--every values of the monitor runs [s], comma-separated")
ap.add_argument("--no-decode", action="store_true",
                help="skip lash can decode (it reads the whole log: about 6x the file in memory)")
a = ap.parse_args()

DBC = os.path.join(SRC, "config", "monitor", "hydraulic_bench_kpa.dbc")
MON = ["--dbc", DBC, "--v", "BenchCommand.SolenoidA_Current-BenchCommand.SolenoidB_Current",
       "--y", "BenchSensors.PilotPressure_kPa", "--model", "input-deadzone", "--method", "iv", "--lambda", "0.995",
       "--quiet"]
tmp = tempfile.mkdtemp(prefix="lash_monitor_bench_")

log = a.log
if log is None:
    scn = os.path.join(SRC, "config", "scenarios", "closed_loop", "valve_deadzone_drift.toml")
    subprocess.run([a.lash, "hil", "run", "--scenario", scn, "--out-dir", os.path.join(tmp, "hil")],
                   check=True, capture_output=True)
    log = os.path.join(tmp, "hil", "master_bus.log")

lines = open(log).read().splitlines()
stamps = [float(x[1:x.index(")")]) for x in lines]
span = stamps[-1] - stamps[0] + (stamps[-1] - stamps[0]) / (len(stamps) - 1)
rest = [x[x.index(")"):] for x in lines]


def long_log(copies):
    path = os.path.join(tmp, f"bench_{copies}.log")
    with open(path, "w") as f:
        for c in range(copies):
            off = c * span
            f.write("".join([f"({s + off:.6f}{r}\n" for s, r in zip(stamps, rest)]))
    return path, copies * len(lines), copies * span


def run(cmd):
    """CPU seconds and peak RSS [MiB] of the child, from wait4."""
    with open(os.devnull, "w") as null:
        p = subprocess.Popen(cmd, stdout=null, stderr=subprocess.PIPE)
        _, status, ru = os.wait4(p.pid, 0)
        err = p.stderr.read().decode()
        p.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(cmd)} failed: {err}")
    return ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024.0


rss = {}
everys = a.every.split(",")
copies = max(1, round(a.minutes * 60 / span))
for scale in (1, 10):
    path, frames, seconds = long_log(copies * scale)
    print(f"{scale:2d}x log: {frames} frames, {seconds / 60:.1f} min of bus, {os.path.getsize(path) / 2**20:.0f} MiB")
    t_dec = float("nan")
    if not a.no_decode:
        t_dec, m_dec = run([a.lash, "can", "decode", "--dbc", DBC, path])
        print(f"    lash can decode          {frames / t_dec:12.0f} frames/s  ({t_dec:7.2f} s CPU)  "
              f"peak RSS {m_dec:7.1f} MiB")
    for every in everys:
        t_mon, m_mon = run([a.lash, "monitor", path, *MON, "--every", every])
        rss[(scale, every)] = m_mon
        print(f"    lash monitor --every {every:2s}  {frames / t_mon:12.0f} frames/s  ({t_mon:7.2f} s CPU)  "
              f"peak RSS {m_mon:7.1f} MiB" + ("" if a.no_decode else f"  ratio to decode {t_dec / t_mon:.3f}"))
    os.remove(path)
for every in everys:
    print(f"monitor --every {every}: peak RSS 10x / 1x = {rss[(10, every)] / rss[(1, every)]:.3f}")
