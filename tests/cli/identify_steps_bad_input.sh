#!/usr/bin/env bash
# lash identify-steps: each bad option value -> exit 2 naming the option, before the data file is read.
set -uo pipefail
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail=0
check() {  # name expected-regex args...
  local name=$1 want=$2; shift 2
  local out rc
  # The data file does not exist: an option error must come first.
  out=$("$LASH" identify-steps "$d/none.csv" "$@" 2>&1); rc=$?
  if [[ $rc -ne 2 ]]; then echo "FAIL $name: exit $rc (want 2): $out"; fail=1; return; fi
  if ! grep -Eq -- "$want" <<<"$out"; then echo "FAIL $name: message '$out' lacks /$want/"; fail=1; return; fi
  echo "ok   $name: $out"
}
check settle_negative   "'--settle-taus'.*\(0, 100\]"        --settle-taus -1
check settle_zero       "'--settle-taus'"                    --settle-taus 0
check settle_huge       "'--settle-taus'"                    --settle-taus 1e9
check tolerance_neg     "'--current-tolerance'.*\(0, 10000\]" --current-tolerance -5
check tolerance_nan     "'--current-tolerance'"              --current-tolerance nan
check plot_no_dir       "'--plot'.*directory $d/nodir does not exist" --plot "$d/nodir/x.png"
help=$("$LASH" identify-steps --help)
for want in "(0, 100]" "(0, 10000]" "8" "0.5"; do
  grep -qF -- "$want" <<<"$help" && echo "ok   --help shows $want" || { echo "FAIL --help lacks $want"; fail=1; }
done
exit $fail
