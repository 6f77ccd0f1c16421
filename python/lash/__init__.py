"""lash: online deadzone/backlash identification, plant simulation and CAN tools.

A thin layer over lash's C++ library (the same code as the `lash` command line):
numpy arrays in and out, the GIL released inside every loop over samples.

Units: time t and periods in seconds (names end in ``_s``), the input v in the plant's
input unit, the output y in its output unit; deadzone c and deadband d in the unit of
the signal they act on (c on v, d on y). See docs/python.md.
"""
from __future__ import annotations

import csv as _csv
import io as _io

from ._lash import (  # noqa: F401  (re-exported)
    BacklashInverse,
    DeadzoneInverse,
    Estimator,
    InputError,
    Plant,
    Result,
    estimate,
    monitor_log,
    read_record,
    signal,
)
from ._lash import _sweep_csv
from . import can  # noqa: F401
from . import xcp  # noqa: F401

__all__ = ["BacklashInverse", "DeadzoneInverse", "Estimator", "InputError", "Plant", "Result", "estimate", "monitor_log", "read_record", "signal", "sweep", "can", "xcp"]
__version__ = "0.1.0"

InputError.__doc__ = (
    "Bad input (a ValueError): .file, .line (1-based, 0 = none) and .key name where; .message says what.")


def _cell(text: str):
    """A results-CSV cell as Python: int, float (nan for not identified) or the text."""
    for conv in (int, float):
        try:
            return conv(text)
        except ValueError:
            pass
    return text


def sweep(campaign_path: str, jobs: int | None = None) -> list[dict]:
    """Runs a campaign file (docs/sweep.md) as `lash sweep` does, on `jobs` threads
    (None = all cores), and returns one dict per run with the columns of the results CSV
    (nrmse as a fraction, tau in s, not-identified values nan)."""
    text = _sweep_csv(str(campaign_path), 0 if jobs is None else int(jobs))
    return [{k: _cell(v) for k, v in row.items()} for row in _csv.DictReader(_io.StringIO(text))]
