"""Type stubs of the native module (``woodpile._core``); use the ``woodpile`` package's API."""

import os
from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Union

Scene = Union[Dict[str, Any], str, "os.PathLike[str]"]

__version__: str
#: The energy shares in the order every table lists them: ("R", "T", "E_tr", "S", "D").
SHARES: Tuple[str, str, str, str, str]

class SceneError(ValueError): ...
class SimulationError(RuntimeError): ...

def simulate(
    scene: Scene,
    fields: bool = False,
    field_sites: Optional[Tuple[int, int]] = None,
    series: str = "energy",
    progress: Optional[Callable[[int, float, float], None]] = None,
    units: str = "scaled",
) -> Dict[str, Any]: ...
def sweep(
    scene: Scene,
    axes: Mapping[str, Any],
    series: Union[bool, str] = False,
    cache: Optional[str] = None,
    progress: Optional[Callable[[int, int], None]] = None,
    units: str = "scaled",
) -> Dict[str, Any]: ...
def simulate_many(
    scenes: Sequence[Scene],
    progress: Optional[Callable[[int, int], None]] = None,
    units: str = "scaled",
    fields: bool = False,
) -> Dict[str, Any]: ...
def spectrum(
    scene: Scene,
    cell: Optional[Tuple[int, int]] = None,
    frequencies: Optional[Tuple[Union[float, str], Union[float, str], int]] = None,
    measure: bool = False,
    probe: Optional[int] = None,
) -> Dict[str, Any]: ...
def calibrate(
    scene: Scene,
    t: Sequence[float],
    rod: Sequence[int],
    velocity: Sequence[float],
    sigma: Optional[Sequence[float]],
    parameters: Sequence[Tuple[str, float, float, Optional[float]]],
) -> Dict[str, Any]: ...
def scene_toml(scene: Scene) -> str: ...
def examples() -> list[str]:
    """The names of the example scenes the package carries."""
def example(name: str) -> str:
    """The TOML text of an example scene: pass it to ``simulate``, or save and edit it."""

def table_integrity(data: bytes) -> str:
    """Whether a table's bytes match their manifest's seal: "intact", "damaged" or "unchecked"."""
