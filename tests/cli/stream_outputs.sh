#!/usr/bin/env bash
# Outputs that are not regular files are written in place, never renamed over:
# -o /dev/null stays a character device (checked inside a private mount
# namespace on a bind-mounted copy of the null node, so the host's /dev/null is
# never at risk), a FIFO delivers the bytes to its reader, `-o -` writes to
# stdout; a regular file still gets the atomic write; --plot errors name the
# real cause.
set -uo pipefail
: "${LASH:?}" "${LASH_SOURCE_DIR:?}"
plant="$LASH_SOURCE_DIR/config/plants/thesis_eq34.toml"
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail=0
ok()  { echo "ok   $*"; }
bad() { echo "FAIL $*"; fail=1; }
sim=(simulate "$plant" --amplitude 600 --duration 0.5)

# Reference output in a regular file (atomic write): no temporary left.
"$LASH" "${sim[@]}" -o "$d/ref.csv" 2>/dev/null || bad "simulate to a regular file"
n_ref=$(wc -l < "$d/ref.csv")
if ls "$d" | grep -q tmp; then bad "temporary left next to ref.csv"; else ok "regular file: $n_ref lines, no temporary"; fi

# 1. stdout.
"$LASH" "${sim[@]}" -o - > "$d/stdout.csv" 2>/dev/null || bad "simulate -o - failed"
if cmp -s "$d/ref.csv" "$d/stdout.csv"; then ok "-o - : stdout equals the file output"; else bad "-o - : stdout differs from the file output"; fi
if [[ -e ./- ]]; then bad "-o - created a file named '-'"; fi

# 2. FIFO: the reader gets exactly the bytes of the file output.
mkfifo "$d/fifo"
cat "$d/fifo" > "$d/fifo.csv" &
reader=$!
"$LASH" "${sim[@]}" -o "$d/fifo" 2>/dev/null || bad "simulate -o fifo failed"
wait "$reader"
if [[ -p "$d/fifo" ]] && cmp -s "$d/ref.csv" "$d/fifo.csv"; then ok "FIFO: still a FIFO, reader got $(wc -l < "$d/fifo.csv") lines"; else bad "FIFO: not a FIFO any more or bytes differ"; fi

# 3. /dev/null in a private mount namespace, over a copy of the null node.
if unshare -m true 2>/dev/null && mknod "$d/null" c 1 3 2>/dev/null; then
  # Record CSV for estimate (t,v,y) and a one-run campaign for sweep.
  "$LASH" simulate "$plant" --input randomized --variance 1e5 --tau 0.05 --duration 5 -o "$d/rec.csv" 2>/dev/null
  printf 'name = "t"\nrig = "motor_cart"\ndt_s = 0.001\nduration_s = 1.0\n[matrix]\nwaveforms = ["sine"]\namplitudes = [4.0]\nfrequencies_rad_s = [2.0]\nrepeats = 1\n' > "$d/camp.toml"
  out=$(unshare -m bash -c '
    set -u
    mount --make-rprivate / && mount --bind "$1" /dev/null || { echo "SKIPMOUNT"; exit 0; }
    [[ -c /dev/null ]] || { echo "no char dev before"; exit 1; }
    rc=0
    "$LASH" simulate "$2" --amplitude 600 --duration 0.5 -o /dev/null 2>/dev/null || { echo "simulate rc $?"; rc=1; }
    [[ -c /dev/null ]] || { echo "simulate replaced /dev/null"; rc=1; }
    "$LASH" estimate "$3" --model input-deadzone -o /dev/null >/dev/null 2>&1 || { echo "estimate rc $?"; rc=1; }
    [[ -c /dev/null ]] || { echo "estimate replaced /dev/null"; rc=1; }
    "$LASH" sweep "$4" -q -o /dev/null >/dev/null 2>&1 || { echo "sweep rc $?"; rc=1; }
    [[ -c /dev/null ]] || { echo "sweep replaced /dev/null"; rc=1; }
    ls /dev | grep -q "^null.tmp" && { echo "temporary left in /dev"; rc=1; }
    exit $rc' _ "$d/null" "$plant" "$d/rec.csv" "$d/camp.toml" 2>&1); rc=$?
  if [[ "$out" == *SKIPMOUNT* ]]; then echo "skip /dev/null check: bind mount not permitted"
  elif [[ $rc -eq 0 ]]; then ok "/dev/null (simulate, estimate, sweep -o): still a character device"
  else bad "/dev/null: $out"; fi
else
  echo "skip /dev/null check: no private mount namespace or mknod here"
fi

# 4. --plot errors name the real cause.
out=$("$LASH" "${sim[@]}" -o "$d/p.csv" --plot "$d/no/such/dir/p.png" 2>&1); rc=$?
if [[ $rc -eq 2 ]] && grep -q "does not exist" <<<"$out" && ! grep -q gnuplot-nox <<<"$out"; then ok "--plot missing dir: $out"; else bad "--plot missing dir: rc $rc: $out"; fi
out=$("$LASH" "${sim[@]}" -o - --plot "$d/p.png" 2>&1 >/dev/null); rc=$?
if [[ $rc -eq 2 ]] && grep -q "regular file" <<<"$out"; then ok "--plot with -o -: $out"; else bad "--plot with -o -: rc $rc: $out"; fi
if [[ $(id -u) -ne 0 ]]; then
  mkdir "$d/ro" && chmod 555 "$d/ro"
  out=$("$LASH" "${sim[@]}" -o "$d/p.csv" --plot "$d/ro/p.png" 2>&1); rc=$?
  if [[ $rc -eq 2 ]] && grep -qi "permission denied" <<<"$out"; then ok "--plot unwritable dir: $out"; else bad "--plot unwritable dir: rc $rc: $out"; fi
fi
out=$("$LASH" "${sim[@]}" -o "$d/no/such/dir/x.csv" 2>&1); rc=$?
if [[ $rc -eq 2 ]] && grep -q "does not exist" <<<"$out"; then ok "-o missing dir: $out"; else bad "-o missing dir: rc $rc: $out"; fi
exit $fail
