"""woodpile: granular chains with internal resonator defects, from Python.

Simulate one scene (``simulate``) or a grid of them on every core (``sweep``), compute its
linear picture (``spectrum``: bands, modes, transmission), fit a scene to a measured
trace (``calibrate``), and drive the
figure pipeline of a woodpile project (``Pipeline``; ``new_study`` makes one). Scenes are dicts with the keys of a
scene file, TOML strings, or paths; the format is docs/scene.md of the woodpile repository.

>>> import woodpile
>>> woodpile.examples()                 # the example scenes the package carries
>>> r = woodpile.simulate(woodpile.example("single_eps10"))
>>> r = woodpile.simulate({"defect": [{"site": 0, "eps": 10.0}], "run": {"t_end": 150.0}})
>>> r.E_tr, r.error_estimate          # verified to run.tolerance (default 1e-8)
>>> r.series.plot(x="t", y=["R", "T", "E_tr"])
>>> woodpile.sweep({"defect": [{"site": 0, "eps": "$eps"}]}, {"eps": [0.5, 1, 2, 5]})
"""

from ._calibrate import CalibrationResult, calibrate
from ._core import SceneError, SimulationError, __version__, example, examples, scene_toml
from ._pipeline import Pipeline, new_study
from ._simulate import EndReachedWarning, LongRunWarning, SimulationResult, simulate
from ._spectrum import SpectrumResult, spectrum
from ._sweep import simulate_many, sweep

__all__ = [
    "CalibrationResult",
    "EndReachedWarning",
    "LongRunWarning",
    "Pipeline",
    "SceneError",
    "SimulationError",
    "SimulationResult",
    "SpectrumResult",
    "__version__",
    "calibrate",
    "example",
    "examples",
    "new_study",
    "scene_toml",
    "simulate",
    "simulate_many",
    "spectrum",
    "sweep",
]
