#!/usr/bin/env bash
# lash sweep: a bad campaign file -> exit 2, a message naming file, line and key, no CSV left behind.
set -uo pipefail
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail=0
head=$'name = "t"\nrig = "motor_cart"\ndt_s = 0.001\nduration_s = 1.0\n'
matrix=$'[matrix]\nwaveforms = ["sine"]\namplitudes = [4.0]\nfrequencies_rad_s = [2.0]\nrepeats = 1\n'
check() {  # name expected-regex content
  local name=$1 want=$2 content=$3
  printf '%s' "$content" > "$d/$name.toml"
  local out rc
  out=$("$LASH" sweep "$d/$name.toml" -q -o "$d/$name.csv" 2>&1); rc=$?
  if [[ $rc -ne 2 ]]; then echo "FAIL $name: exit $rc (want 2): $out"; fail=1; return; fi
  if ! grep -Eq -- "$want" <<<"$out"; then echo "FAIL $name: message '$out' lacks /$want/"; fail=1; return; fi
  if ls "$d" | grep -q "^$name.csv"; then echo "FAIL $name: output file left behind"; fail=1; return; fi
  echo "ok   $name: $out"
}
check unknown_key      "unknown_key.toml:5: 'colour'.*unknown key"               "${head}colour = 3"$'\n'"$matrix"
check unknown_mkey     "unknown_mkey.toml:[0-9]+: 'matrix.repeat'.*unknown key"   "${head}"$'[matrix]\nwaveforms = ["sine"]\namplitudes = [4.0]\nfrequencies_rad_s = [2.0]\nrepeats = 1\nrepeat = 2\n'
check unknown_est      "unknown_est.toml:[0-9]+: 'estimator.lamda'.*unknown key"  "${head}${matrix}"$'[estimator]\nlamda = 0.99\n'
check unknown_rig_key  "unknown_rig_key.toml:[0-9]+: 'rig_params.mass'.*unknown key" "${head}${matrix}"$'[rig_params]\nmass = 3.0\n'
check empty_amplitudes "empty_amplitudes.toml:7: 'matrix.amplitudes'.*empty"     "${head}"$'[matrix]\nwaveforms = ["sine"]\namplitudes = []\nfrequencies_rad_s = [2.0]\nrepeats = 1\n'
check empty_waveforms  "empty_waveforms.toml:6: 'matrix.waveforms'.*empty"       "${head}"$'[matrix]\nwaveforms = []\namplitudes = [1.0]\nfrequencies_rad_s = [2.0]\nrepeats = 1\n'
check no_runs          "no_runs.toml:[0-9]+: 'randomized'.*no runs"               "${head}"$'[randomized]\nruns = 0\n'
check zero_duration    "zero_duration.toml:4: 'duration_s'.*> 0"                $'name = "t"\nrig = "motor_cart"\ndt_s = 0.001\nduration_s = 0.0\n'"$matrix"
check neg_duration     "neg_duration.toml:4: 'duration_s'.*> 0"                 $'name = "t"\nrig = "motor_cart"\ndt_s = 0.001\nduration_s = -30\n'"$matrix"
check zero_dt          "zero_dt.toml:3: 'dt_s'.*> 0"                            $'name = "t"\nrig = "motor_cart"\ndt_s = 0\nduration_s = 1.0\n'"$matrix"
check unknown_rig      "unknown_rig.toml:2: 'rig'.*unknown rig"                 $'name = "t"\nrig = "tractor"\ndt_s = 0.001\nduration_s = 1.0\n'"$matrix"
check bad_waveform     "bad_waveform.toml:6: 'matrix.waveforms'.*sawtooth"      "${head}"$'[matrix]\nwaveforms = ["sawtooth"]\namplitudes = [1.0]\nfrequencies_rad_s = [2.0]\nrepeats = 1\n'
check bad_lambda       "bad_lambda.toml:[0-9]+: 'estimator'.*lambda"              "${head}${matrix}"$'[estimator]\nmodel = "output-deadzone"\n[estimator.rls]\nlambda = 1.5\n'
check bad_rig_value    "bad_rig_value.toml:[0-9]+: 'rig_params'.*mass_kg"         "${head}${matrix}"$'[rig_params]\nmass_kg = -1.0\n'
check bad_model        "bad_model.toml:[0-9]+: 'estimator.model'"                 "${head}${matrix}"$'[estimator]\nmodel = "quadratic"\n'
check model_for_rig    "model_for_rig.toml:[0-9]+: 'estimator.model'.*linear.*motor_cart" "${head}${matrix}"$'[estimator]\nmodel = "linear"\n'
# Options (issue 15 item 5): each bad value -> exit 2 naming the option, before any run (no CSV).
printf '%s' "${head}${matrix}" > "$d/good.toml"
opt() {  # name expected-regex args...
  local name=$1 want=$2; shift 2
  local out rc
  out=$("$LASH" sweep "$d/good.toml" -q "$@" 2>&1); rc=$?
  if [[ $rc -ne 2 ]]; then echo "FAIL $name: exit $rc (want 2): $out"; fail=1; return; fi
  if ! grep -Eq -- "$want" <<<"$out"; then echo "FAIL $name: message '$out' lacks /$want/"; fail=1; return; fi
  if [[ -e $d/opt.csv ]]; then echo "FAIL $name: output file left behind"; fail=1; rm -f "$d/opt.csv"; return; fi
  echo "ok   $name: $out"
}
opt jobs_negative  "jobs"                                   -j -1 -o "$d/opt.csv"
opt jobs_huge      "jobs.*1024"                             -j 100000 -o "$d/opt.csv"
opt jobs_text      "jobs"                                   -j many -o "$d/opt.csv"
opt out_no_dir     "'--output'.*directory $d/nodir does not exist" -o "$d/nodir/x.csv"
opt out_is_dir     "'--output'.*is a directory"             -o "$d"
opt plot_no_dir    "'--plot'.*directory $d/nodir does not exist" -o "$d/opt.csv" --plot "$d/nodir/x.png"
opt trace_no_dir   "'--trace'.*directory $d/nodir does not exist" -o "$d/opt.csv" --trace 0 "$d/nodir/t.csv"
opt trace_no_run   "'--trace'.*run 7 does not exist"        -o "$d/opt.csv" --trace 7 "$d/t.csv"
opt trace_bad_run  "'--trace'.*RUN must be a run number"    -o "$d/opt.csv" --trace -1 "$d/t.csv"
"$LASH" sweep --help | grep -q -- "0..1024 (0 = all cores)" && echo "ok   --help shows the --jobs limits" || { echo "FAIL --help lacks the --jobs limits"; fail=1; }
out=$("$LASH" sweep "$d/nope.toml" -q -o "$d/x.csv" 2>&1); rc=$?
[[ $rc -eq 2 && $out == *"nope.toml: no such file"* && ! -e $d/x.csv ]] || { echo "FAIL missing file: $rc $out"; fail=1; }
exit $fail
