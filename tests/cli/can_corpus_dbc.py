"""lash's tolerant DBC reader, `dbc list --json`, `dbc check` and decoder against
canmatrix (Debian python3-canmatrix) on the corpus of DBC files other tools wrote
(../shared/data/can-corpus/dbc, cantools' test files).

Asserts: >= 82 of the 83 files load; on every loaded file `dbc list --json` agrees
with canmatrix on ids, lengths and signal layouts (start bit, length, byte order,
sign, factor, offset, multiplexing); node long names (SystemNodeLongSymbol, read from the
text) replace the short names in BU_, senders and receivers; random frames (fixed seed; every multiplexor set
to each value that selects something) decode like canmatrix to 1e-9 relative for every
signal canmatrix decodes; `dbc check` exits 1 on bad_message_length.dbc.
"""
import glob
import json
import logging
import os
import random
import re
import subprocess
import sys
import tempfile

logging.disable(logging.CRITICAL)
import canmatrix.formats  # noqa: E402

LASH = os.environ["LASH"]
SRC = os.environ["LASH_SOURCE_DIR"]
CORPUS = os.path.join(SRC, "..", "shared", "data", "can-corpus", "dbc")
# files with deliberate layout errors (cantools tests them): a signal beyond the frame
EXPECTED_LAYOUT_ERRORS = {"bad_message_length.dbc"}
FRAME_LENGTHS = set(range(9)) | {12, 16, 20, 24, 32, 48, 64}
NODE_LONG = re.compile(r'BA_\s+"SystemNodeLongSymbol"\s+BU_\s+(\S+)\s+"([^"]*)"\s*;')


def close(a, b):
    if a != a and b != b:  # both NaN
        return True
    return a == b or abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))


