"""`woodpile.calibrate`: a physical scene's keys fitted to a measured velocity trace."""

from __future__ import annotations

from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import pandas as pd

from . import _core

Bounds = Union[Tuple[float, float], Mapping[str, float]]


class CalibrationResult:
    """A finished calibration.

    Attributes:
        estimates: one row per fitted key: ``key``, ``value``, ``std_error``, and the 95%
            interval ``low``..``high`` (``at_bound`` when the value sits on its box's edge).
        trace: the measured trace with ``fitted`` (the fitted scene's velocity, m/s) and
            ``residual`` (measured minus fitted) beside it.
        rms: the residuals' root mean square, m/s.
        method, dt_s: the method and step (s) every simulation of the fit ran.
        verification: the fitted scene run as written (``auto``) against that step:
            ``max_difference`` and ``allowed`` (m/s), ``passed``.
        scene_toml: the scene with the fitted values, as TOML text.
        iterations, simulations: what the fit took.
    """

    def __init__(self, raw: Dict[str, Any], trace: pd.DataFrame) -> None:
        self.estimates = pd.DataFrame(raw["estimates"])
        self.trace = trace.assign(fitted=raw["fitted"], residual=raw["residuals"])
        self.rms: float = raw["rms"]
        self.method: str = raw["method"]
        self.dt_s: float = raw["dt_s"]
        self.verification: Dict[str, Any] = raw["verification"]
        self.scene_toml: str = raw["scene"]
        self.iterations: int = raw["iterations"]
        self.simulations: int = raw["simulations"]

    def value(self, key: str) -> float:
        """The fitted value of ``key``."""
        return float(self.estimates.set_index("key").loc[key, "value"])

    def plot(self, ax: Any = None) -> Any:
        """The measured trace (points) and the fit (lines), one colour per rod, in ms and mm/s."""
        import matplotlib.pyplot as plt

        ax = ax or plt.figure(figsize=(7, 3.5)).gca()
        for rod, rows in self.trace.groupby("rod"):
            ms = rows["t"] * 1e3
            (line,) = ax.plot(ms, rows["fitted"] * 1e3, lw=1, label=f"rod {rod}")
            ax.plot(ms, rows["velocity"] * 1e3, ".", ms=2, color=line.get_color(), alpha=0.5)
        ax.set_xlabel("t (ms)")
        ax.set_ylabel("v (mm/s)")
        ax.legend(frameon=False)
        return ax

    def __repr__(self) -> str:
        fitted = ", ".join(
            f"{r.key}={r.value:.6g}±{r.std_error:.2g}" for r in self.estimates.itertuples()
        )
        return f"CalibrationResult({fitted}, rms={self.rms:.3g} m/s)"


def calibrate(
    scene: Any,
    trace: Union[pd.DataFrame, Mapping[str, Sequence[float]]],
    parameters: Mapping[str, Bounds],
) -> CalibrationResult:
    """Fit a physical scene's keys to a measured trace by weighted least squares.

    Args:
        scene: an SI scene (with ``[physical]``): a dict, TOML text or a path.
        trace: columns ``t`` (s after the impact), ``rod`` (paper site), ``velocity`` (m/s),
            and optionally ``sigma`` (each row's standard deviation, m/s; rows are then
            weighted by 1/sigma).
        parameters: each fitted key by its dotted name (``"damping.contact"``,
            ``"defect[0].quality_factor"``, ``"chain.boundary.right.spring"``) with its box,
            ``(min, max)`` or ``{"min": ..., "max": ..., "start": ...}``.

    Every simulation of the fit runs one method at one step, the one ``auto`` verifies on the
    starting scene, so that the residuals are smooth in the parameters; the fitted scene is
    then run as written and compared (``verification``). Intervals are ±1.96 standard errors
    from the Jacobian (for a positive box, on the logarithm); docs/calibration.md says how
    often they hold the truth. Ctrl-C stops the fit between simulations.
    """
    frame = pd.DataFrame(trace)
    missing = [c for c in ("t", "rod", "velocity") if c not in frame.columns]
    if missing:
        raise _core.SceneError(f"calibrate: the trace has no column {missing[0]!r}")
    sigma: Optional[np.ndarray] = None
    if "sigma" in frame.columns:
        sigma = frame["sigma"].to_numpy(dtype=float)
    rods = frame["rod"].to_numpy(dtype=float)
    if not np.all(np.isfinite(rods) & (rods == np.round(rods))):
        raise _core.SceneError("calibrate: column 'rod' holds a value that is not a whole paper site")
    asked = [_parameter(key, bounds) for key, bounds in parameters.items()]
    raw = _core.calibrate(
        scene,
        frame["t"].to_numpy(dtype=float).tolist(),
        frame["rod"].to_numpy(dtype=np.int64).tolist(),
        frame["velocity"].to_numpy(dtype=float).tolist(),
        None if sigma is None else sigma.tolist(),
        asked,
    )
    return CalibrationResult(raw, frame[["t", "rod", "velocity"]].copy())


def _parameter(key: str, bounds: Bounds) -> Tuple[str, float, float, Optional[float]]:
    if isinstance(bounds, Mapping):
        start = bounds.get("start")
        return (key, float(bounds["min"]), float(bounds["max"]), None if start is None else float(start))
    low, high = bounds
    return (key, float(low), float(high), None)
