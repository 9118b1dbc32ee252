"""Progress lines: many scenes say how many are done, one scene which run of `auto`'s ladder
it is on; `progress=False` and quick calls say nothing."""

import woodpile

SCENE = {
    "chain": {"n": 40, "boundary": "fixed"},
    "impulse": {"site": -10, "velocity": 1.0},
    "run": {"t_end": 40.0, "tolerance": 1e-6, "sample_every": 2.0},
    "defect": [{"site": 0, "eps": "$eps"}],
}


def test_a_sweep_reports_its_points(capfd):
    woodpile.sweep(SCENE, {"eps": [0.5, 1.0, 4.0]}, progress=True)
    err = capfd.readouterr().err
    assert "sweep: 3/3 points" in err and err.endswith("\n")


def test_simulate_many_reports_its_scenes(capfd):
    scenes = [dict(SCENE, defect=[{"site": 0, "eps": e}]) for e in (0.5, 2.0)]
    woodpile.simulate_many(scenes, progress=True)
    assert "simulate_many: 2/2 points" in capfd.readouterr().err


def test_simulate_reports_the_run_of_autos_ladder(capfd):
    scene = dict(SCENE, defect=[{"site": 0, "eps": 1.0}])
    r = woodpile.simulate(scene, progress=True)
    err = capfd.readouterr().err
    # `auto` verifies with a second run at half the step: the line ends on it, at t_end.
    assert "simulate: run 2 of auto's ladder, t = 40 of 40" in err
    assert r.error_estimate is not None


def test_progress_false_and_quick_calls_are_silent(capfd):
    scene = dict(SCENE, defect=[{"site": 0, "eps": 1.0}])
    woodpile.sweep(SCENE, {"eps": [0.5]}, progress=False)
    woodpile.simulate(scene, progress=False)
    woodpile.simulate(scene)  # not a terminal: the default says nothing
    assert capfd.readouterr().err == ""


def test_a_callback_that_fails_stops_the_run(monkeypatch):
    from woodpile import _progress

    def broken(self, done, total):
        raise RuntimeError("progress broke")

    monkeypatch.setattr(_progress.Progress, "points", broken)
    try:
        woodpile.sweep(SCENE, {"eps": [0.5, 1.0]}, progress=True)
    except RuntimeError as e:
        assert "progress broke" in str(e)
    else:
        raise AssertionError("the callback's error was swallowed")


def test_a_long_run_is_announced_before_it_starts():
    """`auto` forecasts its first rung before it runs: a long one warns `LongRunWarning`
    first (the run is then stopped by its progress callback, at its first poll)."""
    import pytest

    scene = {"chain": {"n": 5000}, "run": {"t_end": 5000.0, "tolerance": 1e-8}}

    def stop(*_):
        raise RuntimeError("stopped by the test")

    with pytest.warns(woodpile.LongRunWarning, match="first rung"):
        with pytest.raises(RuntimeError, match="stopped by the test"):
            woodpile._core.simulate(scene, False, None, None, stop)
