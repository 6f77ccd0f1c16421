#!/usr/bin/env python3
"""Estimator per-sample cost against its hand-written floor, in one run.

Usage: bench/estimator_floor_ratio.py LASH_BENCH [OTHER_LASH_BENCH ...] [--reps N]

Runs the estimator benchmarks of bench/bench_identify.cpp and the floor of
bench/bench_estimator_floor.cpp (the thesis-settings deadzone-deadband estimator's arithmetic
written out by hand, checked bit-equal to it before timing) in each binary given, alternating the
binaries N times (default 5) so that every binary sees the same machine load, and prints per
binary the minimum over the N runs of the CPU time [ns per sample] of each benchmark (on a shared,
loaded host the least-disturbed run; the median is printed beside it) and the ratio
BM_DeadzoneDeadband / BM_DeadzoneDeadbandFloor of the minima (goal <= 1.25). With two binaries (e.g. before and
after a change) it also prints after / before per benchmark.
"""
import json
import statistics
import subprocess
import sys

BENCHES = ["BM_DeadzoneDeadband", "BM_DeadzoneDeadbandFloor", "BM_DeadzoneDeadbandE2Settings",
           "BM_DeadzoneDeadbandDefault", "BM_InputDeadzone", "BM_Linear"]


def run(binary):
    filt = "^(" + "|".join(BENCHES) + ")$"
    out = subprocess.run([binary, f"--benchmark_filter={filt}", "--benchmark_format=json",
                          "--benchmark_min_time=0.3"], check=True, capture_output=True, text=True).stdout
    res = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("error_occurred"):
            sys.exit(f"{binary}: {b['name']}: {b.get('error_message')}")
        res[b["name"]] = b["cpu_time"]  # ns per iteration = per sample
    return res


def main():
    args = sys.argv[1:]
    reps = 5
    if "--reps" in args:
        i = args.index("--reps")
        reps = int(args[i + 1])
        del args[i:i + 2]
    if not args:
        sys.exit(__doc__)
    times = {b: {n: [] for n in BENCHES} for b in args}
    for _ in range(reps):
        for b in args:
            for n, t in run(b).items():
                times[b][n].append(t)
    med = {b: {n: min(v) for n, v in times[b].items() if v} for b in args}
    for b in args:
        print(f"{b}  (CPU time, ns/sample: min and median of {reps} runs)")
        for n in BENCHES:
            if n in med[b]:
                print(f"  {n:32s} {med[b][n]:7.2f} {statistics.median(times[b][n]):7.2f}")
        ratio = med[b]["BM_DeadzoneDeadband"] / med[b]["BM_DeadzoneDeadbandFloor"]
        print(f"  thesis-settings estimator / floor  {ratio:5.2f}  (goal <= 1.25)")
    if len(args) == 2:
        a, b = args
        print(f"after / before ({b} / {a})")
        for n in BENCHES:
            if n in med[a] and n in med[b]:
                print(f"  {n:32s} {med[b][n] / med[a][n]:5.2f}")


if __name__ == "__main__":
    main()
