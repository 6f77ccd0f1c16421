#!/usr/bin/env bash
# EMPS recipe through the CLI (docs/emps.md): lash estimate reads the MAT file in place with
# config/emps_friction.toml; Coulomb force c/K per side within 5 % of the authors' +20.14 N /
# -20.63 N on DATA_EMPS.mat and within 10 % on DATA_EMPS_PULSES.mat. A MAT file without the
# named variable exits 2 naming the file and the variable.
# Skipped (exit 77) when ../shared/data/emps is absent.
set -uo pipefail
dir=${LASH_EMPS_DIR:-$LASH_SOURCE_DIR/../shared/data/emps}
if [[ ! -f $dir/DATA_EMPS.mat ]]; then
  echo "SKIPPED: EMPS data not found at $dir (expected ../shared/data/emps next to the repository)"
  exit 77
fi
if ! "$LASH" --help 2>/dev/null | grep -qE "^ +estimate"; then
  echo "SKIPPED: this lash has no 'estimate' command yet"
  exit 77
fi
fail=0
for rec in DATA_EMPS:0.05 DATA_EMPS_PULSES:0.10; do
  name=${rec%%:*}; tol=${rec##*:}
  out=$("$LASH" estimate "$dir/$name.mat" --config "$LASH_SOURCE_DIR/config/emps_friction.toml" --json 2>&1) || {
    echo "FAIL $name: lash estimate failed: $out"; fail=1; continue; }
  "$LASH_PY" - "$name" "$tol" "$out" <<'PY' || fail=1
import json, sys
name, tol, text = sys.argv[1], float(sys.argv[2]), sys.argv[3]
j = json.loads(text.strip().splitlines()[-1])
ok = True
for side, ref in (("right", 20.14), ("left", -20.63)):
    p = j[side]
    K = p["b1"] / (1 + p["a1"])
    fc = p["c"] / K
    good = abs(fc / ref - 1) <= tol
    ok = ok and good and p["identified"]
    print(f"{'ok  ' if good else 'FAIL'} {name} {side}: c/K = {fc:.3f} N (authors {ref} N, tolerance {tol:.0%})")
sys.exit(0 if ok else 1)
PY
done
# A MAT file without the named variable -> exit 2 naming file and variable.
out=$("$LASH" estimate "$dir/DATA_EMPS.mat" --model output-deadzone --columns t,vir,velocity 2>&1); rc=$?
if [[ $rc -ne 2 || $out != *DATA_EMPS.mat* || $out != *velocity* ]]; then
  echo "FAIL missing variable: exit $rc: $out"; fail=1
else
  echo "ok   missing variable: $out"
fi
exit $fail
