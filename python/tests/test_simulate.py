"""`woodpile.simulate`: the same numbers as the CLI, every input form, series and fields."""

import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import woodpile

from conftest import REPO, SCENES

STANDARD = {
    "chain": {"n": 60, "boundary": "fixed"},
    "impulse": {"site": -20, "velocity": 1.0},
    "defect": [{"site": 0, "eps": 3.0, "kappa": 0.7}],
    "run": {"t_end": 60.0, "tolerance": 1e-7},
}


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_bit_identical_to_the_cli_on_the_reference_scenes(path, cli):
    expected = cli(path)
    result = woodpile.simulate(path)
    for key in ("R", "T", "E_tr", "error_estimate", "E_final", "dt", "steps", "method"):
        assert getattr(result, key) == expected[key], key
    got = result.as_dict()
    assert set(got) == set(expected)
    assert {k: v for k, v in got.items() if k != "wall_s"} == {
        k: v for k, v in expected.items() if k != "wall_s"
    }


def test_a_dict_a_toml_string_and_a_path_are_the_same_scene(tmp_path):
    text = woodpile.scene_toml(STANDARD)
    path = tmp_path / "scene.toml"
    path.write_text(text)
    results = [
        woodpile.simulate(STANDARD),
        woodpile.simulate(text),
        woodpile.simulate(str(path)),
        woodpile.simulate(path),
    ]
    for r in results[1:]:
        assert (r.R, r.T, r.E_tr, r.error_estimate) == (
            results[0].R,
            results[0].T,
            results[0].E_tr,
            results[0].error_estimate,
        )


def test_numpy_values_are_accepted_in_a_dict():
    scene = dict(STANDARD, defect=[{"site": np.int64(0), "eps": np.float64(3.0), "kappa": 0.7}])
    assert woodpile.simulate(scene).E_tr == woodpile.simulate(STANDARD).E_tr


def test_series_has_every_sample_and_ends_at_the_result():
    r = woodpile.simulate(STANDARD)
    s = r.series
    assert list(s.columns) == ["t", "R", "T", "E_tr", "E"]
    assert all(s[c].dtype == np.float64 for c in s.columns)
    assert len(s) == 61 and s.t.iloc[0] == 0.0 and s.t.iloc[-1] == 60.0
    last = s.iloc[-1]
    assert (last.R, last["T"], last.E_tr) == (r.R, r.T, r.E_tr)
    np.testing.assert_allclose(s.R + s["T"] + s.E_tr, 1.0, rtol=0, atol=1e-12)
    assert s.R.iloc[0] == 1.0  # before the wave arrives, all energy is left of the region
    assert r.velocity is None and r.sites is None


def test_fields_have_the_shapes_and_dtypes_stated():
    r = woodpile.simulate(STANDARD, fields=True)
    assert r.sites.dtype == np.int64 and r.sites[0] == -60 and r.sites[-1] == 60
    assert r.velocity.shape == (61, 121) and r.velocity.dtype == np.float64
    assert r.displacement.shape == r.velocity.shape and r.displacement.dtype == np.float64
    assert r.velocity.flags["C_CONTIGUOUS"]
    # At t = 0 only the struck site moves, with the impulse's velocity.
    moving = np.nonzero(r.velocity[0])[0]
    assert list(r.sites[moving]) == [-20] and r.velocity[0, moving[0]] == 1.0
    assert not r.displacement[0].any()
    # A field does not change the numbers.
    assert r.E_tr == woodpile.simulate(STANDARD).E_tr

    part = woodpile.simulate(STANDARD, field_sites=(-5, 5))
    assert list(part.sites) == list(range(-5, 6))
    np.testing.assert_array_equal(part.velocity, r.velocity[:, 55:66])
    np.testing.assert_array_equal(part.displacement, r.displacement[:, 55:66])


