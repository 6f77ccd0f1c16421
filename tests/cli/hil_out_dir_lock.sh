#!/usr/bin/env bash
# Two `hil run`s into one --out-dir: the second is refused at once (exit 2, naming the first's
# pid) and the first is unaffected; once the first has ended the directory is free again
# (the lock is an flock the kernel drops with its holder, so it is never stale).
set -uo pipefail
d=$(mktemp -d); trap 'rm -rf "$d"; kill $first 2>/dev/null' EXIT
fail=0
"$LASH" hil run --duration 3 --out-dir "$d/out" > "$d/first.txt" 2>&1 &
first=$!
for _ in $(seq 100); do [[ -s "$d/out/.lash-run.lock" ]] && break; sleep 0.05; done
out=$("$LASH" hil run --duration 1 --out-dir "$d/out" 2>&1); rc=$?
[[ $rc -eq 2 ]] || { echo "FAIL: second run exit $rc (want 2): $out"; fail=1; }
grep -q "in use by another lash hil run (pid $first)" <<<"$out" || { echo "FAIL: message lacks the first run's pid $first: $out"; fail=1; }
wait $first; rc1=$?
[[ $rc1 -eq 0 ]] || { echo "FAIL: the first run failed ($rc1): $(tail -3 "$d/first.txt")"; fail=1; }
rows=$(($(wc -l < "$d/out/master.csv") - 1))
[[ $rows -gt 500 ]] || { echo "FAIL: the first run's master.csv has $rows rows"; fail=1; }
"$LASH" hil run --duration 0.5 --out-dir "$d/out" > "$d/third.txt" 2>&1 || { echo "FAIL: the directory stayed locked: $(tail -2 "$d/third.txt")"; fail=1; }
[[ $fail -eq 0 ]] && echo "ok: second run refused ($out); first run $rows rows of master.csv; directory free afterwards"
exit $fail
