#!/usr/bin/env bash
# `make fuzz`: random exploration of every libFuzzer target (the clang tree, LASH_BUILD_FUZZ=ON),
# FUZZ_SECONDS each (default 600), one after the other, with a random seed. New inputs that
# reach new code go to $BUILD_CLANG/fuzz-corpus/<target>/ (kept between runs, not in the repo);
# a finding (crash, sanitizer report, timeout, leak) to $BUILD_CLANG/fuzz-artifacts/<target>/.
# Turning a finding into a regression: docs/fuzzing.md.
# Usage: scripts/fuzz.sh [target...]   (default: every fuzz_* binary)
set -uo pipefail
cd "$(dirname "$0")/.."
clang_dir=${BUILD_CLANG:-build-clang}
secs=${FUZZ_SECONDS:-600}
targets=("$@")
if ((${#targets[@]} == 0)); then
  for b in "$clang_dir"/bin/fuzz_*; do targets+=("${b##*/fuzz_}"); done
fi
status=0
for t in "${targets[@]}"; do
  bin="$clang_dir/bin/fuzz_$t"
  [[ -x "$bin" ]] || { echo "fuzz: $bin missing (make build-clang)" >&2; exit 2; }
  corpus="$clang_dir/fuzz-corpus/$t"
  artifacts="$clang_dir/fuzz-artifacts/$t"
  mkdir -p "$corpus" "$artifacts"
  echo "== fuzz_$t for $secs s (new inputs: $corpus, findings: $artifacts)"
  "$bin" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$artifacts/" "$corpus" "fuzz/corpus/$t" 2>&1 |
    grep -E '^stat::number_of_executed_units|^stat::new_units_added|^(==|SUMMARY|.*runtime error)' | head -n 20
  rc=${PIPESTATUS[0]}
  findings=$(find "$artifacts" -type f | wc -l)
  echo "fuzz_$t: exit $rc, $findings finding(s) in $artifacts"
  ((rc == 0)) || status=1
done
exit "$status"
