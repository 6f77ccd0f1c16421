#!/usr/bin/env bash
# Every option of the real-time hil subcommands is checked before any work (issue 15 item 5):
# each bad value gives exit 2 and a message naming the option, at once, with nothing written
# (no abort, no memory exhaustion); --help shows the limits and defaults.
set -u
fail() { echo "FAIL: $*"; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1

expect2() {  # expect2 PATTERN ARGS...
  local pat=$1; shift
  local t0=$SECONDS
  timeout 20 "$LASH" "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  [[ $rc == 2 ]] || fail "expected exit 2, got $rc: $* ($(head -3 "$tmp/err"))"
  grep -q -- "$pat" "$tmp/err" || fail "message lacks '$pat': $* -> $(cat "$tmp/err")"
  (( SECONDS - t0 <= 5 )) || fail "took $((SECONDS - t0)) s to refuse: $*"
  echo "ok (exit 2): $* -> $(grep -m1 -i 'error\|--' "$tmp/err")"
}

for sub in "hil run --out-dir $tmp/o" "hil master --bus mem:x --log $tmp/m.csv" "hil slave --bus mem:x --log $tmp/s.csv" \
           "hil latency"; do
  # shellcheck disable=SC2086
  set -- $sub
  expect2 "--fifo" "$@" --fifo 500
  expect2 "--fifo" "$@" --fifo -1
  expect2 "--overrun-policy" "$@" --overrun-policy never
  expect2 "--step-ms" "$@" --step-ms 0.001
  expect2 "--step-ms" "$@" --step-ms 5000
  expect2 "--duration" "$@" --duration 1e12
  expect2 "--duration" "$@" --duration -1
  expect2 "--duration" "$@" --duration 0
  expect2 "--spin-us" "$@" --spin-us -1
  expect2 "--spin-us" "$@" --spin-us 6000
  expect2 "--max-overruns" "$@" --max-overruns 0
  expect2 "--cpu" "$@" --cpu -5
done
expect2 "--out-dir" hil run --out-dir /proc/nope --duration 1
expect2 "--reference" hil run --out-dir "$tmp/o" --reference bogus:amplitude=1
expect2 "--slave-cpu" hil run --out-dir "$tmp/o" --slave-cpu -7
expect2 "--seed" hil run --out-dir "$tmp/o" --seed -5
expect2 "--dto-timeout" hil master --bus mem:x --dto-timeout -1
expect2 "--connect-timeout" hil slave --bus mem:x --connect-timeout -1
expect2 "--duration" hil simulate --duration 1e12 -o "$tmp/h.csv"
expect2 "--step-ms" hil simulate --step-ms 0.001 -o "$tmp/h.csv"
expect2 "--seed" hil simulate --seed -5 -o "$tmp/h.csv"
[[ -e "$tmp/o/report.json" || -e "$tmp/m.csv" || -e "$tmp/s.csv" || -e "$tmp/h.csv" ]] && fail "output written despite bad input"

# --help states the limits and the defaults.
"$LASH" hil run --help >"$tmp/help" || fail "hil run --help"
for want in "1..99" "tolerate | stop" "0.1..1000" "20000000 steps" "TEXT:{tolerate,stop}=tolerate" "=5"; do
  grep -qF -- "$want" "$tmp/help" || fail "hil run --help lacks '$want': $(cat "$tmp/help")"
done
echo PASS
