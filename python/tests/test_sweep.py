"""`woodpile.sweep`: a sweep stage's grid, one row per point (or per sample), on every core with
the GIL released, stopped by Ctrl-C."""

import os
import signal
import threading

import numpy as np
import pytest

import woodpile

TEMPLATE = {
    "chain": {"n": 40, "boundary": "fixed"},
    "impulse": {"site": -10, "velocity": 1.0},
    "defect": [{"site": 0, "through": "$L", "eps": "$eps"}],
    "run": {"t_end": 40.0, "tolerance": 1e-6, "sample_every": 2.0},
}


def test_one_row_per_point_in_grid_order_matching_simulate():
    table = woodpile.sweep(TEMPLATE, {"L": [0, 2], "eps": {"from": 0.5, "to": 1.5, "step": 0.5}})
    assert list(table.columns[:3]) == ["point", "L", "eps"]
    assert {"R", "T", "E_tr", "error_estimate", "failure", "method", "dt"} <= set(table.columns)
    assert table.point.tolist() == list(range(6))
    assert table.L.tolist() == [0, 0, 0, 2, 2, 2] and table.L.dtype == np.int64
    assert table.eps.tolist() == [0.5, 1.0, 1.5] * 2
    assert table.failure.isna().all()
    row = table.iloc[4]
    scene = dict(TEMPLATE, defect=[{"site": s, "eps": 1.0} for s in range(3)])
    r = woodpile.simulate(scene)
    assert (row.R, row["T"], row.E_tr, row.error_estimate) == (r.R, r.T, r.E_tr, r.error_estimate)
    assert row.steps == r.steps and row.method == r.method


def test_numpy_axes_and_a_toml_template():
    text = woodpile.scene_toml(dict(TEMPLATE, defect=[{"site": 0, "eps": "$eps"}]))
    a = woodpile.sweep(text, {"eps": np.array([0.5, 2.0])})
    b = woodpile.sweep(text, {"eps": [0.5, 2.0]})
    assert a.equals(b)


def test_series_rows_per_point_and_sample():
    table = woodpile.sweep(TEMPLATE, {"L": [1], "eps": [0.5, 2.0]}, series=True)
    assert len(table) == 2 * 21
    assert list(table.columns[:4]) == ["point", "L", "eps", "t"]
    first = table[table.point == 0]
    assert first.t.tolist() == [2.0 * k for k in range(21)]
    scene = dict(TEMPLATE, defect=[{"site": s, "eps": 0.5} for s in range(2)])
    series = woodpile.simulate(scene).series
    for column in ("R", "T", "E_tr", "E"):
        np.testing.assert_array_equal(first[column].to_numpy(), series[column].to_numpy())


def _long_sweep(points):
    """A sweep of `points` scenes that takes a few seconds or more on two cores."""
    scene = dict(TEMPLATE, chain={"n": 200}, run={"t_end": 300.0, "tolerance": 1e-9})
    scene["defect"] = [{"site": 0, "eps": "$eps"}]
    return scene, {"eps": {"from": 1.0, "to": float(points), "step": 1.0}}


def test_the_gil_is_released_while_a_sweep_runs():
    scene, axes = _long_sweep(40)
    started, done = threading.Event(), threading.Event()
    counted = []

    def work():
        started.set()
        woodpile.sweep(scene, axes)
        done.set()

    thread = threading.Thread(target=work)
    thread.start()
    started.wait()
    count = 0
    while not done.is_set():
        count += 1
    thread.join()
    counted.append(count)
    # Holding the GIL, the sweep would leave this loop a handful of turns at most.
    assert count > 10_000


def test_ctrl_c_raises_keyboard_interrupt_inside_a_sweep():
    scene, axes = _long_sweep(2000)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            woodpile.sweep(scene, axes)
    finally:
        timer.cancel()
    # Nothing is left running: a new call works at once.
    assert len(woodpile.sweep(TEMPLATE, {"L": [0], "eps": [1.0]})) == 1


def test_ctrl_c_raises_keyboard_interrupt_inside_one_long_simulation():
    scene = {"chain": {"n": 3000}, "impulse": {"site": -2900}, "run": {"t_end": 5000.0, "tolerance": 1e-10}}
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            woodpile.simulate(scene)
    finally:
        timer.cancel()


