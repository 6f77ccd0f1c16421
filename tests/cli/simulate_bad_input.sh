#!/usr/bin/env bash
# Bad input -> exit 2, a message naming file, line and key, and no output file left behind.
set -uo pipefail
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail=0
check() {  # name expected-regex file-content [extra args...]
  local name=$1 want=$2 content=$3; shift 3
  printf '%s' "$content" > "$d/$name.toml"
  local out rc
  out=$("$LASH" simulate "$d/$name.toml" --amplitude 600 --duration 1 -o "$d/$name.csv" "$@" 2>&1); rc=$?
  if [[ $rc -ne 2 ]]; then echo "FAIL $name: exit $rc (want 2): $out"; fail=1; return; fi
  if ! grep -Eq -- "$want" <<<"$out"; then echo "FAIL $name: message '$out' lacks /$want/"; fail=1; return; fi
  if ls "$d" | grep -q "^$name.csv"; then echo "FAIL $name: output file left behind"; fail=1; return; fi
  echo "ok   $name: $out"
}
ok_plant=$'dt = 0.01\n[[blocks]]\nkind = "deadzone"\nleft = -1\nright = 1\n'
check malformed      "malformed.toml:3: .*TOML syntax"            $'dt = 0.01\n[[blocks]]\nkind = "dead\n'
check unknown_kind   "unknown_kind.toml:3: 'blocks\[0\].kind'"   $'dt = 0.01\n[[blocks]]\nkind = "gearbox"\n'
check inside_out     "inside_out.toml:4: 'blocks\[0\].left'.*c_l <= c_r" $'dt = 0.01\n[[blocks]]\nkind = "deadzone"\nleft = 5.0\nright = -5.0\n'
check neg_half_width "neg_half_width.toml:4: 'blocks\[0\].half_width'" $'dt = 0.01\n[[blocks]]\nkind = "deadband"\nhalf_width = { left = -1.0, right = 3.0 }\n'
check nan_number     "nan_number.toml:4: 'blocks\[0\].left'.*finite" $'dt = 0.01\n[[blocks]]\nkind = "deadzone"\nleft = nan\nright = 1\n'
check inf_number     "inf_number.toml:5: 'blocks\[0\].b1'.*finite" $'dt = 0.01\n[[blocks]]\nkind = "linear"\na1 = -0.9\nb1 = inf\n'
check missing_number "missing_number.toml:2: 'blocks\[0\].right'.*missing" $'dt = 0.01\n[[blocks]]\nkind = "deadzone"\nleft = -1\n'
check dt_zero        "dt_zero.toml:1: 'dt'"                        $'dt = 0\n[[blocks]]\nkind = "deadzone"\nleft = -1\nright = 1\n'
check dt_missing     "dt_missing.toml:1: 'dt'.*missing"            $'[[blocks]]\nkind = "deadzone"\nleft = -1\nright = 1\n'
check string_number  "string_number.toml:4: 'blocks\[0\].left'.*number" $'dt = 0.01\n[[blocks]]\nkind = "deadzone"\nleft = "x"\nright = 1\n'
check unknown_key    "unknown_key.toml:6: 'blocks\[0\].widht'.*unknown key" $'dt = 0.01\n[[blocks]]\nkind = "deadzone"\nleft = -1\nright = 1\nwidht = 3\n'
check unknown_input  "'--input'.*unknown input kind 'sawtooth'"    "$ok_plant" --input sawtooth
check bad_dt_option  "dt"                                          "$ok_plant" --dt -1
# --input-file (a t,v CSV, e.g. from lash excite): t must step by the plant's dt; v must be numbers
printf 't,v\n0,1\n0.02,2\n0.04,3\n' > "$d/in_dt.csv"
check input_file_dt  "'--input-file'.*t steps by 0.02 s, the plant's dt is 0.01 s \(give --dt 0.02\)" "$ok_plant" --input-file "$d/in_dt.csv"
printf 't,v\n0,1\n0.01,x\n' > "$d/in_text.csv"
check input_file_text "in_text.csv:3: 'v'"                          "$ok_plant" --input-file "$d/in_text.csv"
printf 't,x\n0,1\n0.01,2\n' > "$d/in_col.csv"
check input_file_col "in_col.csv:1: 'v'.*no such column"            "$ok_plant" --input-file "$d/in_col.csv"
printf 't,v\n0,1e300\n0.01,2\n' > "$d/in_big.csv"
check input_file_big "'--input-file'.*at most"                      $'dt = 0.01\n[[blocks]]\nkind = "linear"\na1 = -0.5\nb1 = 10\n' --input-file "$d/in_big.csv"
# and replays the file: v column of the output equals the input's v, then holds the last value
printf 't,v\n0,1.5\n0.01,-2\n0.02,7\n' > "$d/in_ok.csv"
printf '%s' "$ok_plant" > "$d/ok.toml"
v=$("$LASH" simulate "$d/ok.toml" --input-file "$d/in_ok.csv" --duration 0.05 -o - 2>/dev/null | cut -d, -f2 | tr '\n' ' ')
[[ $v == "v 1.5 -2 7 7 7 " ]] && echo "ok   --input-file replayed: $v" || { echo "FAIL --input-file replay: '$v'"; fail=1; }
n=$("$LASH" simulate "$d/ok.toml" --input-file "$d/in_ok.csv" -o - 2>/dev/null | wc -l)
[[ $n -eq 4 ]] && echo "ok   --duration defaults to the file's length" || { echo "FAIL default duration: $n lines"; fail=1; }
out=$("$LASH" simulate "$d/nope.toml" -o "$d/x.csv" 2>&1); rc=$?
[[ $rc -eq 2 && $out == *"nope.toml: no such file"* && ! -e $d/x.csv ]] || { echo "FAIL missing file: $rc $out"; fail=1; }
# An existing output is never replaced by a half-written one.
echo "precious" > "$d/keep.csv"
printf '%s' $'dt = 0.01\n[[blocks]]\nkind = "nope"\n' > "$d/bad.toml"
"$LASH" simulate "$d/bad.toml" -o "$d/keep.csv" 2>/dev/null
[[ $(cat "$d/keep.csv") == precious ]] || { echo "FAIL: existing output was touched"; fail=1; }
exit $fail
