#!/usr/bin/env python3
"""Speed of the lash Python package, as ratios printed in one run (docs/python.md):

1. lash.estimate on 10^6 samples from numpy arrays, per sample, against two C++ Google Benchmarks
   on the same plant data, Python and C++ alternating `--rounds` times, each round pinned to one
   vCPU, the vCPUs in turn (each side the best of 5 calls;
   the median of the per-round ratios printed): BM_EstimateArrays (bench_estimate_auto.cpp: the same library call, lash::estimate_arrays,
   on the same 10^6 samples; goal: ratio <= 1.2, i.e. no per-sample Python work) and
   BM_DeadzoneDeadband (bench_identify.cpp: the bare estimator step alone, data in cache). Timed with
   the benchmarks' settings (thesis preset, guesses given, outlier gate off, intervals=False); the
   defaults (preset lash, gate, intervals: more passes) are printed too.
2. The per-call overhead of Estimator.update (one Python call per sample) over update_many.
3. The fleet example (examples/python/05_fleet.py) on its LocalCluster of 2 worker processes against
   1, the two clusters taking turns for --fleet-repeat rounds (cluster start-up not timed; the median
   of the per-round ratios); goal: speed-up >= 1.7 on 2 cores.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_bench.py [--lash-bench build/bin/lash_bench]
"""
import argparse
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import lash

# bench_estimate_auto.cpp's benchmarks time one call on 10^6 samples; bench_identify.cpp's one sample
ESTIMATE_ARRAYS_SAMPLES = 10 ** 6
PER_CALL = ("BM_EstimateArrays", "BM_RunEstimator")
HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.dirname(HERE)


def best_of(fn, repeat):
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def median_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def e1_data(n):
    """The data of bench_identify.cpp: the E1 plant driven by v = 600 sin(0.005 k)."""
    plant = lash.Plant(dt_s=0.005, blocks=[
        {"kind": "deadzone", "left": -300.0, "right": 200.0},
        {"kind": "linear", "right": {"a1": -0.96, "b1": 0.1}, "left": {"a1": -0.94, "b1": 0.15}},
        {"kind": "deadband", "half_width": {"left": 50.0, "right": 30.0}},
    ])
    v = 600.0 * np.sin(0.005 * np.arange(n))
    tr = plant.simulate(v)
    return tr["t"], tr["v"], tr["y"]