def set_bits(data, sig, raw):
    """Writes raw into the payload bytes with the DBC layout (Intel LSB start / Motorola MSB sawtooth)."""
    n = sig["length"]
    start = sig["start_bit"]
    for i in range(n):  # i = bit index from the LSB
        if sig["byte_order"] == "intel":
            pos = start + i
            byte, bit = pos // 8, pos % 8
        else:
            q = 8 * (start // 8) + 7 - start % 8 + (n - 1 - i)
            byte, bit = q // 8, 7 - q % 8
        if (raw >> i) & 1:
            data[byte] |= 1 << bit
        else:
            data[byte] &= ~(1 << bit) & 0xFF


def payloads(rng, msg):
    """Random payloads; with multiplexors, every selecting value (lowest and highest of each
    range) of every multiplexor, its own multiplexors set to values that select it."""
    out = [bytearray(rng.randrange(256) for _ in range(msg["length"])) for _ in range(6)]
    sigs = {s["name"]: s for s in msg["signals"]}
    for s in msg["signals"]:
        if "mux_values" not in s or s.get("multiplexor") not in sigs:
            continue
        for lo, hi in s["mux_values"]:
            for v in sorted({lo, hi}):
                data = bytearray(rng.randrange(256) for _ in range(msg["length"]))
                cur, val, seen = s, v, set()
                while "mux_values" in cur and cur.get("multiplexor") in sigs and cur["name"] not in seen:
                    seen.add(cur["name"])
                    parent = sigs[cur["multiplexor"]]
                    if val < (1 << parent["length"]):
                        set_bits(data, parent, val)
                    cur, val = parent, (parent["mux_values"][0][0] if "mux_values" in parent else 0)
                out.append(data)
    return out


def main():
    if not os.path.isdir(CORPUS):
        print("corpus not found:", CORPUS)
        return 77
    files = sorted(glob.glob(os.path.join(CORPUS, "*.dbc")) + glob.glob(os.path.join(CORPUS, "*.DBC")))
    rng = random.Random(20261123)
    loaded, failures = 0, []
    n_values = n_frames = n_layouts = n_long_names = 0
    skipped_by_canmatrix = []
    for path in files:
        name = os.path.basename(path)
        r = subprocess.run([LASH, "can", "dbc", "list", "--json", path], capture_output=True, text=True, errors="replace")
        if r.returncode != 0:
            print("NOT LOADED", name, r.stderr.strip().splitlines()[-1:])
            continue
        loaded += 1
        ours = json.loads(r.stdout)
        try:
            cm = canmatrix.formats.loadp_flat(path)
        except Exception as e:  # noqa: BLE001
            print("canmatrix cannot load", name, e)
            continue
        # Node long names (BA_ "SystemNodeLongSymbol" BU_ short "long"), read from the text with a
        # regex: the long name replaces the short one in BU_, as sender and as receiver.
        with open(path, "rb") as fh:
            text = fh.read().decode("latin-1")
        for short, long_ in NODE_LONG.findall(text):
            n_long_names += 1
            used = set(ours["nodes"])
            for msg in ours["messages"]:
                used.update(msg["senders"])
                for s in msg["signals"]:
                    used.update(s["receivers"])
            if short != long_ and short in used:
                failures.append(f"{name}: node {short} still used under its short name (long name {long_})")
            if long_ not in ours["nodes"]:
                failures.append(f"{name}: node long name {long_} not in BU_ {ours['nodes']}")
        frames = {f.arbitration_id.id: f for f in cm.frames}
        lines, expected = [], []
        t = 1.0
        for msg in ours["messages"]:
            fr = frames.get(msg["id"])
            if fr is None:  # canmatrix skips some lines it cannot read (e.g. ids > 0x7FF without bit 31)
                skipped_by_canmatrix.append(f"{name}:{msg['name']}")
                continue
            if fr.size != msg["length"]:
                failures.append(f"{name}: {msg['name']} length {msg['length']} vs canmatrix {fr.size}")
            for s in msg["signals"]:
                cs = fr.signal_by_name(s["name"])
                if cs is None:
                    failures.append(f"{name}: {msg['name']}.{s['name']} not in canmatrix")
                    continue
                n_layouts += 1
                got = (s["start_bit"], s["length"], s["byte_order"] == "intel", s["signed"])
                want = (cs.get_startbit(bit_numbering=1, start_little=False) if not cs.is_little_endian
                        else cs.get_startbit(), cs.size, cs.is_little_endian, cs.is_signed)
                if got != want or not close(s["factor"], float(cs.factor)) or not close(s["offset"], float(cs.offset)):
                    failures.append(f"{name}: {msg['name']}.{s['name']} layout {got} x{s['factor']}+{s['offset']} "
                                    f"vs canmatrix {want} x{cs.factor}+{cs.offset}")
                if (s["multiplexing"] == "multiplexor") != (cs.is_multiplexer and cs.mux_val is None):
                    failures.append(f"{name}: {msg['name']}.{s['name']} multiplexing {s['multiplexing']!r} vs canmatrix")
            if msg["length"] not in FRAME_LENGTHS:
                continue  # no CAN (FD) frame has this length (variable_dlc.dbc): nothing to decode
            for data in payloads(rng, msg):
                idtxt = ("%08X" if msg["extended"] else "%03X") % msg["id"]
                sep = "##0" if msg["length"] > 8 else "#"
                lines.append("(%.6f) can0 %s%s%s" % (t, idtxt, sep, bytes(data).hex().upper()))
                try:
                    dec = fr.decode(bytes(data))
                    expected.append((msg, {k: float(v.phys_value) for k, v in dec.items()}))
                except Exception as e:  # noqa: BLE001
                    expected.append((msg, None))
                t += 0.001
        if not lines:
            continue
        with tempfile.NamedTemporaryFile("w", suffix=".log", delete=False) as fh:
            fh.write("\n".join(lines) + "\n")
            log = fh.name
        out = subprocess.run([LASH, "can", "decode", "--dbc", path, log], capture_output=True, text=True,
                             errors="replace")
        failures += [f"{name}: {ln}" for ln in out.stderr.splitlines() if "error:" in ln and "signal-out-of-frame" not in ln
                     and name not in EXPECTED_LAYOUT_ERRORS]
        os.unlink(log)
        if out.returncode != 0:
            failures.append(f"{name}: decode failed: {out.stderr.strip()[-300:]}")
            continue
        got_lines = out.stdout.rstrip("\n").split("\n")
        assert len(got_lines) == len(expected), (name, len(got_lines), len(expected))
        for line, (msg, exp) in zip(got_lines, expected):
            if exp is None:
                continue
            toks = line.split(" ")
            if toks[1] == "?":
                continue  # a message with layout errors (reported at load)
            n_frames += 1
            names = {s["name"] for s in msg["signals"]}
            vals = {}
            for tok in toks[2:]:
                k, eq, v = tok.partition("=")
                if eq and k in names:
                    vals[k] = float(v)
            for k, v in exp.items():
                if k not in vals:
                    failures.append(f"{name}: {msg['name']}.{k} decoded by canmatrix ({v}) but not by lash: {line}")
                elif not close(vals[k], v):
                    failures.append(f"{name}: {msg['name']}.{k} lash {vals[k]!r} canmatrix {v!r}")
                n_values += 1
    print(f"loaded {loaded} of {len(files)} DBC files; {n_layouts} signal layouts and {n_values} values "
          f"from {n_frames} frames compared with canmatrix; {len(failures)} mismatches; "
          f"{len(skipped_by_canmatrix)} messages lash reads but canmatrix skips; {n_long_names} node long names applied")
    for f in failures[:40]:
        print("  ", f)
    chk = subprocess.run([LASH, "can", "dbc", "check", os.path.join(CORPUS, "bad_message_length.dbc")],
                         capture_output=True, text=True)
    print(chk.stdout.strip())
    ok = loaded >= 82 and n_long_names >= 5 and not failures and chk.returncode == 1 and "signal-out-of-frame" in chk.stdout
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
