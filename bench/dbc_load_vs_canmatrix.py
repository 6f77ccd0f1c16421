"""Loading the corpus's largest DBC file: lash against canmatrix, both in-process and in
CPU time (so that the load of a shared machine does not enter).

- lash: `lash_bench --benchmark_filter=BM_CanLoadDbc` (can::dbc::load_dbc: read, parse,
  check every message's layout), CPU time per iteration;
- canmatrix: `canmatrix.formats.loadp_flat(FILE)` in this process (imports done before
  timing), time.process_time(), best of N.
Prints both and the ratio (target >= 3; exit 1 below it).

Usage: /usr/bin/python3 bench/dbc_load_vs_canmatrix.py [LASH_BENCH] [N]
"""
import glob
import json
import logging
import os
import subprocess
import sys
import time

logging.disable(logging.CRITICAL)
import canmatrix.formats  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
BENCH = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", "build", "bin", "lash_bench")
N = int(sys.argv[2]) if len(sys.argv) > 2 else 5
CORPUS = os.path.join(HERE, "..", "..", "shared", "data", "can-corpus", "dbc")


def main():
    files = glob.glob(os.path.join(CORPUS, "*.dbc"))
    if not files:
        print("corpus not found:", CORPUS)
        return 77
    big = max(files, key=os.path.getsize)
    out = subprocess.run([BENCH, "--benchmark_filter=^BM_CanLoadDbc$", "--benchmark_format=json",
                          f"--benchmark_repetitions={N}", "--benchmark_report_aggregates_only=true"],
                         env=dict(os.environ, LASH_BENCH_DBC=big), check=True, capture_output=True, text=True)
    runs = json.loads(out.stdout)["benchmarks"]
    lash_ms = min(r["cpu_time"] for r in runs if r.get("aggregate_name") in ("median", "mean", None))
    cm = []
    for _ in range(N):
        t0 = time.process_time()
        canmatrix.formats.loadp_flat(big)
        cm.append(time.process_time() - t0)
    cm_ms = min(cm) * 1e3
    print(f"{os.path.basename(big)} ({os.path.getsize(big)} bytes), CPU time:")
    print(f"  lash can::dbc::load_dbc (median of {N} runs): {lash_ms:.2f} ms")
    print(f"  canmatrix loadp_flat (best of {N}):           {cm_ms:.2f} ms")
    print(f"  ratio canmatrix / lash:                      {cm_ms / lash_ms:.1f}x (target >= 3)")
    return 0 if cm_ms / lash_ms >= 3 else 1


if __name__ == "__main__":
    sys.exit(main())
