#!/usr/bin/env bash
# Same seed -> byte-identical CSV from the g++ build and from the clang build.
set -euo pipefail
clang_lash="${LASH_CLANG_BUILD_DIR:-}/bin/lash"
if [[ ! -x $clang_lash ]]; then
  echo "SKIP: no clang build at '$clang_lash' (make test builds one)"; exit 77
fi
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
plant="$LASH_SOURCE_DIR/config/plants/thesis_eq34.toml"
for input in randomized sine; do
  args=(simulate "$plant" --input "$input" --amplitude 600 --duration 60 --noise-variance 200 --seed 17)
  "$LASH" "${args[@]}" -o "$d/gcc.csv"
  "$clang_lash" "${args[@]}" -o "$d/clang.csv"
  cmp "$d/gcc.csv" "$d/clang.csv"
  echo "$input: identical ($(wc -l < "$d/gcc.csv") lines, sha256 $(sha256sum < "$d/gcc.csv" | cut -c1-16))"
done
# and a different seed really changes the bits
"$LASH" simulate "$plant" --input randomized --duration 10 --seed 18 -o "$d/other.csv"
"$LASH" simulate "$plant" --input randomized --duration 10 --seed 17 -o "$d/same.csv"
! cmp -s "$d/other.csv" "$d/same.csv"
