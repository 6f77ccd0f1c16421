#!/usr/bin/env bash
# Runs one libFuzzer target (built in the clang tree with LASH_BUILD_FUZZ=ON, as `make test`
# does) for a bounded time, starting from the seed corpus in fuzz/corpus/<name>.
# Usage: can_fuzz.sh <dbc|log|datagram|asc|blf|trc> <seconds>
set -euo pipefail
name=$1
secs=$2
src=${LASH_SOURCE_DIR:?}
clang_dir=${LASH_CLANG_BUILD_DIR:-}
if [[ -z "$clang_dir" ]]; then
  echo "can_fuzz: LASH_CLANG_BUILD_DIR not set (configure through the Makefile); skipped" >&2
  exit 77
fi
bin="$clang_dir/bin/fuzz_can_$name"
if [[ ! -x "$bin" ]]; then
  echo "can_fuzz: FAIL: $bin missing; build the clang tree with -DLASH_BUILD_FUZZ=ON (make build-clang)" >&2
  exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
# libFuzzer's default error exit code is 77, which ctest would read as "skipped": use 1.
artifacts="$clang_dir/fuzz-artifacts/$name"
mkdir -p "$artifacts"
"$bin" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
  -error_exitcode=1 -timeout_exitcode=1 -artifact_prefix="$artifacts/" \
  "$work" "$src/fuzz/corpus/$name" 2>&1 | tail -n 25
rc=${PIPESTATUS[0]}
exit "$rc"
