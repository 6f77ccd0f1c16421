#!/usr/bin/env bash
# Outputs cannot be hijacked: links, regular files and FIFOs planted at every name the old
# temporary-file scheme used (<out>.tmp.<pid>, <png>.tmp.<pid>.png / .gp, for the next 400
# process ids) are left untouched — never followed, truncated or opened — while lash writes
# its CSV (AtomicFile) and its plot (gnuplot through a private mkdtemp directory).
set -uo pipefail
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
SRC=${LASH_SOURCE_DIR:?}
fail=0
printf 'precious\n' > "$d/victim.txt"
sleep 0 & base=$!; wait
for ((p = base; p < base + 400; ++p)); do
  case $((p % 3)) in
    0) ln -s "$d/victim.txt" "$d/out.csv.tmp.$p"; ln -s "$d/victim.txt" "$d/out.png.tmp.$p.png"
       ln -s "$d/victim.txt" "$d/out.png.tmp.$p.gp" ;;
    1) printf 'planted %s\n' "$p" > "$d/out.csv.tmp.$p"; printf 'planted\n' > "$d/out.png.tmp.$p.gp" ;;
    2) mkfifo "$d/out.csv.tmp.$p" "$d/out.png.tmp.$p.gp" ;;
  esac
done
planted_before=$(cd "$d" && find . -name '*.tmp.*' | sort | xargs -d '\n' ls -ld --time-style=+ | awk '{print $1, $5, $NF}' | md5sum)
timeout 60 "$LASH" simulate "$SRC/config/plants/thesis_eq34.toml" --input sine --amplitude 600 --frequency 1 \
  --duration 2 -o "$d/out.csv" --plot "$d/out.png" > "$d/log.txt" 2>&1
rc=$?
[[ $rc -eq 0 ]] || { echo "FAIL: lash simulate exit $rc: $(cat "$d/log.txt")"; fail=1; }
[[ "$(cat "$d/victim.txt")" == precious ]] || { echo "FAIL: the link's target was overwritten"; fail=1; }
planted_after=$(cd "$d" && find . -name '*.tmp.*' | sort | xargs -d '\n' ls -ld --time-style=+ | awk '{print $1, $5, $NF}' | md5sum)
[[ "$planted_before" == "$planted_after" ]] || { echo "FAIL: a planted file, link or FIFO changed"; fail=1; }
for ((p = base; p < base + 400; ++p)); do
  if [[ -f "$d/out.csv.tmp.$p" && ! -L "$d/out.csv.tmp.$p" ]] && [[ "$(cat "$d/out.csv.tmp.$p")" != "planted $p" ]]; then
    echo "FAIL: planted file out.csv.tmp.$p was written"; fail=1
  fi
done
rows=$(($(wc -l < "$d/out.csv") - 1))
[[ $rows -eq 400 ]] || { echo "FAIL: out.csv has $rows rows, want 400 (2 s at the plant's dt = 5 ms)"; fail=1; }
head -c 8 "$d/out.png" | od -An -tx1 | grep -q "89 50 4e 47" || { echo "FAIL: out.png is no PNG"; fail=1; }
leftover=$(cd "$d" && find . -maxdepth 1 -name 'out.*.tmp.*' -newer "$d/victim.txt" | grep -v -E 'tmp\.[0-9]+(\.png|\.gp)?$' || true)
[[ -z "$leftover" ]] || { echo "FAIL: temporary files left behind: $leftover"; fail=1; }
[[ $fail -eq 0 ]] && echo "ok: 400 pids x 3 names planted (links, files, FIFOs) untouched; out.csv $rows rows, out.png written"
exit $fail
