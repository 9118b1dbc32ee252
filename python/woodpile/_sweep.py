"""Many scenes at once: a grid (``sweep``) or any list (``simulate_many``)."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from typing import Any, Dict, Iterator, Mapping, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import _core
from ._progress import Progress
from ._simulate import Scene

Axis = Union[Sequence[float], Sequence[int], "np.ndarray", Mapping[str, float]]


def sweep(
    scene: Scene,
    axes: Mapping[str, Axis],
    *,
    series: Union[bool, str] = False,
    cache: Optional[Union[str, "os.PathLike[str]"]] = None,
    progress: Optional[bool] = None,
    units: str = "scaled",
) -> pd.DataFrame:
    """Simulate every point of a grid of scenes, on all cores, and return one table.

    The grid is a sweep stage's: ``scene`` holds ``"$name"`` placeholders (and may repeat a
    defect over sites with ``"through": "$L"``), and each axis is a list of numbers (or a
    NumPy array) or a range, ``{"from": 0.1, "to": 10.0, "step": 0.1}`` or ``{"from": 0.1,
    "to": 100.0, "count": 31, "log": True}``, whose values are rounded to 12 significant
    digits. Axes vary in name order, the last fastest. The points are simulated by the same
    code as a sweep stage's, so the table has the stage's columns and, with ``series``, its
    rows, bit for bit.

    Args:
        scene: the scene template: a dict, a TOML string or a path.
        axes: axis name -> values.
        series: one row per point and sample instead of one row per point at ``t_end``:
            ``True`` or ``"energy"`` for shares of the total energy, ``"kinetic"`` for kinetic
            energy over the impact energy (as a sweep stage's ``series = "kinetic"``; E is then
            the kinetic share).
        cache: a folder of cached points (a pipeline's ``results/points`` or any folder of
            your own): points found there are read, not simulated, and every point simulated
            is stored there the moment it finishes, so a sweep stopped by Ctrl-C or a crash
            resumes with only the missing points to run.
        progress: a line on stderr with the points done, the rate and the time left:
            ``True`` always, ``False`` never, ``None`` (the default) in a terminal or a
            notebook once the sweep has run two seconds.
        units: ``"scaled"`` (the model's units, as a sweep stage writes them) or ``"SI"``
            for a grid of ``[physical]`` scenes: ``t``, ``dt`` and ``end_reached_at`` in s and
            ``E`` in J (a kinetic series' ``E`` stays a share), each point by its own scales.

    Returns:
        A DataFrame with a sweep stage's columns: ``point``, the axes (integer axes as
        integers), ``t``, ``R``, ``T``, ``E_tr`` (``S`` with a striker, ``D`` when the scene
        declares damping), ``E``, ``method``, ``dt``, ``steps``, ``error_estimate``,
        ``energy_drift``, ``failure`` and ``scene_key`` (the point's cache key). A point
        that failed is one row with NaN fractions and its reason in ``failure`` (None for the
        others).

    Raises:
        SceneError: the template or the axes are invalid (checked on the grid's first and
            last points before anything runs, and on every point before it runs).
        KeyboardInterrupt: Ctrl-C stops the sweep within about a second. The exception's
            ``partial`` is the table of the points finished so far (with ``cache``, they are
            also on disk).

    The GIL is released while the sweep runs.
    """
    path = None if cache is None else os.fspath(cache)
    bar = Progress("sweep", progress)
    try:
        return _frame(_core.sweep(scene, dict(axes), series, path, bar.points, units))
    except KeyboardInterrupt as stopped:
        partial = getattr(stopped, "partial", None)
        if isinstance(partial, dict):
            with _interrupts_held():
                stopped.partial = _frame(partial)
        raise
    finally:
        bar.close()


def simulate_many(
    scenes: Sequence[Scene],
    *,
    progress: Optional[bool] = None,
    units: str = "scaled",
    fields: bool = False,
) -> pd.DataFrame:
    """Simulate any list of scenes on all cores, with the GIL released: the points an
    optimiser picks rather than a grid (SciPy's ``differential_evolution`` with
    ``vectorized=True`` hands over a population at once).

    Args:
        scenes: dicts with the keys of a scene file, TOML strings or paths, in any mix.
        progress: a progress line on stderr, as ``sweep``'s.
        units: ``"scaled"`` (the default) or ``"SI"``: ``dt`` in s and ``E_initial``,
            ``E_final`` in J, each scene with its own scales (every scene must then have a
            ``[physical]`` table). The shares have no unit.
        fields: also record every site's field at every sample of each scene, for fits in
            your own code: a column ``field`` holds, per scene, a dict with ``t``, ``sites``,
            ``velocity``, ``displacement``, ``energy``, ``kinetic`` (float64 arrays of shape
            (time, site)) and the resonators' ``resonator_sites``, ``resonator_displacement``
            and ``resonator_velocity``, as ``simulate(..., fields=True)`` has them (None for a
            scene whose run failed). In SI with ``units="SI"``.

    Returns:
        A DataFrame with one row per scene, in input order: ``point`` (the scene's index),
        ``R``, ``T``, ``E_tr`` (``S`` with a striker, ``D`` with damping), ``E_initial``,
        ``E_final``, ``error_estimate``, ``dt``, ``steps``, ``rhs_evals`` (the reported run's,
        as ``simulate``'s), ``total_rhs_evals`` (every run ``auto`` made), ``method`` and
        ``failure``. A
        scene whose simulation failed is a row with NaN fractions and its reason in
        ``failure``; each number is what ``simulate`` gives for that scene, bit for bit.

    Raises:
        SceneError: a scene is invalid, or has no scales for ``units="SI"`` (the message names
            its index, ``scenes[i]``), or the fields asked for would not fit in memory.
        TypeError: ``scenes`` is one scene (a string, path or dict) rather than a list, or
            ``progress`` is not True, False or None.
        KeyboardInterrupt: Ctrl-C stops the runs within about a second.
    """
    if isinstance(scenes, (str, bytes, os.PathLike, Mapping)):
        raise TypeError(
            "simulate_many: scenes must be a list of scenes (dicts, TOML strings or paths), "
            f"not one {type(scenes).__name__}; for one scene, pass [scene] or call simulate"
        )
    if not isinstance(fields, bool):
        raise TypeError(f"fields must be True or False, not {type(fields).__name__}")
    bar = Progress("simulate_many", progress)
    try:
        raw = _core.simulate_many(list(scenes), bar.points, units, fields)
    finally:
        bar.close()
    recorded = raw.pop("fields", None)
    frame = _frame(raw)
    if recorded is not None:
        frame["field"] = pd.Series(recorded, dtype=object)
    return frame


@contextlib.contextmanager
def _interrupts_held() -> Iterator[None]:
    """Ctrl-C pressed again while the finished points become a table is held back, so that
    a second press does not lose them (the interrupt under way is raised right after). Only
    the main thread receives signals; elsewhere this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, lambda *_: None)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


#: Integer columns that are null where a point failed: pandas' nullable integers.
_NULLABLE = ("steps", "rhs_evals", "total_rhs_evals")


def _frame(raw: Dict[str, Any]) -> pd.DataFrame:
    """The native table (``names`` in order, each a column, ``masks`` the nulls of integer
    columns) as a DataFrame: nullable integer columns masked, text columns as objects."""
    masks = raw["masks"]
    columns: Dict[str, Any] = {}
    for name in raw["names"]:
        values = raw[name]
        if name in masks and name in _NULLABLE:
            values = pd.arrays.IntegerArray(np.asarray(values, dtype=np.int64), masks[name])
        elif isinstance(values, list):
            values = pd.Series(values, dtype=object)
        columns[name] = values
    return pd.DataFrame(columns)
