"""One scene: ``simulate`` and the ``SimulationResult`` it returns."""

from __future__ import annotations

import json
import warnings
import os
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np
import pandas as pd

from . import _core
from ._progress import Progress

Scene = Union[Dict[str, Any], str, "os.PathLike[str]"]


class SimulationResult:
    """What one simulated scene gave: the fractions at ``t_end``, how far they can be
    trusted, their time series and, when asked for, the space-time field.

    Every key of ``woodpile simulate``'s JSON object is an attribute (``R``, ``T``,
    ``E_tr``, ``error_estimate``, ``method``, ``dt``, ``steps``, ``tolerance``, ...), and
    ``as_dict()`` returns that object exactly.

    Attributes:
        S: the striker's share at ``t_end`` for a scene with a ``[striker]``, else None.
        D: the share of E(0) dissipated by ``t_end`` for a scene with damping, else None
            (the shares are then of E(0), ``normalisation == "E(0)"``, and sum to 1 with D).
        series: a DataFrame with columns ``t``, ``R``, ``T``, ``E_tr`` (``S`` with a striker,
            ``D`` with damping), ``E`` at every ``run.sample_every``. R, T and E_tr are the
            shares of the energy left of, right of and inside the region at that time (R = 1
            before the wave arrives).
        t: the sample times (a float64 array).
        sites: the paper site numbers of the field's columns (int64), or None.
        velocity: site velocities, float64, shape (len(t), len(sites)), or None.
        displacement: site displacements, laid out as ``velocity``, or None.
        energy: each site's energy (its mass's kinetic energy, half of each of its bonds, its
            wall or soft end, its resonator's kinetic and spring energy), laid out as
            ``velocity``; over the whole chain a row sums to E(t). None without a field.
        kinetic: each site's kinetic energy, its host mass applied and its resonator's
            included (what the woodpile experiment measures), laid out as ``velocity``.
        resonator_sites: the paper site of each resonator (int64), or None.
        resonator_displacement: each resonator's displacement, float64, shape (len(t),
            len(resonator_sites)), or None.
        resonator_velocity: each resonator's velocity, laid out as
            ``resonator_displacement``, or None.
    """

    R: float
    T: float
    E_tr: float
    S: Optional[float]
    D: Optional[float]
    E_initial: float
    E_final: float
    error_estimate: Optional[float]
    method: str
    requested_method: str
    dt: Optional[float]
    tolerance: float
    steps: int
    rejected_steps: int
    rhs_evals: int
    total_rhs_evals: int
    site_steps: int
    site_steps_full_chain: int
    energy_drift: Optional[float]
    energy_conserved: bool
    normalisation: str
    region: List[int]
    t_end: float
    wall_s: float
    version: str
    physical: Optional[Dict[str, Any]]
    units: Optional[str]
    end_reached_at: Optional[float]

    t: np.ndarray
    sites: Optional[np.ndarray]
    velocity: Optional[np.ndarray]
    displacement: Optional[np.ndarray]
    energy: Optional[np.ndarray]
    kinetic: Optional[np.ndarray]
    resonator_sites: Optional[np.ndarray]
    resonator_displacement: Optional[np.ndarray]
    resonator_velocity: Optional[np.ndarray]

    def __init__(self, raw: Dict[str, Any]) -> None:
        self._report: Dict[str, Any] = json.loads(raw["report"])
        for key, value in self._report.items():
            setattr(self, key, value)
        self.physical = self._report.get("physical")
        self.units = self._report.get("units")
        # A share the scene does not have (S without a striker, D without losses) is None.
        for share in _core.SHARES:
            setattr(self, share, self._report.get(share))
        self._series_columns: Dict[str, np.ndarray] = raw["series"]
        self._series: Optional[pd.DataFrame] = None
        self.t = raw.get("t", self._series_columns["t"])
        self.sites = raw.get("sites")
        self.velocity = raw.get("velocity")
        self.displacement = raw.get("displacement")
        self.energy = raw.get("energy")
        self.kinetic = raw.get("kinetic")
        self.resonator_sites = raw.get("resonator_sites")
        self.resonator_displacement = raw.get("resonator_displacement")
        self.resonator_velocity = raw.get("resonator_velocity")

    @property
    def series(self) -> pd.DataFrame:
        """R, T, E_tr and E at every ``run.sample_every`` (columns t, R, T, E_tr, (S,) (D,)
        E): the arrays the simulation returned, made a DataFrame on first access."""
        if self._series is None:
            # The native module lists t, the scene's shares in their order, then E.
            self._series = pd.DataFrame(self._series_columns)
        return self._series

    def as_dict(self) -> Dict[str, Any]:
        """The JSON object ``woodpile simulate`` prints for this scene (a copy)."""
        return json.loads(json.dumps(self._report))

    def field_frame(self) -> pd.DataFrame:
        """The field in long form (columns t, site, velocity, displacement, energy,
        kinetic, resonator_displacement, resonator_velocity; the last two NaN on a site
        without a resonator), as ``woodpile simulate --field`` writes it; needs
        ``fields=True`` or ``field_sites``."""
        if (
            self.velocity is None
            or self.sites is None
            or self.displacement is None
            or self.energy is None
            or self.kinetic is None
        ):
            raise ValueError("no field was recorded: call simulate(..., fields=True)")
        n_t, n_s = self.velocity.shape
        return pd.DataFrame(
            {
                "t": np.repeat(self.t, n_s),
                "site": np.tile(self.sites, n_t),
                "velocity": self.velocity.ravel(),
                "displacement": self.displacement.ravel(),
                "energy": self.energy.ravel(),
                "kinetic": self.kinetic.ravel(),
                "resonator_displacement": self._per_site(self.resonator_displacement).ravel(),
                "resonator_velocity": self._per_site(self.resonator_velocity).ravel(),
            }
        )

    def _per_site(self, values: Optional[np.ndarray]) -> np.ndarray:
        """A resonator array (time × resonator) on the field's sites (time × site), NaN where
        a site hosts no resonator."""
        assert self.sites is not None and self.velocity is not None
        out = np.full(self.velocity.shape, np.nan)
        if values is None or self.resonator_sites is None:
            return out
        column = {int(site): k for k, site in enumerate(self.sites)}
        for j, site in enumerate(self.resonator_sites):
            if int(site) in column:
                out[:, column[int(site)]] = values[:, j]
        return out

    def __repr__(self) -> str:
        est = "none" if self.error_estimate is None else f"{self.error_estimate:.1e}"
        return (
            f"SimulationResult(R={self.R:.6g}, T={self.T:.6g}, E_tr={self.E_tr:.6g}, "
            f"method={self.method!r}, error_estimate={est}, steps={self.steps})"
        )


