"""lash.can against the independent readers on the corpus written by other tools
(../shared/data/can-corpus): Database.decode equals canmatrix on random frames of every corpus
DBC that lash loads; read_log gives the frames python-can's readers give; encode round-trips
through canmatrix; a python-can can.Message is accepted as a frame."""
import glob
import logging
import math
import os
import random

import numpy as np
import pytest

import lash
from conftest import CORPUS, SRC

logging.disable(logging.CRITICAL)
canmatrix_formats = pytest.importorskip("canmatrix.formats")
pycan = pytest.importorskip("can")

if not os.path.isdir(CORPUS):
    pytest.skip("no CAN corpus at " + CORPUS, allow_module_level=True)

DBCS = sorted(glob.glob(os.path.join(CORPUS, "dbc", "*.dbc")) + glob.glob(os.path.join(CORPUS, "dbc", "*.DBC")))
LOGS = sorted(p for p in glob.glob(os.path.join(CORPUS, "logs", "*", "*")) if os.path.isfile(p))


def close(a, b):
    if math.isnan(a) or math.isnan(b):  # a float signal holding a NaN pattern
        return math.isnan(a) and math.isnan(b)
    return a == b or abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))


def canmatrix_db(path):
    try:
        return canmatrix_formats.loadp_flat(path)
    except Exception:  # canmatrix refuses a few deliberately broken files
        return None


def test_decode_equals_canmatrix():
    rng = random.Random(20261123)
    compared = files = 0
    failures, not_loaded, unmatched = [], [], []
    for path in DBCS:
        ref = canmatrix_db(path)
        if ref is None:
            continue
        try:
            db = lash.can.Database(path)
        except lash.InputError as e:
            not_loaded.append("%s: %s" % (os.path.basename(path), e))
            continue
        files += 1
        for fr in ref.frames:
            if not fr.signals or fr.size > 8 or fr.size == 0:
                continue
            ext = bool(fr.arbitration_id.extended)
            mine = [m for m in db.messages.values() if m["id"] == fr.arbitration_id.id and m["extended"] == ext]
            if not mine:  # an id above 0x7FF written without bit 31: lash reads it as extended (DESIGN.md)
                mine = [m for m in db.messages.values() if m["id"] == fr.arbitration_id.id]
                ext = mine[0]["extended"] if len(mine) == 1 else ext
            if not mine:  # canmatrix failed on the file's BO_ lines and made up a frame (issue_199_extended.dbc)
                unmatched.append("%s %s %#x" % (os.path.basename(path), fr.name, fr.arbitration_id.id))
                continue
            assert len(mine) == 1, (path, fr.name)
            # signals in file order; canmatrix reads long names (SYSTEM_SIGNAL_LONG_SYMBOL) where
            # lash keeps the 32-character DBC names, so names are matched by position
            lash_names = list(mine[0]["signals"])
            assert len(lash_names) == len(fr.signals), (path, fr.name)
            to_lash = {s.name: n for s, n in zip(fr.signals, lash_names)}
            # canmatrix's "complex multiplexing" path picks the signals of another multiplexor value
            # (multiplex.dbc: value 24 gives the m8 signals); there only the common signals are compared
            exact_set = not fr.is_complex_multiplexed
            for _ in range(25):
                data = bytes(rng.randrange(256) for _ in range(fr.size))
                try:
                    exp = {to_lash[k]: float(v.phys_value) for k, v in fr.decode(data).items()}
                except Exception:
                    continue
                try:
                    got = db.decode(fr.arbitration_id.id, data, extended=ext)
                except lash.InputError as e:
                    failures.append("%s %s: %s" % (os.path.basename(path), fr.name, e))
                    break
                if exact_set and set(got) != set(exp):
                    failures.append("%s %s: signals %s vs canmatrix %s" % (os.path.basename(path), fr.name,
                                                                          sorted(got), sorted(exp)))
                    break
                for k in set(exp) & set(got):
                    if not close(got[k], exp[k]):
                        failures.append("%s %s.%s: lash %r canmatrix %r (data %s)" % (
                            os.path.basename(path), fr.name, k, got[k], exp[k], data.hex()))
                    compared += 1
    print("DBC files compared: %d, values: %d; not loaded by lash: %d" % (files, compared, len(not_loaded)))
    for n in not_loaded:
        print("  not loaded:", n)
    print("canmatrix frames without a lash message:", unmatched)
    assert len(unmatched) <= 2, unmatched
    assert not failures, "\n".join(failures[:20])
    assert files >= 60 and compared >= 10000


