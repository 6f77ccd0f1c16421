#!/usr/bin/python3
"""`lash monitor` in file mode: its speed against `lash can decode` of the same log, and its peak
memory on a log and on longer ones (docs/monitor.md, "Cost"; e.g. 1 h and 24 h of the bench's bus).

The logs are the emulated bench's frames: a `lash hil run` master_bus.log (40 s, 200 Hz, two
frames per sample) repeated end to end, each copy shifted by the log's span (its alive counters
jump once per copy: one regressor restart each, as a real counter jump). Every figure comes from
the same run of this script; times are CPU time (user + system) of the child from wait4(2), so
the other loads of a shared machine do not enter; peak memory is the child's ru_maxrss.

Printed per log: frames, `lash can decode --dbc DBC LOG > /dev/null` frames/s,
`lash monitor LOG ...` frames/s at --every 1 (the default: with the default estimator, `online`,
these are the monitor's defaults) and --every 60, with each --estimate mode asked (default: online;
`window` re-estimates the 120 s window every period), their ratios to decode (decode CPU time / monitor CPU time: above 1, the monitor reads the log faster
than decode prints it), and the peak RSS of each; then the RSS ratio of the longest log to the
shortest for each command (both stream the log: about 1).

usage: bench/monitor_bench.py [--lash build/bin/lash] [--log master_bus.log] [--minutes 10]
                              [--scales 1,10] [--every 1,60] [--estimate online,window] [--no-decode]
       e.g. --minutes 60 --scales 1,24 --every 60: 1 h and 24 h of the bench's bus
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
ap.add_argument("--minutes", type=float, default=10.0, help="length of the 1x log [min]")
ap.add_argument("--scales", default="1,10", help="lengths of the logs in units of --minutes, comma-separated")
ap.add_argument("--every", default="1,60", help="--every values of the monitor runs [s], comma-separated")
ap.add_argument("--estimate", default="online", help="--estimate modes of the monitor runs, comma-separated")
ap.add_argument("--floor", type=float, default=2e6, help="the frames/s the defaults must reach (issue 25)")
ap.add_argument("--no-decode", action="store_true", help="skip lash can decode")
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


# A child's ru_maxrss starts from its parent's high-water mark at fork (kept across exec): each
# command is started by a small Python process, not by this one.
SPAWN = """import os, sys
with open(os.devnull, "w") as null:
    pid = os.fork()
    if pid == 0:
        os.dup2(null.fileno(), 1)
        os.execv(sys.argv[1], sys.argv[1:])
    _, status, ru = os.wait4(pid, 0)
print(os.waitstatus_to_exitcode(status), ru.ru_utime + ru.ru_stime, ru.ru_maxrss)
"""


def run(cmd):
    """CPU seconds (user + system) and peak RSS [MiB] of the command, from wait4."""
    r = subprocess.run([sys.executable, "-c", SPAWN, *cmd], capture_output=True, text=True)
    status, cpu, kib = r.stdout.split()
    if status != "0":
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr}")
    return float(cpu), int(kib) / 1024.0


rss = {}
everys = a.every.split(",")
modes = a.estimate.split(",")
scales = [int(x) for x in a.scales.split(",")]
copies = max(1, round(a.minutes * 60 / span))
for scale in scales:
    path, frames, seconds = long_log(copies * scale)
    print(f"{scale:2d}x log: {frames} frames, {seconds / 60:.1f} min of bus, {os.path.getsize(path) / 2**20:.0f} MiB")
    t_dec = float("nan")
    if not a.no_decode:
        t_dec, m_dec = run([a.lash, "can", "decode", "--dbc", DBC, path])
        rss[(scale, "decode")] = m_dec
        print(f"    lash can decode          {frames / t_dec:12.0f} frames/s  ({t_dec:7.2f} s CPU)  "
              f"peak RSS {m_dec:7.1f} MiB")
    for mode in modes:
        for every in everys:
            t_mon, m_mon = run([a.lash, "monitor", path, *MON, "--estimate", mode, "--every", every])
            rss[(scale, (mode, every))] = m_mon
            default = mode == "online" and float(every) == 1.0
            print(f"    lash monitor --estimate {mode:6s} --every {every:2s}{' (defaults)' if default else '           '}"
                  f"{frames / t_mon:12.0f} frames/s  ({t_mon:7.2f} s CPU)  peak RSS {m_mon:7.1f} MiB"
                  + ("" if a.no_decode else f"  ratio to decode {t_dec / t_mon:.3f}")
                  + (f"  {frames / t_mon / a.floor:.2f} x the floor {a.floor:.3g}" if default else ""))
    os.remove(path)
lo, hi = scales[0], scales[-1]
for key in ([] if a.no_decode else ["decode"]) + [(m, e) for m in modes for e in everys]:
    what = "lash can decode" if key == "decode" else f"monitor --estimate {key[0]} --every {key[1]}"
    print(f"{what}: peak RSS {hi}x / {lo}x = {rss[(hi, key)] / rss[(lo, key)]:.3f}")
