"""lash.can: DBC databases and CAN logs.

``Database(path)`` loads a DBC file with lash's reader; ``decode``/``encode`` use lash's
signal codec (physical = raw * factor + offset). ``read_log(path)`` returns the frames of
a log as a numpy structured array with the fields

- ``timestamp`` [s] (float64, the log's time base),
- ``id`` (uint32, 11- or 29-bit identifier),
- ``flags`` (uint8: FLAG_EXTENDED, FLAG_REMOTE, FLAG_FD, FLAG_BRS, FLAG_ESI, FLAG_ERROR),
- ``dlc`` (uint8, data length in bytes),
- ``data`` (64 × uint8, the first ``dlc`` bytes are the payload).

A python-can ``can.Message`` is accepted wherever a frame is (``decode(msg)``);
``to_messages(frames)`` turns read_log's rows into ``can.Message`` objects.
"""
from __future__ import annotations

from ._lash import _can

Database = _can.Database
read_log = _can.read_log
FLAG_EXTENDED: int = _can.FLAG_EXTENDED
FLAG_REMOTE: int = _can.FLAG_REMOTE
FLAG_FD: int = _can.FLAG_FD
FLAG_BRS: int = _can.FLAG_BRS
FLAG_ESI: int = _can.FLAG_ESI
FLAG_ERROR: int = _can.FLAG_ERROR

__all__ = ["Database", "read_log", "to_messages", "FLAG_EXTENDED", "FLAG_REMOTE", "FLAG_FD", "FLAG_BRS", "FLAG_ESI",
           "FLAG_ERROR"]


def to_messages(frames):
    """Rows of read_log() as python-can ``can.Message`` objects (needs python-can)."""
    import can as _pycan

    out = []
    for r in frames:
        flags = int(r["flags"])
        n = int(r["dlc"])
        out.append(_pycan.Message(timestamp=float(r["timestamp"]), arbitration_id=int(r["id"]),
                                  is_extended_id=bool(flags & FLAG_EXTENDED),
                                  is_remote_frame=bool(flags & FLAG_REMOTE), is_fd=bool(flags & FLAG_FD),
                                  bitrate_switch=bool(flags & FLAG_BRS), error_state_indicator=bool(flags & FLAG_ESI),
                                  is_error_frame=bool(flags & FLAG_ERROR),
                                  dlc=n, data=bytes(r["data"][:n])))
    return out
