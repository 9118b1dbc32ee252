"""`woodpile.sweep` runs a sweep stage's points: the stage's table bit for bit, its point cache
shared (``cache=``), and the finished points kept when Ctrl-C stops it."""

import os
import signal
import threading
import time

import numpy as np
import pandas as pd
import pytest

import woodpile

from conftest import SWEEP_STAGE

SCENE = {
    "chain": {"n": 40, "boundary": "fixed"},
    "impulse": {"site": -10, "velocity": 1.0},
    "run": {"t_end": 40.0, "method": "auto", "tolerance": 1e-6, "sample_every": 2.0},
    "defect": [{"site": 0, "eps": "$eps"}],
}
AXES = {"eps": [0.5, 4.0]}


def _points(folder):
    return sorted(folder.rglob("*.wppt"))


def test_a_sweep_is_the_sweep_stages_table_bit_for_bit(small_pipeline):
    assert 'eps = [0.5, 4.0]' in SWEEP_STAGE
    p = woodpile.Pipeline(small_pipeline)
    p.run("small_sweep")
    stage = p.read("small_sweep")
    table = woodpile.sweep(SCENE, AXES, series=True)
    assert list(table.columns) == list(stage.columns)
    pd.testing.assert_frame_equal(table, stage, check_dtype=False, check_exact=True)
    # From the stage's own point cache, nothing is simulated again.
    points = small_pipeline / "results" / "points"
    before = {f: f.stat().st_mtime_ns for f in _points(points)}
    cached = woodpile.sweep(SCENE, AXES, series=True, cache=points)
    pd.testing.assert_frame_equal(cached, table, check_exact=True)
    assert {f: f.stat().st_mtime_ns for f in _points(points)} == before


def test_without_series_each_point_is_its_last_sample():
    every = woodpile.sweep(SCENE, AXES, series=True)
    last = woodpile.sweep(SCENE, AXES)
    assert list(last.columns) == list(every.columns)
    expected = every.groupby("point").tail(1).reset_index(drop=True)
    pd.testing.assert_frame_equal(last, expected, check_exact=True)
    assert last.t.tolist() == [40.0, 40.0]


def test_a_cached_sweep_runs_only_the_missing_points(tmp_path):
    first = woodpile.sweep(SCENE, AXES, cache=tmp_path)
    files = _points(tmp_path)
    assert len(files) == 2
    assert sorted(f.stem for f in files) == sorted(first.scene_key)
    kept, lost = files
    kept_at = kept.stat().st_mtime_ns
    lost.unlink()
    again = woodpile.sweep(SCENE, AXES, cache=tmp_path)
    pd.testing.assert_frame_equal(again, first, check_exact=True)
    assert lost.is_file() and kept.stat().st_mtime_ns == kept_at


def test_a_cache_that_is_a_link_is_refused(tmp_path):
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    with pytest.raises(ValueError, match="cache"):
        woodpile.sweep(SCENE, AXES, cache=tmp_path / "link")


def test_ctrl_c_keeps_the_finished_points(tmp_path):
    scene = dict(SCENE, chain={"n": 200}, run={"t_end": 300.0, "tolerance": 1e-9})
    axes = {"eps": {"from": 1.0, "to": 400.0, "step": 1.0}}
    stop = threading.Event()

    def interrupt_after_three_points():
        while not stop.is_set() and len(_points(tmp_path)) < 3:
            time.sleep(0.05)
        if not stop.is_set():
            os.kill(os.getpid(), signal.SIGINT)

    watcher = threading.Thread(target=interrupt_after_three_points)
    watcher.start()
    try:
        with pytest.raises(KeyboardInterrupt) as stopped:
            woodpile.sweep(scene, axes, cache=tmp_path)
    finally:
        stop.set()
        watcher.join()
    partial = stopped.value.partial
    assert isinstance(partial, pd.DataFrame)
    assert 3 <= len(partial) < 400
    assert partial.failure.isna().all() and np.isfinite(partial.E_tr).all()
    # Every kept point is on disk: a re-run of the same grid starts from them.
    on_disk = {f.stem for f in _points(tmp_path)}
    assert set(partial.scene_key) <= on_disk