def cpp_ns_per_sample(lash_bench, names, calls):
    """Per sample [ns], for each Google Benchmark in `names` (one lash_bench run): the best of `calls`
    repetitions of the shortest run Google Benchmark makes (one call of BM_EstimateArrays)."""
    out = subprocess.run([lash_bench, "--benchmark_filter=^(%s)(/real_time)?$" % "|".join(names),
                          "--benchmark_format=json", "--benchmark_repetitions=%d" % calls,
                          "--benchmark_min_time=0.01"], capture_output=True, text=True, check=True)
    ns = {}
    for b in json.loads(out.stdout)["benchmarks"]:
        if b.get("run_type") != "iteration":
            continue
        t = b["real_time"] * {"ns": 1.0, "us": 1e3, "ms": 1e6}[b["time_unit"]]
        name = b["run_name"].split("/")[0]
        t /= ESTIMATE_ARRAYS_SAMPLES if name in PER_CALL else 1
        ns[name] = min(ns.get(name, t), t)
    missing = [n for n in names if n not in ns]
    if missing:
        raise RuntimeError("no run of %s in lash_bench output" % missing)
    return ns


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lash-bench", default=os.path.join(SRC, "build", "bin", "lash_bench"))
    ap.add_argument("--rounds", type=int, default=5, help="Python/C++ alternations for the ratios of 1.")
    ap.add_argument("--fleet-records", type=int, default=200, help="records in the fleet (the size of the fleet test)")
    ap.add_argument("--fleet-duration", type=float, default=200.0, help="record length [s]")
    ap.add_argument("--fleet-repeat", type=int, default=7, help="alternating rounds of 1 and 2 workers (median)")
    ap.add_argument("--no-fleet", action="store_true", help="skip the fleet speed-up")
    args = ap.parse_args()

    n = ESTIMATE_ARRAYS_SAMPLES
    t, v, y = e1_data(n)
    settings = dict(guess_left=-350.0, guess_right=350.0)
    # the benchmarks' settings: thesis preset, given guesses, no outlier gate, no intervals
    same = dict(preset="thesis", outlier_gate=0, intervals=False, **settings)
    lash.estimate(t, v, y, **same)
    have_cpp = os.path.exists(args.lash_bench)
    # Python and C++ alternate, `rounds` times, so that a change of the host's load hits both; the
    # ratios are taken within each round and their median printed.
    # Each side of a round: the best of 5 calls (an other job's time slice only ever adds time).
    # Each round runs on one vCPU (this process pinned to it; lash_bench inherits the pinning), the
    # vCPUs taken in turn: on a shared host one vCPU can run this code much slower than the other
    # for minutes (docs/identification.md, "Speed"), and an unpinned process stays where it started.
    cpus = sorted(os.sched_getaffinity(0))
    rows = []
    for r in range(args.rounds):
        os.sched_setaffinity(0, {cpus[r % len(cpus)]})
        py_ns = best_of(lambda: lash.estimate(t, v, y, **same), 5) / n * 1e9
        cpp = cpp_ns_per_sample(args.lash_bench, ["BM_EstimateArrays", "BM_DeadzoneDeadband"], 5) if have_cpp else {}
        rows.append((py_ns, cpp))
    os.sched_setaffinity(0, set(cpus))
    py_ns = statistics.median(r[0] for r in rows)
    full_ns = median_of(lambda: lash.estimate(t, v, y, **settings), 3) / n * 1e9
    print("1. lash.estimate, deadzone-deadband, 10^6 samples from numpy: %.2f ns/sample (%.1f M samples/s) with the"
          " benchmarks' settings; %.2f ns/sample with the defaults (preset lash, outlier gate, 95 %% intervals)"
          % (py_ns, 1e3 / py_ns, full_ns))
    if have_cpp:
        same_call = [r[0] / r[1]["BM_EstimateArrays"] for r in rows]
        bare = [r[0] / r[1]["BM_DeadzoneDeadband"] for r in rows]
        print("   C++ BM_EstimateArrays (the same library call, lash::estimate_arrays): %.2f ns/sample"
              " -> ratio Python/C++ = %.3f (goal <= 1.2; rounds: %s)"
              % (statistics.median(r[1]["BM_EstimateArrays"] for r in rows), statistics.median(same_call),
                 ", ".join("%.3f" % x for x in same_call)))
        print("   C++ BM_DeadzoneDeadband (the bare estimator step, 65536 samples in cache): %.2f ns/sample"
              " -> ratio = %.3f (rounds: %s)"
              % (statistics.median(r[1]["BM_DeadzoneDeadband"] for r in rows), statistics.median(bare),
                 ", ".join("%.3f" % x for x in bare)))
    else:
        print("   (no %s: build the lash_bench target for the C++ ratios)" % args.lash_bench)

    m = 200000
    e = lash.Estimator("deadzone-deadband", 0.005, **settings)
    many_s = best_of(lambda: (e.reset(), e.update_many(v[:m], y[:m])), 5) / m
    upd = e.update
    vl, yl = v[:m].tolist(), y[:m].tolist()

    def one_by_one():
        e.reset()
        for a, b in zip(vl, yl):
            upd(a, b)
    one_s = best_of(one_by_one, 3) / m
    print("2. Estimator.update: %.0f ns per call vs %.1f ns per sample in update_many -> overhead %.0f ns per call"
          % (one_s * 1e9, many_s * 1e9, (one_s - many_s) * 1e9))

    if args.no_fleet:
        return 0
    spec = importlib.util.spec_from_file_location("fleet", os.path.join(SRC, "examples", "python", "05_fleet.py"))
    fleet = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fleet)
    from dask.distributed import Client

    with tempfile.TemporaryDirectory() as d:
        fleet.generate(d, args.fleet_records, duration_s=args.fleet_duration)
        files = fleet.records(d)
        # Both clusters run side by side and take turns, 1 worker then 2, `--fleet-repeat` rounds: a
        # shared host's slow spells (another tenant on the same physical core) then fall on both
        # sides of a round's ratio alike, and the median of the per-round ratios is printed.
        with fleet.local_cluster(1) as c1, Client(c1) as one, fleet.local_cluster(2) as c2, Client(c2) as two:
            clients = {1: one, 2: two}
            for workers, client in clients.items():
                fleet.identify_on(client, files[:2 * workers])  # warm-up: import lash on every worker
            w0 = {k: c.run(time.process_time) for k, c in clients.items()}
            c0 = time.process_time()
            runs = {1: [], 2: []}
            for _ in range(args.fleet_repeat):
                for workers, client in clients.items():
                    t0 = time.perf_counter()
                    fleet.identify_on(client, files)
                    runs[workers].append(time.perf_counter() - t0)
            w1 = {k: c.run(time.process_time) for k, c in clients.items()}
            c1_ = time.process_time()
        times = {k: statistics.median(v) for k, v in runs.items()}
        ratios = [a / b for a, b in zip(runs[1], runs[2])]
        cpu = {k: [(w1[k][w] - w0[k][w]) / args.fleet_repeat for w in sorted(w1[k])] for k in runs}
        print("3. fleet of %d records x %g s: 1 worker %.2f s, 2 workers %.2f s (medians of %d alternating runs)"
              " -> speed-up %.2f (median of the per-round ratios %s; goal >= 1.7); load average %.1f"
              % (len(files), args.fleet_duration, times[1], times[2], args.fleet_repeat, statistics.median(ratios),
                 " ".join("%.2f" % r for r in ratios), os.getloadavg()[0]))
        client_cpu = (c1_ - c0) / (2 * args.fleet_repeat)  # the client and both schedulers, per run
        for workers in (1, 2):
            # CPU seconds per run: how evenly the work is split, what the client and scheduler take, and
            # how many cores the run got (a shared host's other sessions take the rest)
            print("   %d worker(s): CPU per run %s s in the workers, %.2f s in the client and schedulers;"
                  " %.2f cores used" % (workers, " + ".join("%.2f" % x for x in cpu[workers]), client_cpu,
                                        (sum(cpu[workers]) + client_cpu) / times[workers]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
