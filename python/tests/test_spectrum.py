"""`woodpile.spectrum`: a scene's linear picture against closed forms, its units, its
refusals, and its transmission measured from the scene's own nonlinear run."""

import math

import numpy as np
import pytest

import woodpile

# A precompressed chain (F0 = 1, so K = 3/2) with one linear resonator (m2 = 0.5, k2 = 0.3).
ONE_DEFECT = {
    "chain": {"n": 30, "precompression": 1.0},
    "defect": [{"site": 0, "eps": 0.5, "kappa": 0.3}],
}

QUARTZ = {"youngs_modulus": 72e9, "poisson_ratio": 0.17, "density": 2200.0}


def test_a_resonator_defect_transmits_as_the_closed_form_says():
    omega0 = math.sqrt(0.3 / 0.5)
    f0 = omega0 / (2 * math.pi)
    r = woodpile.spectrum(ONE_DEFECT, frequencies=(0.5 * f0, 1.5 * f0, 101))
    assert r.frequency_unit == "1/time"
    t = r.transmission
    q = np.arccos(1 - t.omega**2 / (2 * 1.5))
    dm = 0.5 * omega0**2 / (omega0**2 - t.omega**2)
    closed = 1 / (1 + (dm * t.omega**2 / (2 * 1.5 * np.sin(q))) ** 2)
    assert np.max(np.abs(t.transmittance - closed)) < 1e-10
    assert np.max(np.abs(t.transmittance + t.reflectance - 1)) < 1e-10
    assert t.transmittance[50] < 1e-20
    assert r.summary["transmission"]["region"] == [0, 0]


def test_a_chain_of_forty_mm_rods_has_its_gap_in_hz():
    defects = [{"site": s, "rod": {"length": 0.040}} for s in range(-3, 4)]
    scene = {
        "chain": {"sites": [-3, 3], "precompression": 1.0},
        "physical": {"material": QUARTZ, "rod": {"length": 0.040, "diameter": 0.005}, "velocity": 1e-6},
        "impulse": {"site": -3},
        "defect": defects,
    }
    r = woodpile.spectrum(scene)
    assert r.frequency_unit == "Hz"
    [(lower, upper)] = r.gaps
    # The gap's edges are the bands' values at the zone edge and centre.
    bands = r.bands
    assert lower == pytest.approx(bands[(bands.band == 0)].frequency.max(), rel=1e-12)
    assert upper == pytest.approx(bands[(bands.band == 1)].frequency.min(), rel=1e-12)
    assert 8e3 < lower < upper < 16e3
    assert r.transmission is None and "resonator" in r.summary["transmission"]["skipped"]
    inside = r.wavenumber[(r.wavenumber.frequency > lower) & (r.wavenumber.frequency < upper)]
    assert (inside.attenuation > 0).all()


@pytest.mark.parametrize(
    "scene, arguments, match",
    [
        ({"chain": {"n": 30}}, {}, "sonic vacuum"),
        (ONE_DEFECT, {"cell": (-30, -29)}, "cell: the cell does not repeat"),
        (ONE_DEFECT, {"frequencies": (0.1, 1.0, 10)}, "frequencies: .*pass band"),
        (ONE_DEFECT, {"frequencies": ("1 kHz", 0.2, 10)}, r"frequencies: .*\[physical\]"),
    ],
)
def test_what_cannot_be_computed_is_refused_naming_the_argument(scene, arguments, match):
    with pytest.raises(woodpile.SceneError, match=match):
        woodpile.spectrum(scene, **arguments)


def test_wrong_argument_types_are_type_errors():
    with pytest.raises(TypeError, match="measure"):
        woodpile.spectrum(ONE_DEFECT, measure=1)
    with pytest.raises(TypeError, match="probe"):
        woodpile.spectrum(ONE_DEFECT, probe=5)
    with pytest.raises(TypeError, match="frequencies"):
        woodpile.spectrum(ONE_DEFECT, frequencies="1 kHz")


def test_the_run_of_a_small_impulse_measures_the_linear_transmission():
    scene = {
        "chain": {"n": 400, "precompression": 1.0},
        "defect": [{"site": 0, "eps": 0.5, "kappa": 0.3}],
        "impulse": {"site": -30, "velocity": 1e-4},
        "run": {"t_end": 600.0, "sample_every": 0.1, "method": "rkn6-contact", "dt": 0.02},
    }
    r = woodpile.spectrum(scene, measure=True)
    m = r.measured
    assert len(m) > 300
    assert np.max(np.abs(np.sqrt(m.linear) - np.sqrt(m.measured))) < 1e-3
    assert r.summary["measured"]["amplitude"] < 1e-3

