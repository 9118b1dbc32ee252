"""A scene's linear picture: ``spectrum`` and the ``SpectrumResult`` it returns."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import pandas as pd

from . import _core

Scene = Union[Dict[str, Any], str, "os.PathLike[str]"]
Frequency = Union[float, str]

#: Every table a spectrum may have, in the order ``woodpile spectrum --out`` writes them.
TABLES = ("bands", "wavenumber", "modes", "damped", "shapes", "transmission", "measured")


class SpectrumResult:
    """The linear picture of a scene about its static state, as ``woodpile spectrum`` gives it.

    Frequencies are in Hz for a ``[physical]`` scene and in cycles per unit of scaled time
    otherwise (``frequency_unit``); ``omega`` columns are the model's rad per unit time. Sites
    are paper sites. docs/spectrum.md has the equations and conventions.

    Attributes:
        summary: ``woodpile spectrum``'s JSON object, as a dict.
        frequency_unit: ``"Hz"`` or ``"1/time"``.
        pass_bands: the host cell's pass bands, ``[[lower, upper], ...]``.
        gaps: its gaps, ``[[lower, upper], ...]``.
        localised: the modes in the host's stop bands, each ``{"frequency", "peak_site",
            "localisation_length"}``.
        bands: ω_j(q) of the host cell (``band``, ``q``, ``omega``, ``frequency``).
        wavenumber: its complex wavenumber per cell (``omega``, ``frequency``, ``q``,
            ``attenuation``).
        modes: the chain's normal modes (``mode``, ``omega``, ``frequency``, ``localised``
            (1 or 0), ``peak_site``, ``participation``, ``localisation_length``).
        damped: with dashpots, the damped modes (``mode``, ``omega``, ``frequency``,
            ``decay_rate``, ``q_factor``), else None.
        shapes: the modes' site displacements (``mode``, ``site``, ``displacement``).
        transmission: ``omega``, ``frequency``, ``transmittance`` (|t|²), ``reflectance``,
            ``absorbance``, ``phase``, ``log_transmission``; None when the chain has no
            uniform lead (the reason is ``summary["transmission"]["skipped"]``).
        measured: with ``measure=True``, |t|² of the linear picture and of the scene's own
            run (``omega``, ``frequency``, ``linear``, ``measured``), else None.
    """

    summary: Dict[str, Any]
    bands: pd.DataFrame
    wavenumber: pd.DataFrame
    modes: pd.DataFrame
    damped: Optional[pd.DataFrame]
    shapes: pd.DataFrame
    transmission: Optional[pd.DataFrame]
    measured: Optional[pd.DataFrame]

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.summary = json.loads(raw["summary"])
        tables: Dict[str, Dict[str, Any]] = raw["tables"]
        for name in TABLES:
            columns = tables.get(name)
            setattr(self, name, None if columns is None else pd.DataFrame(columns))

    @property
    def frequency_unit(self) -> str:
        return str(self.summary["frequency_unit"])

    @property
    def pass_bands(self) -> List[List[float]]:
        return list(self.summary["cell"]["pass_bands"])

    @property
    def gaps(self) -> List[List[float]]:
        return list(self.summary["cell"]["gaps"])

    @property
    def localised(self) -> List[Dict[str, Any]]:
        return list(self.summary["modes"]["localised"])

    def as_dict(self) -> Dict[str, Any]:
        """``woodpile spectrum``'s JSON object."""
        return dict(self.summary)

    def __repr__(self) -> str:
        unit = self.frequency_unit
        return (
            f"SpectrumResult(gaps={self.gaps} {unit}, "
            f"{len(self.localised)} localised mode(s), "
            f"transmission={'yes' if self.transmission is not None else 'no'})"
        )


def spectrum(
    scene: Scene,
    *,
    cell: Optional[Tuple[int, int]] = None,
    frequencies: Union[None, Sequence[Any], Mapping[str, Any]] = None,
    measure: bool = False,
    probe: Optional[int] = None,
) -> SpectrumResult:
    """The linear picture of a scene about its static state (a precompression): the Bloch
    bands of its host cell, its normal modes and the transmission of its defect region.

    Args:
        scene: a dict with the keys of a scene file, a TOML string, or a path, as for
            ``simulate``. It needs a static load: ``chain.precompression``.
        cell: the host cell, paper sites ``(lo, hi)`` inclusive; by default the shortest
            period the chain repeats, else the one site of its lead.
        frequencies: the transmission's frequencies, ``(min, max, points)`` or
            ``{"min": ..., "max": ..., "points": ...}``: each end a number in the scene's
            frequency unit or, for a physical scene, text such as ``"2 kHz"``. By default 400
            frequencies across the leads' band.
        measure: also run the scene (a small impulse on the precompressed chain) and measure
            its transmission from the run (``measured``).
        probe: the paper site the run is measured at, past the defect region (``measure``
            only; by default as far past the region as the impulse is before it).

    Returns:
        A ``SpectrumResult``.

    Raises:
        SceneError: the scene is invalid or has no static load, the cell does not repeat, the
            frequencies leave the leads' band, or the run cannot resolve a measurement (the
            message names the argument or key).
        SimulationError: the measuring run failed.
        KeyboardInterrupt: Ctrl-C during the measuring run.
    """
    if not isinstance(measure, bool):
        raise TypeError(f"measure must be True or False, not {type(measure).__name__}")
    if probe is not None and not measure:
        raise TypeError("probe is read only with measure=True")
    span = _frequencies(frequencies)
    return SpectrumResult(_core.spectrum(scene, cell, span, measure, probe))


def _frequencies(
    given: Union[None, Sequence[Any], Mapping[str, Any]],
) -> Optional[Tuple[Frequency, Frequency, int]]:
    """``(min, max, points)`` from a tuple or a dict (``points`` defaults to 400)."""
    if given is None:
        return None
    if isinstance(given, Mapping):
        unknown = set(given) - {"min", "max", "points"}
        if unknown or "min" not in given or "max" not in given:
            raise TypeError("frequencies: a dict has keys min, max and optionally points")
        return (given["min"], given["max"], int(given.get("points", 400)))
    if isinstance(given, (str, bytes)) or len(given) not in (2, 3):
        raise TypeError("frequencies: (min, max) or (min, max, points)")
    points = int(given[2]) if len(given) == 3 else 400
    return (given[0], given[1], points)
