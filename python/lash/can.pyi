from typing import Any, Iterable

from ._can import Database as Database, read_log as read_log

FLAG_EXTENDED: int
FLAG_REMOTE: int
FLAG_FD: int
FLAG_BRS: int
FLAG_ESI: int
FLAG_ERROR: int

def to_messages(frames: Iterable[Any]) -> list[Any]:
    """Rows of read_log() as python-can can.Message objects."""
