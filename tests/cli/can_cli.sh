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
# A value that does not fit its bit field is an error: 700 km/h -> raw 70000 > 65535.
set +e
$L can encode --dbc "$DBC" --message IntelMix Speed=700 Temp=-20 2>"$tmp/err"; rc=$?
set -e
expect "$rc" 2
grep -q "does not fit the 16-bit unsigned field" "$tmp/err" || fail "no fit error: $(cat "$tmp/err")"

# Encode semantics (docs/can.md): unset -> GenSigStartValue else raw 0 (never clamped into
# [min|max]); outside [min|max] but fitting -> encoded as given with a warning, --clamp clamps.
cat > "$tmp/enc.dbc" <<'DBC'
VERSION ""
BU_: A
BO_ 291 E: 8 A
 SG_ Level : 0|8@1+ (1,0) [10|200] "" A
 SG_ Start : 8|8@1+ (0.5,0) [0|100] "" A
BO_ 292 Big: 8 A
 SG_ U64 : 0|64@1+ (1,0) [0|0] "" A
BO_ 293 Big2: 8 A
 SG_ S64 : 0|64@1- (1,0) [0|0] "" A
BA_DEF_ SG_ "GenSigStartValue" INT 0 255;
BA_DEF_DEF_ "GenSigStartValue" 0;
BA_ "GenSigStartValue" SG_ 291 Start 7;
DBC
expect "$($L can encode --dbc "$tmp/enc.dbc" --message E)" "123#0007000000000000"
out=$($L can encode --dbc "$tmp/enc.dbc" --message E Level=250 2>"$tmp/err")
expect "$out" "123#FA07000000000000"
grep -q "Level=250 is outside \[10|200\]: encoded as given" "$tmp/err" || fail "range warning: $(cat "$tmp/err")"
expect "$($L can encode --dbc "$tmp/enc.dbc" --message E Level=250 --clamp 2>/dev/null)" "123#C807000000000000"
set +e
$L can encode --dbc "$tmp/enc.dbc" --message E Level=256 2>/dev/null; rc=$?
set -e
expect "$rc" 2
# Exact 64-bit raw values, both ways: 1234567890123456789 = 0x112210F47DE98115 (little-endian bytes).
expect "$($L can encode --dbc "$tmp/enc.dbc" --message Big U64=1234567890123456789)" "124#1581E97DF4102211"
expect "$($L can encode --dbc "$tmp/enc.dbc" --message Big U64=18446744073709551615)" "124#FFFFFFFFFFFFFFFF"
expect "$($L can encode --dbc "$tmp/enc.dbc" --message Big2 S64=-9223372036854775808)" "125#0000000000000080"
printf '(1.000000) can0 124#1581E97DF4102211\n(2.000000) can0 124#FFFFFFFFFFFFFFFF\n(3.000000) can0 125#0000000000000080\n' > "$tmp/big.log"
$L can decode --dbc "$tmp/enc.dbc" "$tmp/big.log" > "$tmp/big.txt"
expect "$(cat "$tmp/big.txt")" "1.000000 Big U64=1234567890123456789
2.000000 Big U64=18446744073709551615
3.000000 Big2 S64=-9223372036854775808"
set +e
$L can encode --dbc "$tmp/enc.dbc" --message Big U64=18446744073709551616 2>/dev/null; rc=$?
set -e
expect "$rc" 2
# Decode.
printf '(1.000000) can0 100#D20421E0CD030000\n(1.500000) can0 300#01D204FF6A000007\n(2.000000) can0 7AB#00\n' > "$tmp/a.log"
$L can decode --dbc "$DBC" "$tmp/a.log" > "$tmp/dec.txt"
expect "$(sed -n 1p "$tmp/dec.txt")" "1.000000 IntelMix Speed=12.34 km/h Temp=-3.5 degC Count=0 Flag=0 \"Off\" Torque=-100.25 Nm Wide=0"
expect "$(sed -n 2p "$tmp/dec.txt")" "1.500000 Muxed Mode=1 \"PageB\" B_Current=1234 mA B_Offset=-1.5 V Common=7"
expect "$(sed -n 3p "$tmp/dec.txt")" "2.000000 ? 7AB#00"

# Bad input: --strict exits 2 naming file:line and column; the default reads on and
# reports the skipped statement (dbc check lists it).
printf 'VERSION ""\nBO_ 1 X: 8 A\n SG_ a : 0|8@3+ (1,0) [0|0] "" A\n' > "$tmp/bad.dbc"
set +e
$L can encode --strict --dbc "$tmp/bad.dbc" --message X 2>"$tmp/err"; rc=$?
set -e
expect "$rc" 2
grep -q "bad.dbc:3: 'SG_': column 14: byte order" "$tmp/err" || fail "DBC error: $(cat "$tmp/err")"
$L can dbc check "$tmp/bad.dbc" > "$tmp/chk.txt"
grep -q "bad.dbc:3: warning: SG_ statement skipped: column 14: byte order" "$tmp/chk.txt" || fail "check: $(cat "$tmp/chk.txt")"
# dbc check: errors exit 1 (signal beyond the frame; overlap)
printf 'BO_ 1 X: 1 A\n SG_ a : 4|8@1+ (1,0) [0|0] "" A\n SG_ b : 0|6@1+ (1,0) [0|0] "" A\n' > "$tmp/lay.dbc"
set +e
$L can dbc check "$tmp/lay.dbc" > "$tmp/chk.txt"; rc=$?
set -e
expect "$rc" 1
grep -q "signal-out-of-frame" "$tmp/chk.txt" && grep -q "share 2 bit(s) \[overlap\]" "$tmp/chk.txt" || fail "check: $(cat "$tmp/chk.txt")"
# Option limits: refused before any work, exit 2
set +e
$L can send --bus mem:x --gap -1 123#00 2>/dev/null; r1=$?
$L can dump --bus mem:x --timeout -1 2>/dev/null; r2=$?
$L can dump --bus mem:x --count 0 --timeout 1 2>/dev/null; r3=$?
$L can replay --bus mem:x --speed 0 "$tmp/big.log" 2>/dev/null; r4=$?
set -e
expect "$r1 $r2 $r3 $r4" "2 2 2 2"
# A bad log line is a counted, reported drop (file and line), the rest is decoded.
printf '(1.000000) can0 100#00\n(2.000000) can0 100#0\n(3.000000) can0 7AB#00\n' > "$tmp/bad.log"
$L can decode --dbc "$DBC" "$tmp/bad.log" > "$tmp/dec.txt" 2>"$tmp/err"
expect "$(wc -l < "$tmp/dec.txt")" 2
grep -q "dropped: .*bad.log:2: candump line: bad hex data" "$tmp/err" || fail "log drop: $(cat "$tmp/err")"
grep -q "1 of 3 records of .*bad.log dropped" "$tmp/err" || fail "log drop count: $(cat "$tmp/err")"
# A file that is no log at all: exit 2.
printf 'not a blf' > "$tmp/x.blf"
set +e
$L can decode --dbc "$DBC" "$tmp/x.blf" > /dev/null 2>"$tmp/err"; rc=$?
set -e
expect "$rc" 2
grep -q "x.blf.*not a BLF file" "$tmp/err" || fail "blf error: $(cat "$tmp/err")"
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
