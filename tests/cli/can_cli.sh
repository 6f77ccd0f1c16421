#!/usr/bin/env bash
# lash can encode/decode against hand-computed frames; bad input exits 2 naming file,
# line and column; nothing half-written.
set -euo pipefail
L=${LASH:?}
DBC=${LASH_SOURCE_DIR:?}/tests/data/can/lash_test.dbc
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
expect() { [[ "$1" == "$2" ]] || fail "expected '$2', got '$1'"; }

# IntelMix: Speed 12.34/0.01 = 1234 = 0x04D2 -> D2 04; Temp (-3.5+20)/0.5 = 33 = 0x21;
# Torque -100.25/0.25 = -401 -> 13-bit 0x1E6F at bit 29: byte3 = 0xE0, byte4 = 0xCD, byte5 = 0x03.
expect "$($L can encode --dbc "$DBC" --message IntelMix Speed=12.34 Temp=-3.5 Torque=-100.25)" "100#D20421E0CD030000"
# Round to nearest: 12.346 -> 1234.6 -> 1235 = 0x04D3 (truncation would give D2).
expect "$($L can encode --dbc "$DBC" --message IntelMix Speed=12.346 Temp=-20)" "100#D304000000000000"
# MotorolaMix: Pressure 1234.5/0.1 = 12345 = 0x3039, MSB first at 7|16 -> 30 39.
expect "$($L can encode --dbc "$DBC" --message MotorolaMix Pressure=1234.5)" "200#3039000000000000"
# Clamped values are reported on stderr; 700 km/h > 655.35 -> raw 65535.
out=$($L can encode --dbc "$DBC" --message IntelMix Speed=700 Temp=-20 2>"$tmp/err")
expect "$out" "100#FFFF000000000000"
grep -q "1 value(s) clamped" "$tmp/err" || fail "clamp not reported"
# Decode.
printf '(1.000000) can0 100#D20421E0CD030000\n(1.500000) can0 300#01D204FF6A000007\n(2.000000) can0 7AB#00\n' > "$tmp/a.log"
$L can decode --dbc "$DBC" "$tmp/a.log" > "$tmp/dec.txt"
expect "$(sed -n 1p "$tmp/dec.txt")" "1.000000 IntelMix Speed=12.34 km/h Temp=-3.5 degC Count=0 Flag=0 \"Off\" Torque=-100.25 Nm Wide=0"
expect "$(sed -n 2p "$tmp/dec.txt")" "1.500000 Muxed Mode=1 \"PageB\" B_Current=1234 mA B_Offset=-1.5 V Common=7"
expect "$(sed -n 3p "$tmp/dec.txt")" "2.000000 ? 7AB#00"

# Bad input: exit 2, file:line and column named.
printf 'VERSION ""\nBO_ 1 X: 8 A\n SG_ a : 0|8@3+ (1,0) [0|0] "" A\n' > "$tmp/bad.dbc"
set +e
$L can encode --dbc "$tmp/bad.dbc" --message X 2>"$tmp/err"; rc=$?
set -e
expect "$rc" 2
grep -q "bad.dbc:3: 'SG_': column 14: byte order" "$tmp/err" || fail "DBC error: $(cat "$tmp/err")"
printf '(1.000000) can0 100#00\n(2.000000) can0 100#0\n' > "$tmp/bad.log"
set +e
$L can decode --dbc "$DBC" "$tmp/bad.log" > /dev/null 2>"$tmp/err"; rc=$?
set -e
expect "$rc" 2
grep -q "bad.log:2" "$tmp/err" || fail "log error: $(cat "$tmp/err")"
set +e
$L can send --bus mem:x 123#GG 2>"$tmp/err"; rc1=$?
$L can dump --bus nope:x --log "$tmp/never.log" 2>/dev/null; rc2=$?
$L can dump --bus socketcan:lash_nosuch0 --count 1 2>"$tmp/err2"; rc3=$?
$L can dump --bus mem:x --filter 12:7FF --count 1 2>/dev/null; rc4=$?
set -e
expect "$rc1 $rc2 $rc3 $rc4" "2 2 2 2"
[[ ! -e "$tmp/never.log" ]] || fail "a log file was left behind"
grep -q "socketcan" "$tmp/err2" || fail "socketcan error: $(cat "$tmp/err2")"
echo "can_cli: ok"
