#!/usr/bin/env bash
# lash tune: every bad option value -> exit 2 with a message naming the option, before the search
# (no TOML left behind); the limits are in --help with the defaults.
set -uo pipefail
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail=0
check() {  # name expected-regex args...
  local name=$1 want=$2; shift 2
  local out rc outarg=(-o "$d/gains.toml")
  local samples=(--samples 10) restarts=(--restarts 1)  # a fast search, unless the case sets them
  [[ " $* " == *" -o "* ]] && outarg=()
  [[ " $* " == *" --samples "* ]] && samples=()
  [[ " $* " == *" --restarts "* ]] && restarts=()
  out=$("$LASH" tune "${samples[@]}" "${restarts[@]}" "${outarg[@]}" "$@" 2>&1); rc=$?
  if [[ $rc -ne 2 ]]; then echo "FAIL $name: exit $rc (want 2): $out"; fail=1; return; fi
  if ! grep -Eq -- "$want" <<<"$out"; then echo "FAIL $name: message '$out' lacks /$want/"; fail=1; return; fi
  if [[ -e $d/gains.toml ]]; then echo "FAIL $name: output file left behind"; fail=1; rm -f "$d/gains.toml"; return; fi
  echo "ok   $name: $out"
}
check samples_zero     "samples"                      --samples 0
check samples_negative "samples"                      --samples -5
check samples_huge     "samples.*10000000"            --samples 2000000000
check restarts_zero    "restarts"                     --restarts 0
check restarts_huge    "restarts"                     --restarts 99999
check seed_negative    "seed"                         --seed -1
check seed_text        "seed"                         --seed abc
check r0_nan           "'--r0'.*finite"               --r0 nan
check r1_inf           "'--r1'.*finite"               --r1 inf
check equal_levels     "'--r1'.*must differ from --r0" --r0 500 --r1 500
check bad_target       "'--target'"                   --target rise=-1,settling=1,overshoot=1
check bad_weights      "--weights"                    --weights speed=1
check out_no_dir       "'--output'.*directory $d/nodir does not exist" -o "$d/nodir/g.toml"
check out_is_dir       "'--output'.*is a directory"   -o "$d"
help=$("$LASH" tune --help)
for want in "1..10000000" "1..10000" "30000" "16"; do
  grep -q -- "$want" <<<"$help" && echo "ok   --help shows $want" || { echo "FAIL --help lacks $want"; fail=1; }
done
exit $fail
