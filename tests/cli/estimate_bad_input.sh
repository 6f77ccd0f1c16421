#!/usr/bin/env bash
# lash estimate, bad input -> exit 2 with a message naming file, line and column; no output left behind.
set -uo pipefail
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail=0
check() {  # name expected-regex file-content [extra args...]
  local name=$1 want=$2 content=$3; shift 3
  printf '%s' "$content" > "$d/$name.csv"
  local out rc
  out=$("$LASH" estimate --model deadzone-deadband --guess-left -350 --guess-right 350 "$d/$name.csv" \
        -o "$d/$name.out.csv" "$@" 2>&1); rc=$?
  if [[ $rc -ne 2 ]]; then echo "FAIL $name: exit $rc (want 2): $out"; fail=1; return; fi
  if ! grep -Eq -- "$want" <<<"$out"; then echo "FAIL $name: message '$out' lacks /$want/"; fail=1; return; fi
  if [[ -e $d/$name.out.csv ]]; then echo "FAIL $name: output file left behind"; fail=1; return; fi
  echo "ok   $name: $out"
}
good=$'t,v,y\n0,0,0\n0.005,1,0\n0.01,2,0\n0.015,3,0\n'
check missing_column "missing_column.csv:1: 'y'.*no such column" $'t,v,x\n0,0,0\n0.005,1,0\n0.01,2,0\n'
check empty_file     "empty_file.csv.*empty file"                ''
check header_only    "header_only.csv:1: .*no data rows"         $'t,v,y\n'
check non_numeric    "non_numeric.csv:4: 'v'"                    $'t,v,y\n0,0,0\n0.005,1,0\n0.01,abc,0\n0.015,3,0\n'
check non_monotonic  "non_monotonic.csv:4: 't'.*increase"        $'t,v,y\n0,0,0\n0.005,1,0\n0.005,2,0\n0.015,3,0\n'
check going_back     "going_back.csv:5: 't'.*increase"           $'t,v,y\n0,0,0\n0.005,1,0\n0.01,2,0\n0.002,3,0\n'
check inside_out     "guess-left.*must be < guess-right"          "$good" --guess-left 400 --guess-right 300
check equal_guesses  "guess-left.*must be < guess-right"          "$good" --guess-left 0 --guess-right 0
check bad_lambda     "lambda"                                     "$good" --lambda 1.5
check bad_model      "'--model'.*unknown model"                   "$good" --model gearbox
check renamed_cols   "renamed_cols.csv:1: 'pos'.*no such column"  "$good" --columns t,v,pos
# --nrmse-window: 0 <= T0 < T1, T0 inside the record (issue 15 item 5)
check window_negative "'--nrmse-window'.*0 <= T0 < T1"            "$good" --nrmse-window -5 -1
check window_reversed "'--nrmse-window'.*0 <= T0 < T1"            "$good" --nrmse-window 2 1
check window_past_end "window_past_end.csv: '--nrmse-window'.*not before the record's end \(0.015 s\)" "$good" --nrmse-window 5 6
# a bad config file names its line and key
printf 'model = "deadzone-deadband"\n[rls]\nlambada = 0.9\n' > "$d/bad.toml"
printf '%s' "$good" > "$d/ok.csv"
out=$("$LASH" estimate --config "$d/bad.toml" "$d/ok.csv" 2>&1); rc=$?
[[ $rc -eq 2 && $out == *"bad.toml:3"*"lambada"* ]] && echo "ok   config unknown key: $out" || { echo "FAIL config: $rc $out"; fail=1; }
out=$("$LASH" estimate --model linear "$d/none.csv" 2>&1); rc=$?
[[ $rc -eq 2 && $out == *"none.csv"* ]] && echo "ok   missing file: $out" || { echo "FAIL missing file: $rc $out"; fail=1; }
exit $fail
