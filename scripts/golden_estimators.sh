#!/usr/bin/env bash
# Golden outputs of the estimators, to show that a change of the estimator code changes no number.
#
#   scripts/golden_estimators.sh save  DIR [BUILD]   # write every output into DIR (before the change)
#   scripts/golden_estimators.sh check DIR [BUILD]   # write them again into DIR.new and cmp each file
#
# BUILD is the CMake build tree (default: build); the script builds lash and lash_golden_dump in it.
# What is written (one file each, compared byte for byte):
#   dump.txt                 bench/golden_dump.cpp: every estimator x settings on the generic tester's
#                            record (tests/unit/test_estimators_generic.cpp), a hash of every
#                            observable after every sample and the final values (%a)
#   generic_tester.txt       the generic tester's test list and verdicts (without timings); check
#                            compares the tests of the saved list (tests added since are listed)
#   demo.txt                 `lash demo`: E1/E2 tables and the E2 comparison (docs/method.md §A7)
#   est_REC_MODEL_PRESET.json / .csv   `lash estimate REC --model MODEL --preset PRESET --json`
#                            and its per-step trace (-o: y, yhat, y_sim, every parameter)
#   emps_REC.json            the EMPS recipe (config/emps_friction.toml)
#   cl_SCENARIO_MODE.json / .csv        `lash closed-loop --scenario S --compensation MODE --json -o`
# Records: three `lash simulate` records (thesis eq. 34 plant: sine, square + noise; the fig. 1.16
# plant: randomized + noise) and, when ../shared/data/emps is there, the two EMPS records.
# Exit status: 0 when every cmp is equal, 1 otherwise (check), 2 on a usage error.
set -euo pipefail
mode=${1:-}; out=${2:-}; build=${3:-build}
if [[ ($mode != save && $mode != check) || -z $out ]]; then
  sed -n '2,7p' "$0"; exit 2
fi
src=$(cd "$(dirname "$0")/.." && pwd)
[[ $mode == check ]] && dir=$out.new || dir=$out
rm -rf "$dir"; mkdir -p "$dir"
cmake --build "$build" -j2 --target lash lash_golden_dump test_estimators_generic >/dev/null
lash=$build/bin/lash
[[ -x $lash ]] || lash=$(find "$build" -name lash -type f -perm -u+x | head -1)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

"$(find "$build" -name lash_golden_dump -type f -perm -u+x | head -1)" > "$dir/dump.txt"
gt=$(find "$build" -name test_estimators_generic -type f -perm -u+x | head -1)
"$gt" --gtest_print_time=0 --gtest_color=no 2>&1 | grep -E '^\[ +(OK|FAILED) +\]|^\[ RUN' > "$dir/generic_tester.txt"
# without the lines that carry a wall time or the temporary folder
"$lash" demo --out-dir "$tmp/demo" 2>/dev/null | grep -v "^wrote \|wall time" > "$dir/demo.txt"

plants=$src/config/plants
"$lash" simulate "$plants/thesis_eq34.toml" --input sine --amplitude 600 --frequency 1 --duration 60 -o "$tmp/sine.csv" >/dev/null
"$lash" simulate "$plants/thesis_eq34.toml" --input square --amplitude 500 --frequency 0.8 --duration 60 \
  --noise-variance 4 --seed 3 -o "$tmp/square.csv" >/dev/null
"$lash" simulate "$plants/fig1_16_g_dz_db.toml" --input randomized --variance 90000 --tau 0.3 --duration 40 \
  --noise-variance 1 --seed 7 -o "$tmp/random.csv" >/dev/null
models="linear input-deadzone output-deadzone deadzone-deadband coupled-carts"
for rec in sine square random; do
  for m in $models; do
    for p in lash thesis; do
      f=$dir/est_${rec}_${m}_${p}
      "$lash" estimate "$tmp/$rec.csv" --model "$m" --preset "$p" --json -o "$f.csv" > "$f.json" 2>/dev/null || echo "exit $?" >> "$f.json"
    done
  done
done
emps=${LASH_EMPS_DIR:-$src/../shared/data/emps}
if [[ -f $emps/DATA_EMPS.mat ]]; then
  for rec in DATA_EMPS DATA_EMPS_PULSES; do
    "$lash" estimate "$emps/$rec.mat" --config "$src/config/emps_friction.toml" --json > "$dir/emps_$rec.json"
    for m in $models; do
      for p in lash thesis; do
        f=$dir/est_${rec}_${m}_${p}
        "$lash" estimate "$emps/$rec.mat" --columns "t,gtau*vir,diff(qm)/0.001" --model "$m" --preset "$p" --json \
          -o "$f.csv" > "$f.json" 2>/dev/null || echo "exit $?" >> "$f.json"
      done
    done
  done
fi
for s in "$src"/config/scenarios/closed_loop/*.toml; do
  n=$(basename "$s" .toml)
  for c in none fixed adaptive; do
    "$lash" closed-loop --scenario "$s" --compensation "$c" --json -o "$dir/cl_${n}_$c.csv" > "$dir/cl_${n}_$c.json"
  done
done

echo "$(ls "$dir" | wc -l) files in $dir"
[[ $mode == save ]] && exit 0
# tests added since the save: compared are the saved ones, in their order
grep -Fx -f "$out/generic_tester.txt" "$dir/generic_tester.txt" > "$tmp/gt" || true
added=$(grep -Fxv -f "$out/generic_tester.txt" "$dir/generic_tester.txt" | grep -c '^\[ RUN' || true)
[[ $added == 0 ]] || echo "generic tester: $added tests added since the save (not compared)"
mv "$tmp/gt" "$dir/generic_tester.txt"
bad=0; n=0
for f in "$out"/*; do
  b=$(basename "$f"); n=$((n + 1))
  if cmp -s "$f" "$dir/$b"; then echo "same  $b"; else echo "DIFF  $b"; bad=$((bad + 1)); fi
done
[[ $(ls "$out" | wc -l) == $(ls "$dir" | wc -l) ]] || { echo "DIFF  the file lists differ"; bad=$((bad + 1)); }
echo "$((n - bad)) of $n files byte-identical"
[[ $bad == 0 ]]
