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
out=$("$LASH" simulate "$d/nope.toml" -o "$d/x.csv" 2>&1); rc=$?
[[ $rc -eq 2 && $out == *"nope.toml: no such file"* && ! -e $d/x.csv ]] || { echo "FAIL missing file: $rc $out"; fail=1; }
# An existing output is never replaced by a half-written one.
echo "precious" > "$d/keep.csv"
printf '%s' $'dt = 0.01\n[[blocks]]\nkind = "nope"\n' > "$d/bad.toml"
"$LASH" simulate "$d/bad.toml" -o "$d/keep.csv" 2>/dev/null
[[ $(cat "$d/keep.csv") == precious ]] || { echo "FAIL: existing output was touched"; fail=1; }
exit $fail
