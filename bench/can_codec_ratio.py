#!/usr/bin/python3
"""CAN codec against its floor, in one run of lash_bench.

Runs BM_CanEncodeDecode4{Intel,Motorola} (MessageCodec: encode + decode of a 4-signal
message) and BM_CanHandWritten4{Intel,Motorola} (the same layout, the same physical values
and rounding, written by hand with constants folded) with N repetitions, and prints each
median CPU time [ns per encode + decode] and the ratio codec / floor per byte order.
Exit status 1 when a ratio exceeds the target 1.5.

usage: bench/can_codec_ratio.py [build/bin/lash_bench] [repetitions]
"""
import json
import subprocess
import sys

bench = sys.argv[1] if len(sys.argv) > 1 else "build/bin/lash_bench"
reps = int(sys.argv[2]) if len(sys.argv) > 2 else 10
out = subprocess.run(
    [bench, "--benchmark_filter=CanEncodeDecode4|CanHandWritten4", f"--benchmark_repetitions={reps}",
     "--benchmark_report_aggregates_only=true", "--benchmark_format=json"],
    check=True, capture_output=True, text=True).stdout
median = {}
for b in json.loads(out)["benchmarks"]:
    if b.get("aggregate_name") == "median":
        median[b["run_name"]] = b["cpu_time"] if b["time_unit"] == "ns" else float("nan")
worst = 0.0
for order in ("Intel", "Motorola"):
    codec = median[f"BM_CanEncodeDecode4{order}"]
    floor = median[f"BM_CanHandWritten4{order}"]
    ratio = codec / floor
    worst = max(worst, ratio)
    print(f"{order:9s} codec {codec:6.2f} ns  floor {floor:6.2f} ns  ratio {ratio:4.2f}  (median CPU time of {reps})")
sys.exit(0 if worst <= 1.5 else 1)
