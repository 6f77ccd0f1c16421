from typing import Any, Mapping

import numpy as np
import numpy.typing as npt

FLAG_EXTENDED: int
FLAG_REMOTE: int
FLAG_FD: int
FLAG_BRS: int
FLAG_ESI: int
FLAG_ERROR: int

class Database:
    """A DBC file loaded by lash's reader."""
    def __init__(self, path: str) -> None: ...
    def decode(self, message: int | str | Any, data: bytes | None = None, *, extended: bool | None = None) -> dict[str, float]:
        """Signal name -> physical value (raw * factor + offset) in the signal's unit."""
    def encode(self, message: int | str, values: Mapping[str, float | str], *, clamp: bool = False) -> bytes:
        """The payload with the given physical values (or VAL_ texts), as `lash can encode`."""
    @property
    def messages(self) -> dict[str, dict[str, Any]]: ...
    @property
    def path(self) -> str: ...

def read_log(path: str) -> npt.NDArray[np.void]:
    """Frames as a structured array: timestamp [s], id, flags, dlc [byte], data (64 bytes)."""