def test_fields_carry_site_energies_and_the_resonators():
    r = woodpile.simulate(STANDARD, fields=True)
    assert r.energy.shape == r.kinetic.shape == r.velocity.shape
    # Over the whole chain a sample's site energies are E(t).
    np.testing.assert_allclose(r.energy.sum(axis=1), r.series.E, rtol=1e-12)
    assert (r.kinetic <= r.energy + 1e-15).all()
    assert list(r.resonator_sites) == [0]
    assert r.resonator_displacement.shape == r.resonator_velocity.shape == (len(r.t), 1)
    # The kinetic energy of the defect's site includes its resonator's (eps = 3).
    at = list(r.sites).index(0)
    v, w = r.velocity[:, at], r.resonator_velocity[:, 0]
    np.testing.assert_allclose(r.kinetic[:, at], 0.5 * v**2 + 0.5 * 3.0 * w**2, rtol=1e-12)
    frame = r.field_frame()
    on_defect = frame[frame.site == 0]
    np.testing.assert_array_equal(on_defect.resonator_velocity, w)
    assert frame[frame.site != 0].resonator_displacement.isna().all()


def test_fields_agree_with_the_cli_field_table(cli, tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(woodpile.scene_toml(STANDARD))
    field_file, series_file = tmp_path / "field.parquet", tmp_path / "series.parquet"
    cli(path, "--field", str(field_file), "--sites", "-3,7", "--series", str(series_file))
    r = woodpile.simulate(path, field_sites=(-3, 7))
    pd.testing.assert_frame_equal(pd.read_parquet(field_file), r.field_frame())
    pd.testing.assert_frame_equal(pd.read_parquet(series_file), r.series)


def test_series_agree_with_a_one_point_sweep_stage(small_pipeline):
    p = woodpile.Pipeline(small_pipeline)
    p.run("small_sweep")
    table = p.read("small_sweep")
    stage = p.manifest("small_sweep")["params"]["scene"]
    for eps in (0.5, 4.0):
        scene = dict(stage, defect=[{"site": 0, "eps": eps}])
        r = woodpile.simulate(scene)
        rows = table[table.eps == eps].reset_index(drop=True)
        for column in ("t", "R", "T", "E_tr", "E"):
            np.testing.assert_array_equal(rows[column].to_numpy(), r.series[column].to_numpy())
        assert rows.error_estimate.iloc[-1] == r.error_estimate


def test_field_sites_outside_the_chain_are_refused():
    with pytest.raises(woodpile.SceneError, match="field_sites"):
        woodpile.simulate(STANDARD, field_sites=(-61, 0))
    with pytest.raises(woodpile.SceneError, match="field_sites"):
        woodpile.simulate(STANDARD, field_sites=(3, 2))


def test_help_reads_well():
    doc = woodpile.simulate.__doc__
    assert "SceneError" in doc and "field_sites" in doc and "Returns" in doc
    assert woodpile.sweep.__doc__ and woodpile.Pipeline.__doc__
    stub = Path(woodpile.__file__).with_name("_core.pyi")
    assert stub.is_file() and Path(woodpile.__file__).with_name("py.typed").is_file()


STRUCK = {
    "chain": {"n": 40, "boundary": {"left": "free", "right": "fixed"}, "exponent": 1.5},
    "segment": [{"sites": [-40, 40], "mass": [1.0, 0.5], "contact": [1.0, 1.5]}],
    "striker": {"mass": 3.0, "velocity": 1.0, "contact": 1.2},
    "defect": [{"site": 0, "eps": 1.0}],
    "run": {"t_end": 60.0, "tolerance": 1e-7},
}


def test_a_striker_reports_its_share_in_the_result_and_the_series():
    r = woodpile.simulate(STRUCK)
    assert r.S is not None and 0.0 <= r.S <= 1.0
    assert abs(r.R + r.T + r.E_tr + r.S - 1.0) < 1e-12
    assert list(r.series.columns) == ["t", "R", "T", "E_tr", "S", "E"]
    assert r.series["S"].iloc[-1] == r.S
    # A scene without a striker has no S.
    plain = woodpile.simulate(STANDARD)
    assert plain.S is None and "S" not in plain.series.columns


def test_a_bad_chain_key_is_a_scene_error_naming_it():
    scene = dict(STRUCK, chain={"n": 40, "boundary": "fixed"})
    with pytest.raises(woodpile.SceneError, match="striker"):
        woodpile.simulate(scene)


DAMPED = dict(
    STANDARD,
    chain={"n": 60, "boundary": {"left": "fixed", "right": {"spring": 0.05, "damping": 0.5}}},
    defect=[{"site": 0, "eps": 3.0, "kappa": 0.7, "quality_factor": 20.0}],
    damping={"contact": 0.02, "law": "hertzian", "ground": 1e-3},
)


def test_a_damped_scene_keeps_its_ledger_in_the_result_and_the_series():
    r = woodpile.simulate(DAMPED)
    assert r.normalisation == "E(0)" and r.method == "rk4-contact"
    assert r.D is not None and r.D > 0.1
    assert abs(r.R + r.T + r.E_tr + r.D - 1.0) < 1e-6
    assert list(r.series.columns) == ["t", "R", "T", "E_tr", "D", "E"]
    assert r.series["D"].iloc[-1] == r.D
    assert (r.series["D"].diff().dropna() >= 0).all()
    # A Nyström method cannot take velocity-dependent forces: a SceneError naming the key.
    with pytest.raises(woodpile.SceneError, match="run.method"):
        woodpile.simulate(dict(DAMPED, run={"t_end": 60.0, "method": "verlet", "dt": 0.01}))


def test_a_sweep_over_a_damping_key_has_d_on_every_row():
    scene = dict(STANDARD, damping={"contact": "$gamma"})
    frame = woodpile.sweep(scene, {"gamma": [0.0, 0.05]})
    assert list(frame["gamma"]) == [0.0, 0.05]
    assert frame["D"].iloc[0] == 0.0 and frame["D"].iloc[1] > frame["D"].iloc[0]
    total = frame["R"] + frame["T"] + frame["E_tr"] + frame["D"]
    assert (abs(total - 1.0) < 1e-6).all()


def test_a_wave_reaching_an_end_before_t_end_warns():
    short = {"chain": {"n": 20}, "impulse": {"site": -15}, "run": {"t_end": 60.0, "tolerance": 1e-6}}
    with pytest.warns(woodpile.EndReachedWarning, match="reached an end of the chain"):
        r = woodpile.simulate(short)
    assert 10.0 < r.end_reached_at < 60.0


def test_the_end_reached_warning_of_si_outputs_is_in_seconds():
    scene = {
        "chain": {"sites": [-10, 9], "boundary": "free"},
        "impulse": {"site": -10},
        "physical": {"contact": 2.47e9, "mass": 0.866e-3, "velocity": 1.0},
        "run": {"t_end": "0.5 ms"},
    }
    with pytest.warns(woodpile.EndReachedWarning, match=r"before t_end = 0\.0005 s"):
        r = woodpile.simulate(scene, units="SI")
    assert 0.0 < r.end_reached_at < 5e-4


def test_si_outputs_of_a_physical_scene():
    path = REPO / "scenes" / "woodpile_experiment.toml"
    scaled = woodpile.simulate(path, fields=True)
    si = woodpile.simulate(path, fields=True, units="SI")
    assert (scaled.units, si.units) == ("scaled", "SI")
    mass, velocity = 0.866e-3, 1.98  # the scene's [physical] mass (kg) and velocity (m/s)
    time_s, length_m = si.physical["time_scale_s"], si.physical["length_scale_m"]
    energy_j = mass * velocity**2
    assert si.t_end == scaled.t_end * time_s
    np.testing.assert_array_equal(si.t, scaled.t * time_s)
    np.testing.assert_array_equal(si.series.E, scaled.series.E * energy_j)
    assert si.E_initial == scaled.E_initial * energy_j
    np.testing.assert_array_equal(si.displacement, scaled.displacement * length_m)
    np.testing.assert_array_equal(si.velocity, scaled.velocity * velocity)
    np.testing.assert_array_equal(si.energy, scaled.energy * energy_j)
    # The struck rod's kinetic energy at t = 0 is the impact's: M V^2 / 2 joules.
    assert si.kinetic[0].max() == pytest.approx(0.5 * mass * velocity**2, rel=1e-12)
    # Shares have no unit.
    assert (si.R, si.T, si.E_tr) == (scaled.R, scaled.T, scaled.E_tr)
    np.testing.assert_array_equal(si.series.R, scaled.series.R)


def test_si_outputs_need_a_physical_scene():
    with pytest.raises(woodpile.SceneError, match="units: SI outputs need a \\[physical\\] scene"):
        woodpile.simulate(STANDARD, units="SI")
    with pytest.raises(woodpile.SceneError, match="units: expected"):
        woodpile.simulate(STANDARD, units="metric")
    assert woodpile.simulate(STANDARD).units is None


def test_the_package_carries_the_example_scenes():
    """A user without a clone starts from an example: every one runs as a scene."""
    names = woodpile.examples()
    assert "single_eps10" in names and "woodpile_striker" in names
    text = woodpile.example("single_eps10")
    assert text.startswith("#") and "[[defect]]" in text
    r = woodpile.simulate(text.replace("t_end = 150.0", "t_end = 20.0"))
    assert 0 <= r.E_tr <= 1
    with pytest.raises(woodpile.SceneError, match="single_eps10"):
        woodpile.example("nope")


def test_simulate_many_gives_si_units_per_scene():
    """`units="SI"`: each scene's dt in s and energies in J, as `simulate` gives them."""
    text = woodpile.example("woodpile_experiment")
    scenes = [text, text.replace("velocity = 1.98", "velocity = 1.2")]
    frame = woodpile.simulate_many(scenes, progress=False, units="SI")
    for i, scene in enumerate(scenes):
        one = woodpile.simulate(scene, units="SI")
        assert frame.E_initial[i] == one.E_initial and frame.E_final[i] == one.E_final
        assert frame.R[i] == one.R
    with pytest.raises(woodpile.SceneError, match=r"scenes\[0\]: units"):
        woodpile.simulate_many([{"chain": {"n": 10}, "impulse": {"site": -5}}], progress=False, units="SI")


def test_simulate_many_returns_each_scenes_field():
    """`fields=True`: each scene's field, bit for bit the one `simulate` records."""
    scenes = [
        {"chain": {"n": 20}, "impulse": {"site": -5}, "defect": [{"site": 0, "eps": eps}], "run": {"t_end": 15.0}}
        for eps in (1.0, 2.0, 3.0)
    ]
    frame = woodpile.simulate_many(scenes, progress=False, fields=True)
    for i, scene in enumerate(scenes):
        one = woodpile.simulate(scene, fields=True)
        field = frame.field[i]
        assert np.array_equal(field["t"], one.t)
        assert np.array_equal(field["velocity"], one.velocity)
        assert np.array_equal(field["sites"], one.sites)
    assert "field" not in woodpile.simulate_many(scenes[:1], progress=False).columns
    with pytest.raises(TypeError, match="fields"):
        woodpile.simulate_many(scenes, progress=False, fields=1)


def test_simulate_many_refuses_fields_that_would_not_fit_before_running():
    big = {"chain": {"n": 2000}, "impulse": {"site": -5}, "run": {"t_end": 150.0, "sample_every": 0.05}}
    with pytest.raises(woodpile.SceneError, match="fields"):
        woodpile.simulate_many([big] * 8, progress=False, fields=True)


def test_every_output_lists_the_same_shares_in_one_order():
    """The shares are named once (`woodpile._core.SHARES`): `simulate`'s attributes and
    series, `simulate_many`'s and `sweep`'s columns and the type stubs all follow it."""
    from woodpile import _core
    from woodpile._simulate import SimulationResult

    assert _core.SHARES == ("R", "T", "E_tr", "S", "D")
    assert set(_core.SHARES) <= set(SimulationResult.__annotations__)
    stubs = (Path(woodpile.__file__).parent / "_core.pyi").read_text()
    assert "SHARES:" in stubs
    struck = {
        "chain": {"n": 20, "boundary": {"left": "free"}},
        "striker": {"mass": 2.0},
        "defect": [{"site": 0, "eps": 2.0}],
        "damping": {"ground": 0.001},
        "run": {"t_end": 10.0, "tolerance": 1e-6},
    }
    result = woodpile.simulate(struck)
    assert [c for c in result.series.columns if c in _core.SHARES] == list(_core.SHARES)
    assert result.S is not None and result.D is not None
    many = woodpile.simulate_many([struck, struck])
    assert [c for c in many.columns if c in _core.SHARES] == list(_core.SHARES)
    swept = woodpile.sweep(struck | {"defect": [{"site": 0, "eps": "$eps"}]}, {"eps": [1.0, 2.0]})
    assert [c for c in swept.columns if c in _core.SHARES] == list(_core.SHARES)
    plain = woodpile.simulate(STANDARD)
    assert [c for c in plain.series.columns if c in _core.SHARES] == ["R", "T", "E_tr"]
    assert plain.S is None and plain.D is None
