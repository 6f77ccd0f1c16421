"""lash's DBC codec against canmatrix (Debian python3-canmatrix), the independent oracle.

For every DBC of the project (config/**/*.dbc) and the test DBC with Motorola,
signed and multiplexed signals (tests/data/can/lash_test.dbc):
  1. random payloads of every message: `lash can decode` and canmatrix decode to the same values;
  2. random raw values: `lash can encode` builds the frame, canmatrix decodes exactly those raw values.
"""
import glob
import math
import os
import random
import re
import subprocess
import sys
import tempfile
import logging

logging.disable(logging.CRITICAL)
import canmatrix.formats  # noqa: E402

LASH = os.environ["LASH"]
SRC = os.environ["LASH_SOURCE_DIR"]


def dbc_files():
    files = [os.path.join(SRC, "tests/data/can/lash_test.dbc")]
    files += sorted(glob.glob(os.path.join(SRC, "config/**/*.dbc"), recursive=True))
    return files


def load(path):
    # canmatrix prints unsupported-format notices on import; silence stdout noise only
    return canmatrix.formats.loadp_flat(path)


def raw_bounds(sig):
    if sig.is_signed:
        lo, hi = -(1 << (sig.size - 1)), (1 << (sig.size - 1)) - 1
    else:
        lo, hi = 0, (1 << sig.size) - 1
    f, o = float(sig.factor), float(sig.offset)
    mn, mx = float(sig.min), float(sig.max)
    if mn < mx:  # lash clamps to a given [min|max]: stay inside it
        a, b = sorted(((mn - o) / f, (mx - o) / f))
        lo, hi = max(lo, math.ceil(a - 1e-9)), min(hi, math.floor(b + 1e-9))
    return lo, hi


def close(a, b):
    return a == b or abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))


def main():
    rng = random.Random(20260522)
    checked_decode = checked_encode = 0
    failures = []
    for path in dbc_files():
        db = load(path)
        frames = [f for f in db.frames if f.size <= 8 and f.signals]
        # 1. decode random payloads
        lines, expected = [], []
        t = 1.0
        for fr in frames:
            for _ in range(40):
                data = bytes(rng.randrange(256) for _ in range(fr.size))
                idtxt = ("%08X" if fr.arbitration_id.extended else "%03X") % fr.arbitration_id.id
                lines.append("(%.6f) can0 %s#%s" % (t, idtxt, data.hex().upper()))
                dec = fr.decode(data)
                expected.append((fr.name, {k: float(v.phys_value) for k, v in dec.items()}))
                t += 0.001
        with tempfile.NamedTemporaryFile("w", suffix=".log", delete=False) as fh:
            fh.write("\n".join(lines) + "\n")
            log = fh.name
        out = subprocess.run([LASH, "can", "decode", "--dbc", path, log], capture_output=True, text=True)
        os.unlink(log)
        if out.returncode != 0:
            print(out.stderr)
            return 1
        got = out.stdout.strip().split("\n")
        assert len(got) == len(expected), (len(got), len(expected))
        for line, (name, exp) in zip(got, expected):
            parts = line.split()
            if parts[1] != name:
                failures.append("%s: expected message %s, got %s" % (path, name, line))
                continue
            vals = {m.group(1): float(m.group(2)) for m in re.finditer(r"(\w+)=(\S+)", line)}
            if set(vals) != set(exp):
                failures.append("%s %s: signals %s vs canmatrix %s" % (path, name, sorted(vals), sorted(exp)))
                continue
            for k in exp:
                if not close(vals[k], exp[k]):
                    failures.append("%s %s.%s: lash %r canmatrix %r" % (path, name, k, vals[k], exp[k]))
            checked_decode += len(exp)
        # 2. encode with lash, decode with canmatrix
        for fr in frames:
            mux = next((s for s in fr.signals if s.multiplex == "Multiplexor"), None)
            pages = sorted({int(s.mux_val) for s in fr.signals if s.mux_val is not None})
            for _ in range(15):
                page = rng.choice(pages) if pages else None
                args, want = [], {}
                for s in fr.signals:
                    if s.mux_val is not None and int(s.mux_val) != page:
                        continue
                    if s.is_float:
                        v = float(rng.uniform(-1000, 1000))
                        if s.size == 32:  # representable as float32
                            import struct
                            v = struct.unpack("<f", struct.pack("<f", v))[0]
                        args.append("%s=%r" % (s.name, v))
                        want[s.name] = ("float", v)
                        continue
                    lo, hi = raw_bounds(s)
                    raw = page if s is mux else rng.randint(lo, hi)
                    phys = raw * float(s.factor) + float(s.offset)
                    args.append("%s=%r" % (s.name, phys))
                    want[s.name] = ("raw", raw)
                out = subprocess.run([LASH, "can", "encode", "--dbc", path, "--message", fr.name] + args,
                                     capture_output=True, text=True)
                if out.returncode != 0 or out.stderr:
                    failures.append("%s encode %s %s: rc %d %s" % (path, fr.name, args, out.returncode, out.stderr))
                    continue
                hexdata = out.stdout.strip().split("#", 1)[1]
                dec = fr.decode(bytes.fromhex(hexdata))
                for name, (kind, v) in want.items():
                    if name not in dec:
                        failures.append("%s %s: canmatrix did not decode %s" % (path, fr.name, name))
                        continue
                    r = dec[name].raw_value
                    if kind == "raw":
                        r = int(r)
                        if r != v:
                            failures.append("%s %s.%s: encoded raw %d, canmatrix reads %d (%s)"
                                            % (path, fr.name, name, v, r, out.stdout.strip()))
                    elif not close(float(dec[name].phys_value), v):
                        failures.append("%s %s.%s: encoded %r, canmatrix reads %r" % (path, fr.name, name, v, r))
                    checked_encode += 1
        print("%s: %d frames" % (os.path.relpath(path, SRC), len(frames)))
    print("decoded values compared: %d, encoded values compared: %d" % (checked_decode, checked_encode))
    for f in failures[:30]:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
