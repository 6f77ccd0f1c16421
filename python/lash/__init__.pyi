from ._lash import (BacklashInverse as BacklashInverse, DeadzoneInverse as DeadzoneInverse,
                    Estimator as Estimator, InputError as InputError, Plant as Plant, Result as Result,
                    estimate as estimate, monitor_log as monitor_log, read_record as read_record, signal as signal)
from . import can as can
from . import xcp as xcp

__version__: str

def sweep(campaign_path: str, jobs: int | None = None) -> list[dict[str, int | float | str]]:
    """One dict per run of a campaign, with the columns of `lash sweep`'s results CSV."""
