#!/usr/bin/env bash
# SocketCAN for real: boots Debian's kernel (linux-image-*-amd64, fetched with
# `apt-get download` and cached in the build tree) under qemu-system-x86_64 -accel tcg
# with a busybox-static initramfs holding lash and its shared libraries (ldd),
# creates vcan0 and checks that
#   1. `lash can send` frames arrive at `lash can dump` on socketcan:vcan0, identical;
#   2. `lash can replay` of a candump log keeps its timing within 1 ms (kernel receive
#      timestamps of the dumped frames vs the log's times, relative to the first frame).
# If the kernel cannot be fetched this test FAILS (it never passes silently).
# The replay is run three times; each run must keep every frame within 1 ms of its log
# time (after one constant shift).
# Env: LASH (the CLI), LASH_PY (Debian python), LASH_QEMU_DIR (cache; default next to LASH).
set -euo pipefail

LASH=${LASH:?LASH must point to the lash binary}
PY=${LASH_PY:-/usr/bin/python3}
WORK=${LASH_QEMU_DIR:-$(dirname "$(dirname "$LASH")")/qemu-socketcan}
SRC_DIR=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$WORK"
cd "$WORK"
t_start=$(date +%s.%N)

die() { echo "can_socketcan_qemu: FAIL: $*" >&2; exit 1; }

for tool in qemu-system-x86_64 cpio dpkg-deb; do
  command -v "$tool" >/dev/null || die "$tool is missing (scripts/install-deps.sh installs it)"
done
BUSYBOX=/bin/busybox  # busybox-static
[[ -x "$BUSYBOX" ]] || die "busybox-static is missing"

