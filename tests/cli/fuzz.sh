#!/usr/bin/env bash
# The deterministic fuzz gate of `make test` for one libFuzzer target (built in the clang tree
# with LASH_BUILD_FUZZ=ON, as `make test` does):
#   1. replay: every input of fuzz/corpus/<name>/ (seeds and regress-* files, inputs that once
#      failed) runs once and must pass;
#   2. explore: a fixed number of executions from a fixed seed, starting from that corpus.
# Same binary, same corpus, same seed: the same inputs and the same execution count on every
# machine and every run. Random exploration for longer is `make fuzz` (scripts/fuzz.sh).
# Usage: fuzz.sh <target> <runs>   (target: can_dbc, can_blf, table, plant, ...)
set -euo pipefail
name=$1
runs=$2
src=${LASH_SOURCE_DIR:?}
clang_dir=${LASH_CLANG_BUILD_DIR:-}
if [[ -z "$clang_dir" ]]; then
  echo "fuzz: LASH_CLANG_BUILD_DIR not set (configure through the Makefile); skipped" >&2
  exit 77
fi
bin="$clang_dir/bin/fuzz_$name"
if [[ ! -x "$bin" ]]; then
  echo "fuzz: FAIL: $bin missing; build the clang tree with -DLASH_BUILD_FUZZ=ON (make build-clang)" >&2
  exit 1
fi
corpus="$src/fuzz/corpus/$name"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
artifacts="$clang_dir/fuzz-artifacts/$name"
mkdir -p "$artifacts"
# libFuzzer's default error exit code is 77, which ctest would read as "skipped": use 1.
opts=(-timeout=10 -rss_limit_mb=2048 -max_len=65536 -error_exitcode=1 -timeout_exitcode=1 -artifact_prefix="$artifacts/")
shopt -s nullglob
inputs=("$corpus"/*)
if ((${#inputs[@]} == 0)); then
  echo "fuzz: FAIL: no corpus in $corpus" >&2
  exit 1
fi
echo "fuzz $name: replaying ${#inputs[@]} corpus inputs"
if ! "$bin" "${opts[@]}" "${inputs[@]}" >"$work/replay.txt" 2>&1; then
  tail -n 40 "$work/replay.txt"
  echo "fuzz $name: FAIL: a corpus input fails (see above)" >&2
  exit 1
fi
echo "fuzz $name: $runs executions from seed 1"
set +e
"$bin" "${opts[@]}" -seed=1 -runs="$runs" -print_final_stats=1 "$work" "$corpus" >"$work/run.txt" 2>&1
rc=$?
set -e
grep -E '^stat::number_of_executed_units|^stat::new_units_added|^stat::peak_rss_mb' "$work/run.txt" || true
if ((rc != 0)); then
  tail -n 40 "$work/run.txt"
  echo "fuzz $name: FAIL: finding saved under $artifacts; copy it to fuzz/corpus/$name/regress-<what>" >&2
fi
exit "$rc"
