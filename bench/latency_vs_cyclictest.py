#!/usr/bin/python3
"""Wake-up latency of lash's periodic loop against Debian's cyclictest (package rt-tests), in one run.

Both sleep with clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME) to a fixed grid and measure how
late they woke (µs). They run one after the other, alternating, in ROUNDS rounds, under the same
conditions: the same interval, one thread, no CPU pinning, no memory locking, and
/dev/cpu_dma_latency held at 0 by both (cyclictest's default; lash's default, see docs/hil.md).
Each condition is measured with the default scheduler and with SCHED_FIFO (--fifo, cyclictest -p).

Prints, per condition, the p99 of each tool in each round and the median over rounds, and the
ratio lash p99 / cyclictest p99 of the medians (goal: <= 1.5). Needs root (cyclictest,
SCHED_FIFO, /dev/cpu_dma_latency).

  bench/latency_vs_cyclictest.py --lash build/apps/lash/lash [--rounds 3] [--seconds 10] [--interval-us 1000]
"""
import argparse
import json
import shutil
import statistics
import subprocess
import sys


def lash_p99(lash, seconds, interval_us, fifo):
    cmd = [lash, "hil", "latency", "--json", "--duration", str(seconds), "--step-ms", str(interval_us / 1000)]
    if fifo:
        cmd += ["--fifo", str(fifo)]
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    j = json.loads(r.stdout)
    if fifo and any("SCHED_FIFO" in w for w in j["warnings"]):
        sys.exit("lash could not get SCHED_FIFO: " + "; ".join(j["warnings"]))
    return j["wake_latency_us"]["p99"], j["dma_latency_held"]


def cyclictest_p99(seconds, interval_us, fifo):
    """p99 [µs] of cyclictest's per-sample latencies (-v prints `thread: cycle: latency` lines)."""
    loops = int(seconds * 1e6 / interval_us)
    cmd = ["cyclictest", "-q", "-v", "-t1", "-i", str(interval_us), "-l", str(loops)]
    cmd += ["--policy=fifo", "-p", str(fifo)] if fifo else ["--policy=other"]
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    lat = []
    for line in r.stdout.splitlines():
        parts = line.replace(":", " ").split()
        if len(parts) == 3 and all(p.isdigit() for p in parts) and parts[1] != "0":  # cycle 0: the first wake
            lat.append(int(parts[2]))
    if len(lat) < loops // 2:
        sys.exit("cyclictest printed too few samples:\n" + r.stdout[-2000:] + r.stderr)
    lat.sort()
    return float(lat[-(-99 * len(lat) // 100) - 1])  # nearest rank, as lash's rt::summarize


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lash", required=True, help="the lash executable")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    ap.add_argument("--seconds", type=float, default=10.0, help="length of each measurement [s] (default 10)")
    ap.add_argument("--interval-us", type=int, default=1000, help="period of both loops [µs] (default 1000)")
    ap.add_argument("--fifo", type=int, default=50, help="SCHED_FIFO priority of the FIFO condition (default 50)")
    a = ap.parse_args()
    if a.rounds < 1 or a.seconds <= 0 or a.interval_us < 100 or not 1 <= a.fifo <= 99:
        sys.exit("--rounds >= 1, --seconds > 0, --interval-us >= 100, --fifo 1..99")
    if shutil.which("cyclictest") is None:
        sys.exit("cyclictest not found: apt-get install rt-tests")
    worst = 0.0
    for name, fifo in (("default scheduler", 0), (f"SCHED_FIFO {a.fifo}", a.fifo)):
        lp, cp = [], []
        for k in range(a.rounds):
            # Alternate which goes first so that a drift of the host load does not favour one.
            order = ("lash", "cyclictest") if k % 2 == 0 else ("cyclictest", "lash")
            for tool in order:
                if tool == "lash":
                    p, held = lash_p99(a.lash, a.seconds, a.interval_us, fifo)
                    lp.append(p)
                else:
                    cp.append(cyclictest_p99(a.seconds, a.interval_us, fifo))
            print(f"{name:18s} round {k}: lash p99 {lp[-1]:8.1f} us (cpu_dma_latency {'held' if held else 'NOT held'})"
                  f"   cyclictest p99 {cp[-1]:8.1f} us", flush=True)
        ml, mc = statistics.median(lp), statistics.median(cp)
        ratio = ml / mc if mc > 0 else float("inf")
        worst = max(worst, ratio)
        print(f"{name:18s} median of {a.rounds}: lash p99 {ml:.1f} us, cyclictest p99 {mc:.1f} us, "
              f"ratio lash/cyclictest {ratio:.2f} (goal <= 1.5)", flush=True)
    print(f"worst ratio {worst:.2f}")


if __name__ == "__main__":
    main()
