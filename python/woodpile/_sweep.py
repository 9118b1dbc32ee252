"""Many scenes at once: a grid (``sweep``) or any list (``simulate_many``)."""

from __future__ import annotations

from typing import Any, Dict, Mapping, Sequence, Union

import numpy as np
import pandas as pd

from . import _core
from ._simulate import Scene

Axis = Union[Sequence[float], Sequence[int], "np.ndarray", Mapping[str, float]]


def sweep(
    scene: Scene, axes: Mapping[str, Axis], *, series: Union[bool, str] = False
) -> pd.DataFrame:
    """Simulate every point of a grid of scenes, on all cores, and return one table.

    The grid is a sweep stage's: ``scene`` holds ``"$name"`` placeholders (and may repeat a
    defect over sites with ``"through": "$L"``), and each axis is a list of numbers (or a
    NumPy array) or a range, ``{"from": 0.1, "to": 10.0, "step": 0.1}`` or ``{"from": 0.1,
    "to": 100.0, "count": 31, "log": True}``, whose values are rounded to 12 significant
    digits. Axes vary in name order, the last fastest.

    Args:
        scene: the scene template: a dict, a TOML string or a path.
        axes: axis name -> values.
        series: one row per point and sample (columns t, R, T, E_tr, E) instead of one row
            per point with the fractions at ``t_end``: ``True`` or ``"energy"`` for shares of
            the total energy, ``"kinetic"`` for kinetic energy over the impact energy (as a
            sweep stage's ``series = "kinetic"``; E is then the kinetic share).

    Returns:
        A DataFrame: ``point``, the axes, then ``R``, ``T``, ``E_tr`` (or, with
        ``series``, ``t``, ``R``, ``T``, ``E_tr``, ``E``; ``D`` after ``E_tr`` when the scene
        declares damping), ``error_estimate``, ``dt``,
        ``steps``, ``rhs_evals``, ``method`` and ``failure``. A point that failed is a row
        with NaN fractions and its reason in ``failure`` (None for the others).

    Raises:
        SceneError: the template or the axes are invalid (checked on the grid's first and
            last points before anything runs).
        KeyboardInterrupt: Ctrl-C stops the sweep within about a second.

    The GIL is released while the sweep runs.
    """
    return _frame(_core.sweep(scene, dict(axes), series))


def simulate_many(scenes: Sequence[Scene]) -> pd.DataFrame:
    """Simulate any list of scenes on all cores, with the GIL released: the points an
    optimiser picks rather than a grid (SciPy's ``differential_evolution`` with
    ``vectorized=True`` hands over a population at once).

    Args:
        scenes: dicts with the keys of a scene file, TOML strings or paths, in any mix.

    Returns:
        A DataFrame with one row per scene, in input order: ``point`` (the scene's index),
        ``R``, ``T``, ``E_tr`` (``D`` with damping), ``E_initial``, ``E_final``,
        ``error_estimate``, ``dt``, ``steps``, ``rhs_evals``, ``method`` and ``failure``. A
        scene whose simulation failed is a row with NaN fractions and its reason in
        ``failure``; each number is what ``simulate`` gives for that scene, bit for bit.

    Raises:
        SceneError: a scene is invalid (the message names its index, ``scenes[i]``).
        KeyboardInterrupt: Ctrl-C stops the runs within about a second.
    """
    return _frame(_core.simulate_many(list(scenes)))


def _frame(raw: Dict[str, Any]) -> pd.DataFrame:
    """The native table (``names`` in order, each a column) as a DataFrame: integer columns
    of failed points masked, text columns as objects."""
    valid = np.asarray(raw["valid"], dtype=bool)
    columns: Dict[str, Any] = {}
    for name in raw["names"]:
        values = raw[name]
        if name in ("steps", "rhs_evals"):
            values = pd.arrays.IntegerArray(np.asarray(values, dtype=np.int64), ~valid)
        elif name in ("method", "failure"):
            values = pd.Series(values, dtype=object)
        columns[name] = values
    return pd.DataFrame(columns)