def test_a_sweep_over_a_striker_key_matches_simulate():
    template = {
        "chain": {"n": 40, "boundary": {"left": "free", "right": "fixed"}},
        "striker": {"mass": "$mass", "velocity": 1.0},
        "defect": [{"site": 0, "eps": 1.0}],
        "run": {"t_end": 50.0, "tolerance": 1e-6},
    }
    table = woodpile.sweep(template, {"mass": [1.0, 10.0]})
    assert table.failure.isna().all()
    heavy = woodpile.simulate(dict(template, striker={"mass": 10.0, "velocity": 1.0}))
    assert (table.iloc[1].R, table.iloc[1].E_tr) == (heavy.R, heavy.E_tr)


def _python(code, env=None, timeout=60):
    """`code` in a fresh interpreter (a fork or a bad environment must not touch this one)."""
    import os
    import subprocess
    import sys

    full_env = dict(os.environ, **(env or {}))
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout, env=full_env
    )


_SMALL = """
import woodpile
scene = {"chain": {"n": 20}, "impulse": {"site": -5}, "defect": [{"site": 0, "eps": "$eps"}],
         "run": {"t_end": 10.0, "method": "rk4", "dt": 0.05}}
def small():
    return woodpile.sweep(scene, {"eps": [0.5, 1.0, 2.0]})
"""