def simulate(
    scene: Scene,
    *,
    fields: bool = False,
    field_sites: Optional[Tuple[int, int]] = None,
    series: str = "energy",
    progress: Optional[bool] = None,
    units: str = "scaled",
) -> SimulationResult:
    """Simulate one scene and return its fractions, series and (optionally) field.

    Args:
        scene: a dict with the keys of a scene file (``{"defect": [{"site": 0, "eps":
            10.0}], "run": {"t_end": 150.0}}``), a TOML string, or the path of a scene
            file (``str`` or ``os.PathLike``). Keys left out take the paper's defaults.
        fields: also record every site's velocity, displacement, energy and kinetic energy,
            and every resonator's displacement and velocity, at every sample.
        field_sites: record only the paper sites ``lo..=hi`` (implies ``fields``).
        series: what ``series`` splits: ``"energy"`` (shares of the total energy) or
            ``"kinetic"`` (kinetic energy over the impact energy, the woodpile experiment's
            measure, paper Fig. 2).
        progress: a line on stderr with the run of ``auto``'s ladder under way and its time:
            ``True`` always, ``False`` never, ``None`` (the default) in a terminal or a
            notebook once the run has taken two seconds.
        units: ``"scaled"`` (the model's units, the default) or ``"SI"`` for a ``[physical]``
            scene: times in s (``t``, ``t_end``, ``dt``, ``end_reached_at``), displacements in
            m, velocities in m/s and energies in J (``E_initial``, ``E_final``, the series'
            ``E`` unless it is a kinetic share, the field's ``energy`` and ``kinetic``). The
            shares have no unit. ``result.units`` says which, for a ``[physical]`` scene.

    Returns:
        A ``SimulationResult``: ``R``, ``T``, ``E_tr`` (fractions at ``t_end``),
        ``error_estimate`` (``auto``'s verified error bound estimate), ``method``, ``dt``
        and every other key of ``woodpile simulate``'s JSON; ``series`` (a DataFrame of
        t, R, T, E_tr, E); with a field, ``t``, ``sites``, ``velocity``, ``displacement``,
        ``energy`` and ``kinetic`` (float64 arrays of shape (time, site)), and
        ``resonator_sites``, ``resonator_displacement`` and ``resonator_velocity`` (shape
        (time, resonator)).

    Raises:
        SceneError: the scene is invalid (a ``ValueError``; the message names the file or
            ``<dict>``/``<string>``, the key and the reason).
        SimulationError: the run failed (blow-up, energy drift, tolerance out of reach).
        KeyboardInterrupt: Ctrl-C; the run stops within a sample interval.

    The GIL is released while the scene runs, so other Python threads go on.
    """
    bar = Progress("simulate", progress)
    try:
        raw = _core.simulate(scene, fields, field_sites, series, bar.run, units)
    finally:
        bar.close()
    result = SimulationResult(raw)
    reached = result.end_reached_at
    if reached is not None and reached < result.t_end:
        unit = " s" if result.units == "SI" else ""
        warnings.warn(
            f"the wave reached an end of the chain at t = {reached}{unit}, before t_end = "
            f"{result.t_end}{unit}: R and T include what that end sent back",
            EndReachedWarning,
            stacklevel=2,
        )
    return result


class LongRunWarning(UserWarning):
    """``simulate`` forecasts, before it starts, that ``auto`` will run long: the message
    says how long its first rung should take and how long every halving would."""


class EndReachedWarning(UserWarning):
    """A run's wave reached an end of the chain before ``t_end`` (``end_reached_at``): its
    R and T include what that end sent back."""
