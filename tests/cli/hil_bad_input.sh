#!/usr/bin/env bash
# Bad input to lash hil: exit 2 with a message naming file, line and field; nothing written.
# A master without a slave: exit 1 with a clear error after the DTO timeout.
# `lash hil latency`: the loop alone runs its 200 steps and reports them.
set -u
fail() { echo "FAIL: $*"; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
src=${LASH_SOURCE_DIR}

expect2() {  # expect2 PATTERN ARGS...
  local pat=$1; shift
  "$LASH" "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  [[ $rc == 2 ]] || fail "expected exit 2, got $rc: $* ($(cat "$tmp/err"))"
  grep -q -- "$pat" "$tmp/err" || fail "message lacks '$pat': $(cat "$tmp/err")"
  echo "ok (exit 2): $(head -1 "$tmp/err")"
}

expect2 "--reference" hil simulate --reference bogus:amplitude=1 -o "$tmp/a.csv"
expect2 "--reference" hil simulate --reference square:amplitude=x -o "$tmp/a.csv"
expect2 "--duration" hil simulate --duration 0 -o "$tmp/a.csv"
# --schedule: the run's master.csv / slave.csv (issue 15 item 7); bad logs name file, line, column.
mkdir -p "$tmp/run"
printf 'step,control_step,sensor_seq,dropped,measured_kPa,current_mA\n0,-1,-1,0,0,0\n1,0,0,0,0,0\n2,1,1,0,0,0\n' >"$tmp/run/master.csv"
printf 'step,command_counter,command_fresh,dropped\n0,0,0,0\n1,0,1,0\n' >"$tmp/run/slave.csv"
expect2 "--schedule" hil simulate --schedule "$tmp/nope.csv" -o "$tmp/a.csv"
expect2 "--schedule" hil simulate --slave-schedule "$tmp/run/slave.csv" -o "$tmp/a.csv"
printf 'step,control_step,dropped\n1,0,0\n' >"$tmp/run/noseq.csv"
cp "$tmp/run/slave.csv" "$tmp/slave.csv"
expect2 "noseq.csv:1: 'sensor_seq'" hil simulate --schedule "$tmp/run/noseq.csv" --slave-schedule "$tmp/slave.csv" -o "$tmp/a.csv"
printf 'step,control_step,sensor_seq,dropped,measured_kPa,current_mA\n1,0,0,0,0,0\n2,1,0.5,0,0,0\n' >"$tmp/run/frac.csv"
expect2 "frac.csv:3: 'sensor_seq'.*integer" hil simulate --schedule "$tmp/run/frac.csv" --slave-schedule "$tmp/slave.csv" -o "$tmp/a.csv"
printf 'step,command_counter,command_fresh,dropped\n0,0,0,0\n1,0,2,0\n' >"$tmp/run/slave2.csv"
expect2 "slave2.csv:3: 'command_fresh'.*0 or 1" hil simulate --schedule "$tmp/run/master.csv" --slave-schedule "$tmp/run/slave2.csv" -o "$tmp/a.csv"
[[ -e "$tmp/a.csv" ]] && fail "output written despite bad input"

write_cfg() {  # write_cfg EXTRA_CONTROLLER_LINE [DTO_LOG]
  cat >"$tmp/bench.toml" <<TOML
dbc = "$src/config/hydraulic_bench.dbc"
dto_log = "${2:-$src/config/hil/ccp_connect.log}"
[controller]
kp = 1.0
$1
TOML
}
write_cfg "ki_per_s = -3"
expect2 "bench.toml:5" hil simulate --config "$tmp/bench.toml" -o "$tmp/b.csv"
write_cfg "kq = 3"
expect2 "kq" hil simulate --config "$tmp/bench.toml" -o "$tmp/b.csv"
printf '(1.000000) can0 7E0#0100000000000000\n(1.000100) can0 123#00\n' >"$tmp/nodto.log"
write_cfg "" "$tmp/nodto.log"
expect2 "nodto.log" hil simulate --config "$tmp/bench.toml" -o "$tmp/b.csv"
[[ -e "$tmp/b.csv" ]] && fail "output written despite bad input"

# Controller override flags (from the field table, after the settings' controller): bad values
# exit 2 naming the flag; with --scenario refused; --dt-s is not one (the step is --step-ms).
expect2 "'--kp'.*>= 0" hil simulate --kp -1 -o "$tmp/d.csv"
expect2 "'--max-mA'.*min_mA <= max_mA" hil simulate --max-mA -5 -o "$tmp/d.csv"
expect2 "'--anti-windup'" hil master --bus mem:x --anti-windup soft --log "$tmp/d.csv"
expect2 "'--ki-per-s'.*scenario" hil simulate --ki-per-s 3 --scenario "$src/config/scenarios/closed_loop/valve_no_drift.toml" -o "$tmp/d.csv"
expect2 "dt-s" hil simulate --dt-s 0.001 -o "$tmp/d.csv"
[[ -e "$tmp/d.csv" ]] && fail "output written despite bad input"
# Identity: a flag gives the same run as the same key in the gains file.
sed -e 's/^kp = .*/kp = 0.9/' "$src/config/control/lash_gains.toml" >"$tmp/gains_kp.toml"
grep -q "^kp = 0.9$" "$tmp/gains_kp.toml" || fail "lash_gains.toml changed: update this test"
for g in "$src/config/control/lash_gains.toml" "$tmp/gains_kp.toml"; do
  sed -e "s|^controller = .*|controller = \"$g\"|" -e "s|^dbc = .*|dbc = \"$src/config/hydraulic_bench.dbc\"|" \
      -e "s|^dto_log = .*|dto_log = \"$src/config/hil/ccp_connect.log\"|" "$src/config/hil/bench.toml" >"$tmp/$(basename "$g").bench.toml"
done
"$LASH" hil simulate --config "$tmp/lash_gains.toml.bench.toml" --kp 0.9 --duration 2 -o "$tmp/flag.csv" 2>/dev/null || fail "hil simulate --kp failed"
"$LASH" hil simulate --config "$tmp/gains_kp.toml.bench.toml" --duration 2 -o "$tmp/file.csv" 2>/dev/null || fail "hil simulate (kp in file) failed"
"$LASH" hil simulate --config "$tmp/lash_gains.toml.bench.toml" --duration 2 -o "$tmp/base.csv" 2>/dev/null || fail "hil simulate failed"
cmp -s "$tmp/flag.csv" "$tmp/file.csv" || fail "hil simulate --kp 0.9 differs from kp = 0.9 in the gains file"
cmp -s "$tmp/flag.csv" "$tmp/base.csv" && fail "--kp 0.9 changed nothing"
echo "ok: hil simulate --kp 0.9 = kp = 0.9 in the gains file (and differs from the shipped kp)"

expect2 "--spin-us" hil master --bus mem:x --spin-us 5000 --log "$tmp/c.csv"
expect2 "--spin-us" hil slave --bus mem:x --spin-us -1 --log "$tmp/c.csv"
[[ -e "$tmp/c.csv" ]] && fail "log written despite bad input"

expect2 "--duration" hil latency --duration 0
expect2 "--step-ms" hil latency --step-ms -1
"$LASH" hil latency --duration 0.2 --step-ms 1 --json >"$tmp/lat.json" || fail "hil latency failed"
grep -q '"steps": 200' "$tmp/lat.json" || fail "hil latency: expected 200 steps: $(head -c 300 "$tmp/lat.json")"
grep -q '"wake_latency_us"' "$tmp/lat.json" || fail "hil latency: no wake_latency_us"
echo "ok: hil latency ran 200 steps"

# No slave on an in-process bus: the master gives up after its DTO timeout.
"$LASH" hil master --bus mem:lonely --dto-timeout 0.1 --duration 1 --log "$tmp/m.csv" 2>"$tmp/err"; rc=$?
[[ $rc == 1 ]] || fail "master without slave: expected exit 1, got $rc"
grep -q "no positive DTO reply to CCP CONNECT" "$tmp/err" || fail "no clear DTO timeout message: $(cat "$tmp/err")"
grep -q "dto_timeout" "$tmp/m.events.csv" || fail "DTO timeout not in the events log"
echo "ok (exit 1): $(grep error "$tmp/err")"
echo PASS
