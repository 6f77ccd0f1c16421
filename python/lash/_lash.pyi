# Type stubs of the extension module lash._lash (public names are re-exported by lash).
from typing import Any, Iterable, Mapping, Sequence

import numpy as np
import numpy.typing as npt

from . import _can as _can

ArrayLike = npt.ArrayLike

class InputError(ValueError):
    """Bad input: .file, .line (1-based; 0 = none), .key name where, .message says what."""
    file: str
    line: int
    key: str
    message: str

class Result:
    """What `lash estimate` reports about one record."""
    def to_dict(self) -> dict[str, Any]:
        """The object `lash estimate --json` prints for the same data and settings."""
    @property
    def json(self) -> str: ...
    @property
    def model(self) -> str: ...
    @property
    def samples(self) -> int:
        """Samples stepped, including skipped ones."""
    @property
    def skipped(self) -> int:
        """Samples skipped because v or y was not finite."""
    @property
    def identified(self) -> bool: ...
    @property
    def dt_s(self) -> float:
        """Sample period used: mean step of t [s]."""
    @property
    def nrmse(self) -> float:
        """NRMSE of the free-run simulation over the window (fraction)."""
    @property
    def nrmse_window_s(self) -> tuple[float, float]:
        """NRMSE window (t0, t1) [s]."""
    @property
    def yhat(self) -> npt.NDArray[np.float64] | None:
        """One-step prediction per sample [output unit] (lash.estimate only)."""
    @property
    def ysim(self) -> npt.NDArray[np.float64] | None:
        """Free-run simulated output per sample [output unit] (lash.estimate only)."""
    @property
    def params(self) -> dict[str, npt.NDArray[np.float64]] | None:
        """With trace=True: each parameter per sample (NaN while not identified)."""
    def __getitem__(self, key: str) -> Any: ...

def estimate(t: ArrayLike, v: ArrayLike, y: ArrayLike, *, model: str = "deadzone-deadband", preset: str = "lash",
             outlier_gate: float = 12.0, trace: bool = False, intervals: bool = True, **settings: Any) -> Result:
    """Identify a model from a whole record (t [s], v [input unit], y [output unit])."""

class Estimator:
    """One estimator fed sample by sample; the k-th sample is at t = k*dt_s [s]."""
    def __init__(self, model: str, dt_s: float, *, preset: str = "lash", reguess: bool = False,
                 **settings: Any) -> None: ...
    def update(self, v: float, y: float) -> float:
        """One sample; returns the one-step prediction yhat [output unit]."""
    def update_many(self, v: ArrayLike, y: ArrayLike) -> npt.NDArray[np.float64]:
        """Many samples; returns yhat per sample."""
    def result(self, *, intervals: bool = True) -> Result: ...
    def reset(self) -> None: ...
    @property
    def samples(self) -> int: ...
    @property
    def dt_s(self) -> float: ...
    @property
    def identified(self) -> bool: ...
    @property
    def reguesses(self) -> dict[str, int]:
        """Moves of each side's switching guess so far (reguess=True; docs/method.md A4.8)."""
    @property
    def guesses(self) -> dict[str, float]:
        """Each side's switching guess now [input unit]."""
    def params(self) -> dict[str, float]:
        """Current parameters by name (a1_r, b1_r, c_r, d_r, ...; NaN = not identified)."""

class Plant:
    """A chain of blocks (docs/method.md §A1), from [[blocks]] tables (docs/plant-files.md) or a plant file."""
    def __init__(self, *, blocks: Sequence[Mapping[str, Any]], dt_s: float = 0.005) -> None: ...
    @staticmethod
    def from_toml(path: str, dt_s: float | None = None) -> Plant: ...
    def simulate(self, v: ArrayLike, *, noise_variance: float = 0.0, seed: int = 1) -> dict[str, npt.NDArray[np.float64]]:
        """t [s], v, y (with noise), y_true and each block's output x<i>_<kind>."""
    @property
    def dt_s(self) -> float: ...
    @property
    def blocks(self) -> list[str]: ...

def signal(kind: str, duration_s: float, dt_s: float, *, amplitude: float = 1.0, frequency_rad_s: float = 1.0,
           offset: float = 0.0, phase_rad: float = 0.0, variance: float = 10000.0, tau_s: float = 0.5, seed: int = 1,
           steps: Iterable[tuple[float, float]] = ()) -> npt.NDArray[np.float64]:
    """round(duration_s/dt_s) samples of an excitation (sine | square | triangle | randomized | steps | constant)."""

def monitor_log(path: str, dbc: str, v: str, y: str, *, model: str = "deadzone-deadband", preset: str = "lash",
                every: float = 1.0, dt: float = 0.0, window: float = 120.0, stale_timeout: float = 0.5,
                record: str = "", db: str = "", jsonl: str = "", **settings: Any) -> dict[str, Any]:
    """`lash monitor LOGFILE` as a call: the history, one entry per period (t, samples, status, each
    parameter with <param>_lo/_hi, NaN while not identified), events (dict of columns), counts, last."""

def read_record(path: str, columns: Sequence[str] = ("t", "v", "y")) -> dict[str, Any]:
    """t [s], v, y arrays, dt_s [s] and file of a CSV or MAT record."""

class DeadzoneInverse:
    """Deadzone inverse (docs/compensation.md): u [output unit] -> v [input unit] with DZ(DI(u)) = u.
    right, left: deadzone edges c_r, |c_l| >= 0 [input unit]; slopes > 0 [output unit / input unit];
    smoothing: band delta >= 0 around u = 0 [output unit] (0 = exact inverse)."""
    def __init__(self, right: float, left: float, *, slope_right: float = 1.0, slope_left: float = 1.0,
                 smoothing: float = 0.0) -> None: ...
    def step(self, u: float) -> float:
        """One sample: desired deadzone output u [output unit] -> command v [input unit]."""
    def apply(self, u: ArrayLike) -> npt.NDArray[np.float64]:
        """step() on every sample of a 1-D array (GIL released)."""
    def set_params(self, *, right: float = ..., left: float = ..., slope_right: float = ..., slope_left: float = ...,
                   smoothing: float = ...) -> None:
        """Replaces the given parameters between samples (units as in the constructor)."""
    @property
    def params(self) -> dict[str, float]: ...

class BacklashInverse:
    """Backlash inverse (docs/compensation.md): desired output u -> backlash input w [unit of w],
    B(BI(u)) = u. right, left: gaps >= 0 while pushed up / down [unit of w] (deadband half-width d);
    smoothing: travel of u over which the gap is crossed [unit of u] (0 = jump)."""
    def __init__(self, right: float, left: float, *, smoothing: float = 0.0) -> None: ...
    def step(self, u: float) -> float:
        """One sample u(k) -> w(k) [unit of w]."""
    def apply(self, u: ArrayLike) -> npt.NDArray[np.float64]:
        """step() on every sample of a 1-D array, continuing from the current state (GIL released)."""
    def reset(self, u0: float = 0.0, rising: bool = True) -> None:
        """From rest at output u0, engaged rising (w = u0 + right) or falling (w = u0 - left)."""
    def set_params(self, *, right: float = ..., left: float = ..., smoothing: float = ...) -> None:
        """Replaces the given widths between samples [unit of w]; smoothing [unit of u]."""
    @property
    def offset(self) -> float:
        """Current offset w - u [unit of w]."""
    @property
    def params(self) -> dict[str, float]: ...

def _sweep_csv(campaign_path: str, jobs: int = 0) -> str: ...