def test_a_sweep_in_a_process_forked_after_a_sweep_runs():
    """rayon's pool does not survive fork: the child gets a pool of its own instead of waiting
    for the parent's threads for ever."""
    code = _SMALL + """
import os
parent = small()
pid = os.fork()
if pid == 0:
    child = small()
    os._exit(0 if child.E_tr.tolist() == parent.E_tr.tolist() else 1)
_, status = os.waitpid(pid, 0)
print("child", os.waitstatus_to_exitcode(status))
"""
    done = _python(code, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "child 0" in done.stdout, done.stdout + done.stderr


def test_rayon_num_threads_is_validated():
    """A thread count rayon would choke on is a ValueError at once, and a later valid sweep in
    a fresh process runs."""
    done = _python(_SMALL + "small()\n", env={"RAYON_NUM_THREADS": "100000"}, timeout=30)
    assert done.returncode != 0 and "RAYON_NUM_THREADS" in done.stderr, done.stderr
    assert "ValueError" in done.stderr and "panic" not in done.stderr.lower(), done.stderr
    done = _python(_SMALL + "print(len(small()))\n", env={"RAYON_NUM_THREADS": "2"}, timeout=30)
    assert done.returncode == 0 and done.stdout.strip() == "3", done.stderr


def test_a_sweep_of_a_long_chain_keeps_no_state_per_point():
    """Each point keeps its numbers, not its final state or scratch (a chain's worth of floats
    each): 150 points of a 200,001-site chain fit in 250 MB more address space."""
    code = _SMALL + """
import resource
with open("/proc/self/status") as f:
    size = next(int(l.split()[1]) for l in f if l.startswith("VmSize:")) * 1024
resource.setrlimit(resource.RLIMIT_AS, (size + 250 * 2**20, resource.RLIM_INFINITY))
import numpy as np
long = dict(scene, chain={"n": 100000}, run={"t_end": 0.5, "method": "rk4", "dt": 0.05})
print(len(woodpile.sweep(long, {"eps": np.linspace(0.1, 4.0, 150)})))
"""
    done = _python(code, env={"RAYON_NUM_THREADS": "2"}, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "150", done.stderr[-2000:]


def test_a_kinetic_series_starts_with_the_impact_energy_left_of_the_region():
    scene = {"chain": {"n": 30}, "impulse": {"site": -20}, "defect": [{"site": 0, "eps": "$eps"}],
             "run": {"t_end": 20.0, "tolerance": 1e-6}}
    frame = woodpile.sweep(scene, {"eps": [1.0, 2.0]}, series="kinetic")
    first = frame[frame.t == 0.0]
    assert (first.R == 1.0).all() and (first.E_tr == 0.0).all()
    energy = woodpile.sweep(scene, {"eps": [1.0, 2.0]}, series=True)
    assert (abs(frame.R.values - energy.R.values) > 1e-3).any()
    r = woodpile.simulate(dict(scene, defect=[{"site": 0, "eps": 1.0}]), series="kinetic")
    assert r.series.R.iloc[0] == 1.0
    for bad in ("kinetik", 3):
        with pytest.raises(woodpile.SceneError, match="series"):
            woodpile.sweep(scene, {"eps": [1.0]}, series=bad)
    with pytest.raises(woodpile.SceneError, match="series"):
        woodpile.simulate(dict(scene, defect=[]), series="total")


def test_simulate_many_runs_any_list_in_order_as_simulate_does():
    base = {"chain": {"n": 40}, "impulse": {"site": -20}, "run": {"t_end": 30.0, "tolerance": 1e-6}}
    scenes = [dict(base, defect=[{"site": 0, "eps": eps}]) for eps in (3.0, 0.5, 1.5)]
    scenes.append(woodpile.scene_toml(scenes[0]))
    scenes.append(dict(base, defect=[{"site": 0, "eps": 1.0}], run={"t_end": 30.0, "method": "rk4", "dt": 5.0}))
    frame = woodpile.simulate_many(scenes)
    assert list(frame.point) == [0, 1, 2, 3, 4]
    for i in range(3):
        one = woodpile.simulate(scenes[i])
        assert frame.R[i] == one.R and frame.E_tr[i] == one.E_tr and frame.method[i] == one.method
    assert frame.E_tr[3] == frame.E_tr[0]
    assert frame.failure[4] is not None and np.isnan(frame.E_tr[4])
    with pytest.raises(woodpile.SceneError, match=r"scenes\[1\]"):
        woodpile.simulate_many([scenes[0], dict(base, defect=[{"site": 0, "eps": -1.0}])])


def test_neighbouring_points_in_lanes_match_simulate():
    """Groups of four neighbouring points run their first pair together in SIMD lanes, by
    `rkn6-contact` (heavy resonators) or `erkn6-contact` (light ones); every point must equal
    its own `simulate` to the bit, in `sweep` and in `simulate_many` alike."""
    template = {
        "chain": {"n": 60, "boundary": "fixed"},
        "impulse": {"site": -15, "velocity": 1.0},
        "defect": [{"site": 0, "eps": "$eps"}, {"site": 10, "eps": 7.0}],
        "run": {"t_end": 60.0, "tolerance": 1e-5},
    }
    values = [3.0, 4.0, 5.0, 6.0, 0.3, 0.35, 0.4, 0.45, 9.0]
    table = woodpile.sweep(template, {"eps": values})
    scenes = [
        dict(template, defect=[{"site": 0, "eps": eps}, {"site": 10, "eps": 7.0}])
        for eps in values
    ]
    many = woodpile.simulate_many(scenes)
    for k, scene in enumerate(scenes):
        alone = woodpile.simulate(scene)
        row = table.iloc[k]
        assert (row["R"], row["T"], row["E_tr"]) == (alone.R, alone.T, alone.E_tr)
        assert (many["R"][k], many["T"][k], many["E_tr"][k]) == (alone.R, alone.T, alone.E_tr)


def test_a_physical_sweep_in_si_is_the_scaled_one_times_each_points_scales():
    """``units="SI"``: t, dt and end_reached_at in s and E in J, each point by its own scales
    (the impact velocity is an axis here, so they differ), the shares as they were."""
    scene = {
        "chain": {"sites": [-10, 9], "boundary": "free"},
        "impulse": {"site": -10},
        "physical": {"contact": 2.47e9, "mass": 0.866e-3, "velocity": "$V"},
        "run": {"t_end": 30.0, "tolerance": 1e-6},
    }
    axes = {"V": [0.5, 2.0]}
    scaled = woodpile.sweep(scene, axes)
    si = woodpile.sweep(scene, axes, units="SI")
    for (_, a), (_, b) in zip(scaled.iterrows(), si.iterrows()):
        one = woodpile.simulate({**scene, "physical": {**scene["physical"], "velocity": a["V"]}})
        time_s = one.physical["time_scale_s"]
        assert b["t"] == pytest.approx(a["t"] * time_s, rel=1e-12)
        assert b["R"] == a["R"] and b["T"] == a["T"]
        energy_j = 0.866e-3 * a["V"] ** 2
        assert b["E"] == pytest.approx(a["E"] * energy_j, rel=1e-12)
    with pytest.raises(woodpile.SceneError, match="units"):
        woodpile.sweep({"defect": [{"site": 0, "eps": "$eps"}]}, {"eps": [1.0]}, units="SI")