def test_encode_roundtrips_through_canmatrix():
    path = os.path.join(CORPUS, "dbc", "motohawk.dbc")
    db = lash.can.Database(path)
    ref = canmatrix_db(path)
    name = "ExampleMessage"
    assert name in db.messages
    values = {"Temperature": 250.1, "AverageRadius": 3.2, "Enable": 1.0}
    data = db.encode(name, values)
    assert len(data) == db.messages[name]["size"]
    dec = ref.frame_by_name(name).decode(data)
    for k, v in values.items():
        assert close(float(dec[k].phys_value), v), (k, dec[k].phys_value, v)
    assert db.decode(name, data) == pytest.approx(values)


def test_python_can_message_is_a_frame():
    path = os.path.join(CORPUS, "dbc", "motohawk.dbc")
    db = lash.can.Database(path)
    m = db.messages["ExampleMessage"]
    data = db.encode("ExampleMessage", {"Temperature": 244.0, "AverageRadius": 1.5, "Enable": 0.0})
    msg = pycan.Message(arbitration_id=m["id"], is_extended_id=m["extended"], data=data)
    assert db.decode(msg) == db.decode(m["id"], data) == db.decode("ExampleMessage", data)
    with pytest.raises(lash.InputError):
        db.decode(pycan.Message(arbitration_id=0x7AB, is_extended_id=False, data=b"\0" * 8))
    with pytest.raises(lash.InputError):
        db.decode("ExampleMessage", b"\x01")  # too short for the message


def python_can_frames(path):
    with pycan.LogReader(path) as r:
        return list(r)


def test_read_log_equals_python_can():
    compared, skipped = [], []
    for path in LOGS:
        try:
            ref = python_can_frames(path)
        except Exception as e:  # python-can cannot read it either
            skipped.append("%s (python-can: %s)" % (os.path.relpath(path, CORPUS), e))
            continue
        try:
            got = lash.can.read_log(path)
        except lash.InputError as e:
            skipped.append("%s (lash: %s)" % (os.path.relpath(path, CORPUS), e))
            continue
        name = os.path.relpath(path, CORPUS)
        if path.endswith(".trc"):
            # python-can 4.1's TRCReader drops remote-request lines ("RR": "Unsupported type");
            # lash reads them as remote frames. Compare the rest, and count those against the text.
            rr = sum(1 for line in open(path, errors="replace") if " RR " in line)
            remote = (got["flags"] & lash.can.FLAG_REMOTE) != 0
            assert int(remote.sum()) == rr, (name, int(remote.sum()), rr)
            got = got[~remote]
        assert got.dtype.names == ("timestamp", "id", "flags", "dlc", "data")
        assert len(got) == len(ref), (name, len(got), len(ref))
        for i, (g, m) in enumerate(zip(got, ref)):
            flags = int(g["flags"])
            where = "%s frame %d" % (name, i)
            assert math.isclose(g["timestamp"], m.timestamp, rel_tol=0, abs_tol=1e-6), (where, g["timestamp"], m.timestamp)
            assert bool(flags & lash.can.FLAG_ERROR) == m.is_error_frame, where
            if m.is_error_frame:  # the id of an error frame is its error class, not an identifier
                continue
            assert int(g["id"]) == m.arbitration_id, where
            assert bool(flags & lash.can.FLAG_EXTENDED) == m.is_extended_id, where
            assert bool(flags & lash.can.FLAG_REMOTE) == m.is_remote_frame, where
            # a CAN FD frame has no remote form: python-can flags a remote CANFD line of an ASC file
            # is_fd, lash reads it as a classic remote frame; the FD flag is compared for data frames
            if not m.is_remote_frame:
                assert bool(flags & lash.can.FLAG_FD) == m.is_fd, where
            if m.is_fd and not m.is_remote_frame:
                assert bool(flags & lash.can.FLAG_BRS) == m.bitrate_switch, where
                assert bool(flags & lash.can.FLAG_ESI) == m.error_state_indicator, where
            if not (m.is_remote_frame or m.is_error_frame):
                n = int(g["dlc"])
                assert bytes(g["data"][:n]) == bytes(m.data), where
        compared.append(name)
    print("logs compared with python-can:", compared)
    print("skipped:", skipped)
    # every format lash reads is compared (candump, Vector ASC and BLF, PEAK TRC)
    for fmt in ("candump", "vector-asc", "vector-blf", "peak-trc"):
        assert any(c.startswith("logs/" + fmt) for c in compared), (fmt, compared, skipped)
    # to_messages gives python-can objects back
    if compared:
        msgs = lash.can.to_messages(lash.can.read_log(os.path.join(CORPUS, compared[0])))
        assert all(isinstance(m, pycan.Message) for m in msgs)
