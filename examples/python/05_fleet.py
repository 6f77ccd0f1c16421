#!/usr/bin/env python3
"""05 — identify a whole fleet of actuators on a Dask cluster.

Every record (CSV or MAT with columns t [s], v, y) in DIR is identified with lash.estimate
on a dask.distributed cluster: a LocalCluster on this machine by default, or a running
cluster with --scheduler ADDRESS (dask-ssh, dask-jobqueue on Slurm, ...: the same code).
Writes one results CSV (file, side, parameters, 95 % intervals, verdict) and a figure of the
parameters across the fleet, so a backlash that grows with wear stands out.

    python3 05_fleet.py --generate 200 fleet/          # a synthetic fleet (backlash grows)
    python3 05_fleet.py fleet/                          # LocalCluster, one worker per core
    python3 05_fleet.py fleet/ --scheduler tcp://head:8786
    python3 05_fleet.py fleet/ --serial                 # no Dask (the reference)
"""
import argparse
import csv
import glob
import math
import os
import sys
import time

import numpy as np

import lash

# Settings of the fleet's estimator (keys of docs/identification.md): the thesis's deadzone-
# deadband model with moving-average filtering, robust to measurement noise (E2 settings).
SETTINGS = dict(model="deadzone-deadband", guess_left=-350.0, guess_right=350.0, pooled=True, method="iv",
                iv_delay=45, direction_run=41, rls={"lambda": 1.0, "p0": 1000.0},
                noise={"filter_length": 40, "filter_input": True, "derivative_filter_length": 20,
                       "derivative_threshold": 150.0, "align_delay": 10}, nrmse_window=[7.5, 1e9])
PARAMS = ("a1", "b1", "c", "d")
COLUMNS = (["file", "side"] + [p for k in PARAMS for p in (k, k + "_lo", k + "_hi")]
           + ["identified", "reason", "updates", "nrmse"])


def records(folder):
    """The records of a fleet folder, in name order."""
    return sorted(glob.glob(os.path.join(folder, "*.csv")) + glob.glob(os.path.join(folder, "*.mat")))


def identify(path, settings=SETTINGS):
    """One record -> one row per side. Runs on a Dask worker (only lash and numpy needed there)."""
    rec = lash.read_record(path)
    r = lash.estimate(rec["t"], rec["v"], rec["y"], **settings).to_dict()
    rows = []
    for side in ("right", "left"):
        s = r[side]
        ci = s.get("ci95") if isinstance(s.get("ci95"), dict) else {}
        row = {"file": os.path.basename(path), "side": side}
        for k in PARAMS:
            val = s.get(k)
            lo_hi = ci.get(k) or (None, None)
            row[k] = math.nan if val is None else val
            row[k + "_lo"] = math.nan if lo_hi[0] is None else lo_hi[0]
            row[k + "_hi"] = math.nan if lo_hi[1] is None else lo_hi[1]
        row["identified"] = bool(s["identified"])
        row["reason"] = s.get("reason", "") or ""
        row["updates"] = sum(s["updates"].values())
        row["nrmse"] = math.nan if r["nrmse"] is None else r["nrmse"]
        rows.append(row)
    return rows


def run_serial(files):
    return [row for f in files for row in identify(f)]


# Dask's nanny starts every worker process with MALLOC_TRIM_THRESHOLD_=65536 (distributed.yaml,
# nanny.pre-spawn-environ), and setting it turns glibc's adaptive mmap threshold off: every block
# above 128 KiB (a 200 s record's columns, lash's per-sample arrays) is then a fresh mmap whose
# pages fault in zeroed on first touch. lash.estimate of one 40 000-sample record took 3x the CPU
# time in such a worker as in the client (docs/python.md). With these two, blocks up to 16 MiB come
# from the heap again, which is still trimmed beyond 32 MiB free. For workers started by hand
# (dask-worker, dask-ssh, Slurm), set the same two variables in their environment.
WORKER_ENV = {"MALLOC_MMAP_THRESHOLD_": "16777216", "MALLOC_TRIM_THRESHOLD_": "33554432"}
# Dask's statistical profiler samples every thread's stack each 10 ms in every worker (for the
# dashboard's profile page): with lash doing the work, that sampling was 5-8 % of a worker's CPU.
WORKER_CONFIG = {"distributed.worker.profile.enabled": False}


def local_cluster(workers=None):
    """A LocalCluster of `workers` processes (default one per core), one thread each, WORKER_ENV set."""
    import dask
    from dask.distributed import LocalCluster

    settings = {"distributed.nanny.pre-spawn-environ." + k: v for k, v in WORKER_ENV.items()}
    settings.update(WORKER_CONFIG)
    with dask.config.set(settings):
        return LocalCluster(n_workers=workers or os.cpu_count(), threads_per_worker=1, processes=True,
                            dashboard_address=None)


def run_dask(files, scheduler=None, workers=None):
    """Identifies every file on a Dask cluster; rows in file order whatever the scheduling."""
    from dask.distributed import Client

    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        cluster = local_cluster(workers)
        client = Client(cluster)
    try:
        return identify_on(client, files)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def identify_batch(paths, settings=SETTINGS):
    """Several records in one task -> their rows, a list per record (one record takes only ~10-30 ms:
    one task per record would spend a large part of the time in Dask's per-task scheduling)."""
    return [identify(p, settings) for p in paths]


