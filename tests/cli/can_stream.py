"""`lash can decode` and `lash can convert` stream their logs (issue 29, "Memory bounded by design"):

 - peak RSS (the child's ru_maxrss from wait4) of `can decode` of a candump log of N frames and of
   one of 30·N frames, and of the 30·N log converted (by `can convert`, itself measured) to ASC, BLF
   and TRC: every 30·N figure is within 8 MiB of the N figure of the same command (reading the log
   whole took about 200 bytes per frame: 30·N = 300 000 frames would add about 60 MiB);
 - the first decoded line comes out while the log is still being written: `can decode` of a FIFO
   whose writer holds it open after the first 4 000 frames prints lines before the writer
   closes it (a reader of the whole file prints nothing before the end), then all of them.
The decoded text is checked: one line per frame, the first one's time, message and pressure field
decoded by hand (little-endian 16 bits times the DBC's factor 0.00152590218966964).
"""
import os
import random
import select
import subprocess
import sys
import tempfile
import threading

LASH = os.environ["LASH"]
SRC = os.environ["LASH_SOURCE_DIR"]
DBC = os.path.join(SRC, "config", "hydraulic_bench.dbc")
N = 10_000
BOUND_MIB = 8.0
tmp = tempfile.mkdtemp(prefix="lash_can_stream_")


def candump_lines(n, seed):
    rnd = random.Random(seed)
    out, t = [], 1700000000.0
    for k in range(n):
        t += 0.0025
        ident = "200" if k % 2 == 0 else "100"
        data = bytes(rnd.randrange(256) for _ in range(8))
        out.append(f"({t:.6f}) can0 {ident}#{data.hex().upper()}\n")
    return out


def write(name, lines):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        f.writelines(lines)
    return path


# A child's ru_maxrss starts from its parent's high-water mark at fork (the kernel keeps it
# across exec): the command is started by a small Python process, not by this one holding the logs.
SPAWN = """import os, resource, sys
with open(os.devnull, "w") as null:
    pid = os.fork()
    if pid == 0:
        os.dup2(null.fileno(), 1)
        os.execv(sys.argv[1], sys.argv[1:])
    _, status, ru = os.wait4(pid, 0)
print(os.waitstatus_to_exitcode(status), ru.ru_maxrss)
"""


def peak_mib(cmd):
    """Peak RSS [MiB] of the command (resource usage of the child from wait4), stdout discarded."""
    r = subprocess.run([sys.executable, "-c", SPAWN, *cmd], capture_output=True, text=True, timeout=300)
    status, kib = r.stdout.split()
    assert status == "0", (cmd, r.stderr)
    return int(kib) / 1024.0


small, large = write("n.log", candump_lines(N, 1)), write("30n.log", candump_lines(30 * N, 2))
rows = []
for ext in ("log", "asc", "blf", "trc"):
    if ext == "log":
        s_in, l_in = small, large
        conv = None
    else:
        s_in, l_in = os.path.join(tmp, "n." + ext), os.path.join(tmp, "30n." + ext)
        conv = (peak_mib([LASH, "can", "convert", small, s_in]), peak_mib([LASH, "can", "convert", large, l_in]))
        rows.append((f"convert -> {ext}", *conv))
    rows.append((f"decode {ext}", peak_mib([LASH, "can", "decode", "--dbc", DBC, s_in]),
                 peak_mib([LASH, "can", "decode", "--dbc", DBC, l_in])))
for what, a, b in rows:
    print(f"{what:16s} peak RSS {a:7.1f} MiB at {N} frames, {b:7.1f} MiB at {30 * N} frames")
    assert b - a <= BOUND_MIB, (what, a, b)

# decode of a FIFO: lines come out before the writer closes it
fifo = os.path.join(tmp, "live.log")
os.mkfifo(fifo)
lines = candump_lines(8000, 3)
p = subprocess.Popen([LASH, "can", "decode", "--dbc", DBC, fifo], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
release = threading.Event()


def writer():
    with open(fifo, "w") as f:
        f.writelines(lines[:4000])
        f.flush()
        release.wait(120)  # held open until the test has seen output
        f.writelines(lines[4000:])


th = threading.Thread(target=writer)
th.start()
ready, _, _ = select.select([p.stdout], [], [], 60)
early = p.stdout.readline().decode() if ready else ""
writer_open = th.is_alive() and not release.is_set()
release.set()
rest = p.stdout.read()  # (through the same buffered reader as the first line)
err = p.stderr.read()
p.wait(120)
th.join()
assert writer_open
assert early, "no decoded line while the FIFO was still open"
assert p.returncode == 0, err
out = [early] + rest.decode().splitlines(keepends=True)
assert len(out) == len(lines), (len(out), len(lines))
# the first frame (0x200, BenchSensors) decoded by hand: PilotPressure_Duty = u16 LE * factor
first = bytes.fromhex(lines[0].split("#")[1])
assert early.startswith(lines[0][1:lines[0].index(")")] + " BenchSensors PilotPressure_Duty="), early
duty = float(early.split("PilotPressure_Duty=")[1].split()[0])
assert abs(duty - int.from_bytes(first[0:2], "little") * 0.00152590218966964) < 1e-9, (early, first.hex())
print(f"FIFO: the first line came out while the writer held the FIFO open; {len(out)} lines in all: {early.strip()[:80]}")

# replay and convert read the log twice: a pipe is refused at once (exit 2, naming it), not half-sent
for cmd in ([LASH, "can", "replay", "--bus", "mem:stream_test", "-"], [LASH, "can", "convert", fifo, os.path.join(tmp, "x.asc")]):
    r = subprocess.run(cmd, input="(1.000000) can0 123#00\n", capture_output=True, text=True, timeout=30)
    assert r.returncode == 2 and "give a regular file" in r.stderr, (cmd, r.returncode, r.stderr)
    assert not os.path.exists(os.path.join(tmp, "x.asc"))
print("replay of standard input and convert of a FIFO: exit 2 (they read the log twice)")
