#!/usr/bin/env bash
# lash monitor: bad input is exit 2 with a message naming the file, option or signal; nothing written.
set -u
L=${LASH:?}
S=${LASH_SOURCE_DIR:?}
DBC=$S/config/monitor/hydraulic_bench_kpa.dbc
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '(1.000000) can0 100#0000000000000000\n' > "$tmp/a.log"
fail=0
expect() {  # expect TEXT -- ARGS...: exit 2 and TEXT on stderr
  local text=$1; shift 2
  "$L" monitor "$@" > "$tmp/out" 2> "$tmp/err"
  local rc=$?
  if [[ $rc -ne 2 ]] || ! grep -qF -- "$text" "$tmp/err"; then
    echo "FAIL: lash monitor $* -> rc $rc, stderr: $(cat "$tmp/err")"; fail=1
  fi
}
V=BenchCommand.SolenoidA_Current-BenchCommand.SolenoidB_Current
expect "SolenoidC_Current" -- "$tmp/a.log" --dbc "$DBC" --v BenchCommand.SolenoidC_Current --y BenchSensors.PilotPressure_kPa --model linear
expect "NoSuchMsg" -- "$tmp/a.log" --dbc "$DBC" --v $V --y NoSuchMsg.X --model linear
expect "--v" -- "$tmp/a.log" --dbc "$DBC" --v Bench --y BenchSensors.PilotPressure_kPa --model linear
expect "missing.log" -- "$tmp/missing.log" --dbc "$DBC" --v $V --y BenchSensors.PilotPressure_kPa --model linear
expect "--model" -- "$tmp/a.log" --dbc "$DBC" --v $V --y BenchSensors.PilotPressure_kPa
expect "--every" -- "$tmp/a.log" --dbc "$DBC" --v $V --y BenchSensors.PilotPressure_kPa --model linear --every 0
# model switching iterates over a whole window: refused online (named), run in window mode (the default)
expect "model-switching" -- "$tmp/a.log" --dbc "$DBC" --v $V --y BenchSensors.PilotPressure_kPa --model deadzone-deadband --model-switching --estimate online
printf 'model = "deadzone-deadband"\nmodel_switching = true\n' > "$tmp/ms.toml"
expect "model-switching" -- "$tmp/a.log" --dbc "$DBC" --v $V --y BenchSensors.PilotPressure_kPa --config "$tmp/ms.toml" --estimate online
"$L" monitor "$tmp/a.log" --dbc "$DBC" --v $V --y BenchSensors.PilotPressure_kPa --config "$tmp/ms.toml" > "$tmp/out" 2> "$tmp/err" ||
  { echo "FAIL: --estimate window with model_switching -> rc $?, stderr: $(cat "$tmp/err")"; fail=1; }
printf '[alarms]\nq_r_max = 3\n' > "$tmp/bad.toml"
expect "q_r_max" -- "$tmp/a.log" --dbc "$DBC" --v $V --y BenchSensors.PilotPressure_kPa --model linear --config "$tmp/bad.toml"
printf '[alarms]\nwarmup_s = -1\nc_r_max = 350\n' > "$tmp/bad.toml"
expect "warmup_s" -- "$tmp/a.log" --dbc "$DBC" --v $V --y BenchSensors.PilotPressure_kPa --model linear --config "$tmp/bad.toml"
expect "missing.sqlite" -- --report "$tmp/missing.sqlite" -o "$tmp/x.png"
[[ ! -e "$tmp/x.png" ]] || { echo "FAIL: a PNG was left behind"; fail=1; }
exit $fail