def identify_on(client, files, batches_per_worker=4):
    """Identifies every file on a connected dask.distributed Client: the files dealt round-robin into
    `batches_per_worker` batches per worker (enough to even out the load, few enough that each task is
    long; dealt, not cut in runs, so that every batch holds early and late records of the fleet alike
    and no worker is left with the slowest stretch at the end). Rows in file order."""
    workers = max(1, len(client.scheduler_info().get("workers", {})))
    n = max(1, min(len(files), workers * batches_per_worker))
    batches = [files[i::n] for i in range(n)]
    futures = client.map(identify_batch, batches, pure=False)
    per_file = [None] * len(files)
    for i, batch in enumerate(client.gather(futures)):
        per_file[i::n] = batch  # batch i holds files i, i + n, i + 2n, ...
    return [row for rows in per_file for row in rows]


def write_csv(path, rows):
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for row in rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    os.replace(path + ".tmp", path)


def plot(path, rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = sorted({r["file"] for r in rows})
    index = {f: i for i, f in enumerate(files)}
    fig, axes = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    for ax, key, unit in ((axes[0], "d", "output unit"), (axes[1], "c", "input unit")):
        for side, color in (("right", "C0"), ("left", "C1")):
            sel = [r for r in rows if r["side"] == side]
            x = np.array([index[r["file"]] for r in sel])
            y = np.array([r[key] for r in sel])
            ok = np.array([r["identified"] for r in sel])
            ax.plot(x[ok], y[ok], ".", color=color, label="%s_%s identified" % (key, side[0]))
            ax.plot(x[~ok], y[~ok], "x", color="0.5", label="not identified" if side == "right" else None)
            lo = np.array([r[key + "_lo"] for r in sel])
            hi = np.array([r[key + "_hi"] for r in sel])
            if np.isfinite(lo).any():
                ax.vlines(x, lo, hi, color=color, alpha=0.3, lw=1)
        ax.set_ylabel("%s [%s]" % ("deadband d (backlash half-width)" if key == "d" else "deadzone c", unit))
        ax.legend(loc="upper left", fontsize=8)
    axes[1].set_xlabel("record (file name order)")
    fig.suptitle("lash fleet identification: %d records" % len(files))
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def generate(folder, n, duration_s=40.0, seed=1):
    """A synthetic fleet: the thesis plant with the backlash (deadband) growing from record to
    record (d_r 10 -> 60, d_l 20 -> 70 output units), the deadzone and lag unchanged, noise of
    variance 50. Record i is fleet/unit_<i>.csv with t [s], v, y."""
    os.makedirs(folder, exist_ok=True)
    dt = 0.005
    v = lash.signal("sine", duration_s, dt, amplitude=600.0, frequency_rad_s=1.0)
    for i in range(n):
        grow = i / max(1, n - 1)
        plant = lash.Plant(dt_s=dt, blocks=[
            {"kind": "deadzone", "left": -300.0, "right": 200.0},
            {"kind": "linear", "right": {"a1": -0.96, "b1": 0.1}, "left": {"a1": -0.94, "b1": 0.15}},
            {"kind": "deadband", "half_width": {"left": 20.0 + 50.0 * grow, "right": 10.0 + 50.0 * grow}},
        ])
        tr = plant.simulate(v, noise_variance=50.0, seed=seed + i)
        np.savetxt(os.path.join(folder, "unit_%04d.csv" % i), np.column_stack([tr["t"], tr["v"], tr["y"]]),
                   delimiter=",", header="t,v,y", comments="", fmt="%.17g")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir", help="folder of records (*.csv, *.mat with columns t, v, y)")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, help="LocalCluster worker processes (default: one per core)")
    ap.add_argument("--serial", action="store_true", help="no Dask: identify in this process")
    ap.add_argument("--out", default="fleet_results.csv", help="results CSV")
    ap.add_argument("--figure", default="fleet.png", help="figure of the parameters across the fleet")
    ap.add_argument("--generate", type=int, metavar="N", help="write a synthetic fleet of N records to DIR and exit")
    ap.add_argument("--duration", type=float, default=40.0, help="--generate: record length [s]")
    args = ap.parse_args(argv)

    if args.generate:
        generate(args.dir, args.generate, args.duration)
        print("wrote %d records to %s" % (args.generate, args.dir))
        return 0
    files = records(args.dir)
    if not files:
        print("no *.csv or *.mat records in %s" % args.dir, file=sys.stderr)
        return 2
    start = time.perf_counter()
    rows = run_serial(files) if args.serial else run_dask(files, args.scheduler, args.workers)
    wall = time.perf_counter() - start
    write_csv(args.out, rows)
    if args.figure:
        plot(args.figure, rows)
    ident = sum(r["identified"] for r in rows)
    print("%d records, %d of %d sides identified in %.2f s (%s); results -> %s, figure -> %s"
          % (len(files), ident, len(rows), wall, "serial" if args.serial else "dask", args.out, args.figure))
    return 0


if __name__ == "__main__":
    sys.exit(main())
