"""`lash can dump --log FILE` streams the frames to disk (issue 29): run inside can_netns.sh (a
private network namespace; the frames go over UDP multicast on its loopback only).

 - kill -9: a dump logging to out.log while `lash can replay` sends 1 000 frames a second is
   killed after ~2.5 s; the temporary file it names on stderr (`out.log.tmp.<random>`) holds, in
   order, every frame it printed on stdout (candump -L, flushed per line) with a receive time at
   least 1 s before the kill;
 - a relative format: a dump to out.blf (spooled, converted at the end) reads back (`lash can
   convert` to candump) as exactly the times and frames the dump printed, and the spool is gone;
 - memory: peak RSS (ru_maxrss of the dump, from wait4) of a dump of N frames and of one of 10·N
   frames (sent at 50 kHz; the socket may drop some) to out.asc: within 4 MiB of each other (kept in memory, 10·N = 200 000 frames took
   about 160 bytes each: +29 MiB).
"""
import glob
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

LASH = os.environ["LASH"]
BUS = "udp:239.74.163.9:43119"
tmp = tempfile.mkdtemp(prefix="lash_can_dump_")


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def candump_log(path, n, gap_s):
    with open(path, "w") as f:
        t = 1700000000.0
        for k in range(n):
            t += gap_s
            f.write(f"({t:.6f}) can0 {0x100 + k % 7:03X}#{k & 0xFFFFFFFF:08X}\n")


def start_dump(args):
    p = subprocess.Popen([LASH, "can", "dump", "--bus", BUS] + args, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    time.sleep(0.5)  # joined the group
    return p


def replay(log, speed):
    subprocess.run([LASH, "can", "replay", "--bus", BUS, "--speed", str(speed), log], check=True,
                   capture_output=True, timeout=120)


def stamp(line):
    return float(re.match(r"\((\d+\.\d+)\)", line).group(1))


# --- kill -9 while logging: at most the last second is lost.
src = os.path.join(tmp, "steady.log")
candump_log(src, 6000, 0.001)
out = os.path.join(tmp, "killed.log")
dump = start_dump(["--log", out])
sender = subprocess.Popen([LASH, "can", "replay", "--bus", BUS, src], stdout=subprocess.DEVNULL,
                          stderr=subprocess.DEVNULL)
time.sleep(2.5)
t_kill = time.time()
dump.send_signal(signal.SIGKILL)
printed = dump.stdout.read().splitlines()
dump.wait()
sender.terminate()
sender.wait()
spools = glob.glob(out + ".tmp.*")
if len(spools) != 1 or os.path.exists(out):
    fail(f"expected one spool and no {out}: {spools}")
with open(spools[0]) as f:
    kept = f.read().splitlines()
needed = [l for l in printed if stamp(l) <= t_kill - 1.0]
print(f"kill -9 at t = {t_kill:.3f}: printed {len(printed)}, on disk {len(kept)}, "
      f"printed >= 1 s before the kill {len(needed)}")
if len(needed) < 500:
    fail("too few frames before the kill to judge")
if kept != printed[:len(kept)]:
    fail("the spool is not the printed frames in order")
if len(kept) < len(needed):
    fail(f"lost frames received more than 1 s before the kill: {len(needed) - len(kept)}")

# --- a relative format: spooled, converted at the end, the spool removed.
src = os.path.join(tmp, "burst.log")
candump_log(src, 3000, 0.0002)
out = os.path.join(tmp, "dump.blf")
dump = start_dump(["--log", out, "--timeout", "4"])
replay(src, 1.0)
printed_text, err = dump.communicate(timeout=30)
printed = printed_text.splitlines()
if dump.returncode != 0:
    fail(err)
back = os.path.join(tmp, "back.log")
subprocess.run([LASH, "can", "convert", out, back], check=True, capture_output=True)
with open(back) as f:
    back_lines = f.read().splitlines()
print(f"blf: printed {len(printed)}, read back {len(back_lines)}")
def no_iface(lines):  # BLF numbers its channels: the interface reads back as "1"
    return [(l.split()[0], l.split()[2]) for l in lines]


if not printed or no_iface(back_lines) != no_iface(printed):
    fail("the BLF does not read back as the printed frames")
if glob.glob(out + ".tmp.*"):
    fail("spool left behind")

# --- memory: N and 10 N frames.
SPAWN = """import os, sys
with open(os.devnull, "w") as null:
    pid = os.fork()
    if pid == 0:
        os.dup2(null.fileno(), 1)
        os.dup2(null.fileno(), 2)
        os.execv(sys.argv[1], sys.argv[1:])
    print(pid, flush=True)
    _, status, ru = os.wait4(pid, 0)
print(os.waitstatus_to_exitcode(status), ru.ru_maxrss)
"""
peaks = {}
for n in (20_000, 200_000):
    src = os.path.join(tmp, f"n{n}.log")
    candump_log(src, n, 0.00002)
    out = os.path.join(tmp, f"n{n}.asc")
    p = subprocess.Popen([sys.executable, "-c", SPAWN, LASH, "can", "dump", "--bus", BUS, "--quiet", "--log", out,
                          "--count", str(n), "--timeout", "60"], stdout=subprocess.PIPE, text=True)
    dump_pid = int(p.stdout.readline())
    time.sleep(0.5)
    replay(src, 1.0)
    time.sleep(0.5)
    if p.poll() is None:  # frames dropped by the socket: stop it (it writes its log and exits)
        try:
            os.kill(dump_pid, signal.SIGINT)
        except ProcessLookupError:
            pass
    status, kb = p.communicate(timeout=60)[0].split()
    with open(out) as f:
        frames = sum(1 for l in f if " Rx " in l)
    peaks[n] = int(kb) / 1024
    print(f"dump of {n} frames sent: {frames} in the ASC, peak RSS {peaks[n]:.1f} MiB")
    if frames < 0.5 * n:
        fail("too few frames received")
if peaks[200_000] > peaks[20_000] + 4.0:
    fail(f"peak RSS grows with the frames: {peaks}")
shutil.rmtree(tmp)
print("ok")
