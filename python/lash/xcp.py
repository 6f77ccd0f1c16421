"""lash.xcp: an XCP-on-CAN master over an A2L file (docs/xcp.md).

``Client(a2l, bus=..., timeout_ms=500)`` connects to the ECU the A2L describes (``lash hil a2l``);
``get(name)``, ``set(name, value)`` (refused outside the A2L limits), ``daq(names, duration_s)``
(one sample per control step, with the ECU's timestamp), ``epk()``, ``close()``; a context manager.
"""
from __future__ import annotations

from ._lash import _xcp

Client = _xcp.Client

__all__ = ["Client"]