# 1. The kernel: Debian's current linux-image-*-amd64 (cached .deb).
deb=$(ls linux-image-*-amd64_*.deb 2>/dev/null | head -n1 || true)
if [[ -z "$deb" ]]; then
  resolve() { apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-/{print $2; exit}'; }
  pkg=$(resolve)
  if [[ -z "$pkg" ]]; then  # empty apt lists (fresh CI image): refresh them once
    SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
    $SUDO apt-get update -qq >/dev/null 2>&1 || true
    pkg=$(resolve)
  fi
  [[ -n "$pkg" ]] || die "cannot resolve linux-image-amd64 with apt-cache (apt-get update failed?)"
  apt-get download "$pkg" >/dev/null 2>apt.err || { cat apt.err >&2; die "apt-get download $pkg failed"; }
  deb=$(ls linux-image-*-amd64_*.deb | head -n1)
fi
if [[ ! -f kernel.stamp || kernel.stamp -ot "$deb" ]]; then
  rm -rf kroot && mkdir kroot
  dpkg-deb --fsys-tarfile "$deb" | tar -x -C kroot --wildcards './boot/vmlinuz-*' \
    './lib/modules/*/kernel/net/can/can.ko' './lib/modules/*/kernel/net/can/can-raw.ko' \
    './lib/modules/*/kernel/drivers/net/can/vcan.ko' './lib/modules/*/kernel/drivers/net/can/dev/can-dev.ko' \
    || die "cannot extract the kernel from $deb"
  touch kernel.stamp
fi
VMLINUZ=$(ls kroot/boot/vmlinuz-* | head -n1)
MODDIR=$(ls -d kroot/lib/modules/*/kernel)

# 2. The initramfs: busybox, lash + its libraries, the CAN modules, the test script.
rm -rf initrd && mkdir -p initrd/{bin,dev,proc,sys,tmp,mods,etc}
cp "$BUSYBOX" initrd/bin/busybox
for app in sh ash ip insmod mount sleep cat echo poweroff mkdir date; do ln -s busybox "initrd/bin/$app"; done
cp "$LASH" initrd/bin/lash
ldd "$LASH" | awk '/=>/ {print $3} /^\s*\/lib/ {print $1}' | while read -r lib; do
  [[ -f "$lib" ]] || continue
  mkdir -p "initrd$(dirname "$lib")"
  cp -L "$lib" "initrd$lib"
done
interp=$(ldd "$LASH" | awk '/ld-linux/ {print $1}')
[[ -n "$interp" ]] && mkdir -p "initrd$(dirname "$interp")" && cp -L "$interp" "initrd$interp"
cp "$MODDIR/net/can/can.ko" "$MODDIR/net/can/can-raw.ko" "$MODDIR/drivers/net/can/dev/can-dev.ko" \
  "$MODDIR/drivers/net/can/vcan.ko" initrd/mods/
# The replay log: irregular gaps from 0.5 ms to 50 ms.
"$PY" - > initrd/replay.log <<'EOF'
import random
r = random.Random(5)
t = 1700000000.0
for i in range(40):
    print("(%.6f) vcan0 %03X#%02X%02X" % (t, 0x100 + i, i, r.randrange(256)))
    t += r.choice([0.0005, 0.001, 0.002, 0.005, 0.010, 0.025, 0.050])
EOF
cat > initrd/init <<'EOF'
#!/bin/sh
export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev 2>/dev/null
echo "LASH-VM: kernel up"
# SocketCAN absent before the modules: lash must say so clearly.
lash can dump --bus socketcan:vcan0 --count 1 --timeout 1 2>/tmp/nocan.err
echo "LASH-NOCAN: rc=$? $(cat /tmp/nocan.err)"
insmod /mods/can.ko && insmod /mods/can-raw.ko && insmod /mods/can-dev.ko && insmod /mods/vcan.ko || echo "LASH-FAIL insmod"
ip link add dev vcan0 type vcan || echo "LASH-FAIL ip link add"
ip link set vcan0 up || echo "LASH-FAIL ip link up"
# send -> dump
lash can dump --bus socketcan:vcan0 --count 4 --timeout 20 --log /tmp/sent.log > /tmp/dump.out 2>/tmp/dump.err &
sleep 1
lash can send --bus socketcan:vcan0 123#DEADBEEF 1ABCDEF0#0102030405060708 7FF#R 000#
wait $!
echo "LASH-DUMP-RC $?"
while read -r line; do echo "LASH-SENT $line"; done < /tmp/sent.log
# kernel filters (CAN_RAW_FILTER): only 0x1xx standard ids and one extended id pass
lash can dump --bus socketcan:vcan0 --filter 100:700 --filter 18FF0000:1FFF0000 --count 3 --timeout 20 > /tmp/filt.out 2>/tmp/filt.err &
sleep 1
lash can send --bus socketcan:vcan0 223#01 123#02 18FE0001#03 100#04 18FF0002#05 1FF#06
wait $!
echo "LASH-FILT-RC $?"
while read -r line; do echo "LASH-FILTERED $line"; done < /tmp/filt.out
echo "LASH-FILT-STATS $(cat /tmp/filt.err)"
# replay timing
# The dumper runs at the lowest priority, the replayer under SCHED_FIFO: on one vCPU
# the dumper must not delay a frame (timestamps are taken by the kernel in the send path).
for run in 1 2 3; do
  lash can dump --bus socketcan:vcan0 --count 40 --timeout 30 --quiet --log /tmp/replayed.log 2>/tmp/dump2.err &
  dpid=$!
  renice -n 19 -p $dpid >/dev/null
  sleep 1
  lash can replay --rt-priority 50 --bus socketcan:vcan0 /replay.log
  echo "LASH-REPLAY-RC $?"
  wait $dpid
  echo "LASH-DUMP2-RC $?"
  while read -r line; do echo "LASH-REPLAYED$run $line"; done < /tmp/replayed.log
done
echo "LASH-VM: done"
poweroff -f
EOF
chmod +x initrd/init
(cd initrd && find . | cpio -o -H newc --quiet | gzip -1) > initrd.cpio.gz
t_built=$(date +%s.%N)

# 3. Boot (TCG: no KVM needed). The guest powers off when done.
# Guest clock: by default icount mode (guest time = executed instructions, idle time
# skipped), so that host load — other processes descheduling qemu — is not seen as
# guest time; replay timing is then measured against the guest's own clock. With
# LASH_QEMU_ICOUNT= (empty) qemu runs plain TCG on host time (docs/can.md has numbers).
ICOUNT=${LASH_QEMU_ICOUNT-shift=0,sleep=off}
timeout 180 qemu-system-x86_64 -accel tcg ${ICOUNT:+-icount "$ICOUNT"} -m 512 -smp 1 -nographic -no-reboot \
  -kernel "$VMLINUZ" -initrd initrd.cpio.gz \
  -append "console=ttyS0 quiet loglevel=3 panic=-1 rdinit=/init" > console.log 2>&1 || true
t_done=$(date +%s.%N)
grep -q "LASH-VM: done" console.log || { tail -n 40 console.log >&2; die "the VM did not finish (see $WORK/console.log)"; }

# 4. Check.
"$PY" - "$WORK/console.log" "$t_start" "$t_built" "$t_done" <<'EOF'
import sys
log, t0, t1, t2 = sys.argv[1], *map(float, sys.argv[2:])
lines = [l.rstrip("\r\n") for l in open(log, errors="replace")]
def tagged(tag):
    return [l.split(tag + " ", 1)[1] for l in lines if l.startswith(tag + " ")]
fail = [l for l in lines if l.startswith("LASH-FAIL")]
nocan = [l for l in lines if l.startswith("LASH-NOCAN")]
print(nocan[0] if nocan else "no LASH-NOCAN line")
if not nocan or "rc=2" not in nocan[0] or "no CAN support" not in nocan[0]:
    fail.append("without CAN modules lash should exit 2 saying the kernel has no CAN support")
sent = [s.split()[2] for s in tagged("LASH-SENT")]
want = ["123#DEADBEEF", "1ABCDEF0#0102030405060708", "7FF#R", "000#"]
print("send -> dump over socketcan:vcan0:", sent)
if sent != want:
    fail.append("dump got %s, expected %s" % (sent, want))
filt = [s.split()[2] for s in tagged("LASH-FILTERED")]
print("dump --filter 100:700 --filter 18FF0000:1FFF0000 got:", filt)
if filt != ["123#02", "100#04", "18FF0002#05"]:
    fail.append("kernel filters: got %s, expected 123#02, 100#04, 18FF0002#05" % filt)
stats = tagged("LASH-FILT-STATS")
print("filter dump stats:", stats)
if not stats or "(0 filtered" not in stats[0]:
    fail.append("the kernel (CAN_RAW_FILTER) should have dropped the others before user space: %s" % stats)
orig = []
for l in open(sys.argv[0] if False else log.replace("console.log", "initrd/replay.log")):
    orig.append(float(l.split()[0][1:-1]))
for run in (1, 2, 3):
    rows = tagged("LASH-REPLAYED%d" % run)
    rep = [float(s.split()[0][1:-1]) for s in rows]
    rep_ids = [s.split()[2].split("#")[0] for s in rows]
    if len(rep) != len(orig) or rep_ids != ["%03X" % (0x100 + i) for i in range(len(orig))]:
        fail.append("replay run %d: %d of %d frames dumped in order" % (run, len(rep), len(orig)))
        continue
    # Timing kept = every frame at its log time plus one constant shift (the median shift).
    shifts = sorted(r - o for r, o in zip(rep, orig))
    shift = shifts[len(shifts) // 2]
    errs = sorted(abs((r - o) - shift) for r, o in zip(rep, orig))
    gaps = sorted(abs((rep[i] - rep[i - 1]) - (orig[i] - orig[i - 1])) for i in range(1, len(orig)))
    print("replay run %d: %d frames, error vs log timing: median %.1f us, max %.1f us; "
          "inter-frame gap error median %.1f us, max %.1f us" % (
              run, len(errs), errs[len(errs) // 2] * 1e6, errs[-1] * 1e6, gaps[len(gaps) // 2] * 1e6, gaps[-1] * 1e6))
    if errs[-1] > 1e-3:
        fail.append("replay run %d: timing error %.1f us > 1 ms" % (run, errs[-1] * 1e6))
print("time: prepare %.1f s, boot+run %.1f s" % (t1 - t0, t2 - t1))
for f in fail:
    print("FAIL", f)
sys.exit(1 if fail else 0)
EOF
