"""Errors as Python users expect them: SceneError (a ValueError) with the CLI's message,
SimulationError with the reason, failed sweep points as rows, and no panic reaching Python."""

import subprocess

import pytest

import woodpile
from woodpile import _core

SCENE = {
    "chain": {"n": 40},
    "impulse": {"site": -10},
    "defect": [{"site": 0, "eps": 2.0}],
    "run": {"t_end": 40.0, "tolerance": 1e-6},
}


def test_scene_error_is_a_value_error_naming_source_key_and_reason():
    with pytest.raises(woodpile.SceneError) as caught:
        woodpile.simulate(dict(SCENE, defect=[{"site": 0, "eps": -1.0}]))
    assert isinstance(caught.value, ValueError)
    assert str(caught.value) == "<dict>: key `defect[0].eps`: must be finite and > 0, got -1"


def test_scene_errors_match_the_cli(tmp_path, woodpile_bin):
    bad = tmp_path / "bad.toml"
    bad.write_text('[chain]\nn = 40\n[[defect]]\nsite = 0\neps = 2.0\nkapa = 1.0\n')
    with pytest.raises(woodpile.SceneError) as caught:
        woodpile.simulate(bad)
    done = subprocess.run([woodpile_bin, "simulate", str(bad)], capture_output=True, text=True)
    assert done.returncode == 2
    assert str(caught.value) in done.stderr and "kapa" in str(caught.value)


@pytest.mark.parametrize(
    "scene, fragment",
    [
        ("[chain]\nn = \n", "<string>"),
        ({"chain": {"n": None}}, "key `chain.n`"),
        ({"chain": {"n": 40}, "run": {"t_end": -1.0}}, "run.t_end"),
        ({"chain": {"nn": 40}}, "nn"),
        ("no/such/scene.toml", "cannot read"),
        (42, "a scene is a dict, a TOML string or a path"),
    ],
)
def test_every_kind_of_bad_scene_is_a_scene_error(scene, fragment):
    with pytest.raises(woodpile.SceneError, match=None) as caught:
        woodpile.simulate(scene)
    assert fragment in str(caught.value)


def test_a_failed_simulation_raises_simulation_error_with_the_reason():
    scene = dict(SCENE, run={"t_end": 40.0, "method": "rk4", "dt": 2.5})
    with pytest.raises(woodpile.SimulationError) as caught:
        woodpile.simulate(scene)
    assert "<dict>: simulation failed" in str(caught.value)
    assert "non-finite" in str(caught.value) or "energy drift" in str(caught.value)


def test_failed_sweep_points_are_rows_with_their_reason():
    scene = dict(SCENE, run={"t_end": 40.0, "method": "rk4", "dt": "$h"})
    table = woodpile.sweep(scene, {"h": [0.02, 2.5]})
    good, bad = table.iloc[0], table.iloc[1]
    assert table.failure[0] is None and good.E_tr > 0
    assert bad.failure and ("non-finite" in bad.failure or "energy drift" in bad.failure)
    assert table.E_tr.isna().tolist() == [False, True]
    assert table.steps.isna().tolist() == [False, True]


def test_bad_axes_and_templates_are_scene_errors():
    template = dict(SCENE, defect=[{"site": 0, "eps": "$eps"}])
    with pytest.raises(woodpile.SceneError, match=r"key `axes.eps.to`"):
        woodpile.sweep(template, {"eps": {"from": 0.1, "to": 1.05, "step": 0.1}})
    with pytest.raises(woodpile.SceneError, match=r"placeholder `\$kappa` names no axis"):
        woodpile.sweep(dict(SCENE, defect=[{"site": 0, "eps": "$kappa"}]), {"eps": [1.0]})
    with pytest.raises(woodpile.SceneError, match=r"axes.L"):
        woodpile.sweep(template, {"eps": [1.0], "L": [1, 2]})
    with pytest.raises(woodpile.SceneError, match=r"at eps = -1"):
        woodpile.sweep(template, {"eps": [1.0, -1.0]})


@pytest.mark.skipif(
    not hasattr(_core, "_panic_in_worker"),
    reason="a release build (the wheel) has no test-only entry points",
)
def test_a_panic_in_the_core_is_an_exception_not_a_crash():
    with pytest.raises(woodpile.SimulationError, match="internal error.*calling thread"):
        _core._panic_in_worker()
    # The interpreter and the module still work.
    assert woodpile.simulate(SCENE).E_tr > 0


def _refused(scene, match):
    """Each entry point raises SceneError naming the key, and the interpreter lives on."""
    for call in (woodpile.simulate, woodpile.scene_toml):
        with pytest.raises(woodpile.SceneError, match=match):
            call(scene)


def test_values_that_contain_themselves_are_scene_errors():
    looped = [1.0]
    looped.append(looped)
    _refused({"defect": [{"site": 0, "eps": looped}]}, r"defect\[0\]\.eps.*nested more than")
    mapping = {"n": 10}
    mapping["self"] = mapping
    _refused({"chain": mapping}, "chain.self.*nested more than")
    deep = 1.0
    for _ in range(8000):
        deep = [deep]
    _refused({"run": {"t_end": deep}}, "run.t_end.*nested more than")

    class Again:
        def tolist(self):
            return Again()

    _refused({"run": {"t_end": Again()}}, "run.t_end.*nested more than")


def test_hostile_values_are_scene_errors():
    scene = {"run": {"t_end": 5.0}}

    class Grows:
        def tolist(self):
            scene["extra"] = 1
            return 5.0

    scene["run"]["tolerance"] = Grows()
    with pytest.raises(woodpile.SceneError, match="changed while it was read"):
        woodpile.simulate(scene)

    class Endless(list):
        def __iter__(self):
            while True:
                self.append(1.0)
                yield 1.0

    class Lister:
        def tolist(self):
            return Endless()

    _refused({"segment": [{"sites": [0, 3], "mass": Lister()}]}, "more than 10000000 values")
    _refused({"run": {"method": "rk\ud800"}}, "run.method.*not valid text")

    class BadIndex:
        def __index__(self):
            raise RuntimeError("no index here")

    _refused({"run": {"t_end": BadIndex()}}, "run.t_end.*__index__ failed.*no index here")


def test_kernel_files_are_refused_unread():
    """/proc and /sys files pass as regular files; one read as root (/proc/kmsg) blocks for ever,
    holding the GIL."""
    with pytest.raises(woodpile.SceneError, match="a kernel file"):
        woodpile.simulate("/proc/self/status")


def test_a_refused_run_keeps_its_finest_run_on_the_error():
    stiff = {"chain": {"n": 10}, "impulse": {"site": -5},
             "defect": [{"site": 0, "eps": 0.3, "kappa": 2.0, "p": 7}],
             "run": {"t_end": 20.0, "tolerance": 1e-13}}
    with pytest.raises(woodpile.SimulationError, match="could not verify") as caught:
        woodpile.simulate(stiff)
    kept = caught.value.result
    assert kept["verified"] is False
    assert abs(kept["R"] + kept["T"] + kept["E_tr"] - 1.0) < 1e-9
    with pytest.raises(woodpile.SimulationError) as blown:
        woodpile.simulate({"run": {"method": "rk4", "dt": 5.0, "t_end": 30.0}})
    assert blown.value.result is None
