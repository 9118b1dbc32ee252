//! `simulate`: one scene, its JSON report (the CLI's), its fraction series and optionally its
//! field, as NumPy arrays that take over the simulator's vectors (no copy per sample).

use std::time::{Duration, Instant};

use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use woodpile_scene::report::{cost_note, simulate_report, unverified_report};
use woodpile_scene::units_out::{SiFactors, Units};
use woodpile_scene::Scene;
use woodpile_sim::observe::{FractionSeries, SiteField};
use woodpile_sim::simulation::{simulate as run, Outcome, Scenario};
use woodpile_sim::{ShareSet, SimError};

use crate::interrupt::{on_this_thread, Clock, Watch};
use crate::scene_input::{label_text, Source};
use crate::series;
use crate::{SceneError, SimulationError};
use woodpile_points::Shares;

/// _simulate(scene, fields=False, field_sites=None, series=None) -> dict
/// --
///
/// The native call behind `woodpile.simulate`: a dict with `report` (the CLI's JSON text),
/// `series` (t, R, T, E_tr, E arrays, S with a striker, D with damping) and, when a field is asked for, `t`, `sites`,
/// `velocity` and `displacement`.
#[pyfunction]
#[pyo3(signature = (scene, fields = false, field_sites = None, series = None, progress = None, units = "scaled"))]
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    fields: bool,
    field_sites: Option<(i64, i64)>,
    series: Option<&Bound<'py, PyAny>>,
    progress: Option<Py<PyAny>>,
    units: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = match series {
        Some(value) => series::parse(value, false)?.unwrap_or(Shares::Energy),
        None => Shares::Energy,
    };
    let source = Source::of(scene)?;
    let label = label_text(&source.label());
    let scene = source.scene()?;
    let si = Units::parse(units)
        .and_then(|units| SiFactors::of(&scene, units))
        .map_err(|reason| SceneError::new_err(format!("{label}: units: {reason}")))?;
    let recorder = kind
        .recorder(&scene.scenario)
        .map_err(|reason| SceneError::new_err(format!("{label}: series: {reason}")))?;
    let sites = match field_sites {
        Some(range) => Some(internal_sites(&scene, range)?),
        None if fields => Some((0, scene.scenario.model.n_sites() - 1)),
        None => None,
    };
    let s = &scene.scenario;
    if let Some((first, last)) = sites {
        woodpile_sim::simulation::check_field_size(s, last - first + 1)
            .map_err(|reason| SceneError::new_err(format!("{label}: field: {reason}")))?;
    }
    if let Some(note) = cost_note(&scene) {
        warn_long_run(py, &format!("{label}: {note}"))?;
    }
    // `progress(run, t, t_end)`: the run of `auto`'s ladder under way and its last sample.
    let clock = Clock::default();
    let t_end = s.t_end;
    let poll = |py: Python<'_>| -> PyResult<()> {
        let Some(callback) = &progress else {
            return Ok(());
        };
        let (run, t) = clock.read();
        callback.call1(py, (run, t, t_end)).map(|_| ())
    };
    let (outcome, wall_s, series, field) = on_this_thread(py, &poll, |stop| {
        run_recorded(s, recorder, sites, stop, &clock)
    })?;
    let outcome = outcome.map_err(|e| failure(py, &scene, &label, e))?;
    let mut report = simulate_report(&scene, &outcome, wall_s.as_secs_f64());
    let (mut series, mut field) = (series, field);
    if let Some(si) = si {
        si.report(&mut report);
        si.series(&mut series, kind == Shares::Kinetic);
        if let Some(field) = field.as_mut() {
            si.field(field);
        }
    }
    let out = PyDict::new(py);
    out.set_item("report", report.to_string())?;
    out.set_item("series", series_columns(py, &scene, series)?)?;
    if let Some(field) = field {
        add_field(py, &out, &scene, field)?;
    }
    Ok(out)
}

/// A run of `s` recording `series` and, for `sites`, a field: its outcome, wall time, series
/// and field. `stop` ends it early; `clock` says where it is.
fn run_recorded(
    s: &Scenario,
    series: FractionSeries,
    sites: Option<(usize, usize)>,
    stop: &dyn Fn() -> bool,
    clock: &Clock,
) -> (
    Result<Outcome, SimError>,
    Duration,
    FractionSeries,
    Option<SiteField>,
) {
    let started = Instant::now();
    match sites {
        Some((first, last)) => {
            let field = SiteField::new(&s.model, first, last);
            let mut watched = Watch {
                inner: (series, field),
                stop,
                clock: Some(clock),
            };
            let outcome = run(s, &mut watched);
            let (series, field) = watched.inner;
            (outcome, started.elapsed(), series, Some(field))
        }
        None => {
            let mut watched = Watch {
                inner: series,
                stop,
                clock: Some(clock),
            };
            let outcome = run(s, &mut watched);
            (outcome, started.elapsed(), watched.inner, None)
        }
    }
}

/// Warns `woodpile.LongRunWarning` with `message`, from the caller's line.
fn warn_long_run(py: Python<'_>, message: &str) -> PyResult<()> {
    let category = py.import("woodpile._simulate")?.getattr("LongRunWarning")?;
    let message = std::ffi::CString::new(message)
        .map_err(|e| SimulationError::new_err(format!("warning text: {e}")))?;
    PyErr::warn(py, &category, &message, 2)
}

/// The recorded series as arrays: t, R, T, E_tr, S (with a striker), D (with damping), E.
fn series_columns<'py>(
    py: Python<'py>,
    scene: &Scene,
    mut series: FractionSeries,
) -> PyResult<Bound<'py, PyDict>> {
    let columns = PyDict::new(py);
    columns.set_item("t", std::mem::take(&mut series.t).into_pyarray(py))?;
    let scenario = &scene.scenario;
    for share in ShareSet::of(&scenario.model, &scenario.region).iter() {
        columns.set_item(
            share.name(),
            share.take_series(&mut series).into_pyarray(py),
        )?;
    }
    columns.set_item("E", series.energy.into_pyarray(py))?;
    Ok(columns)
}

/// Paper sites `(lo, hi)` as internal indices, or a `SceneError` naming the chain's range.
fn internal_sites(scene: &Scene, (lo, hi): (i64, i64)) -> PyResult<(usize, usize)> {
    scene
        .site_range(lo, hi)
        .map_err(|reason| SceneError::new_err(format!("field_sites ({lo}, {hi}): {reason}")))
}

pub(crate) fn add_field(
    py: Python<'_>,
    out: &Bound<'_, PyDict>,
    scene: &Scene,
    field: SiteField,
) -> PyResult<()> {
    let width = field.width();
    let first = scene.first_site + *field.sites().start() as i64;
    let rows = field.t.len();
    let resonators = scene.scenario.model.resonators();
    let grid = |values: Vec<f64>, width: usize| {
        Array2::from_shape_vec((rows, width), values)
            .map_err(|e| SimulationError::new_err(format!("field shape: {e}")))
    };
    let sites: Vec<i64> = (first..first + width as i64).collect();
    let resonator_sites: Vec<i64> = resonators
        .iter()
        .map(|r| scene.first_site + r.site as i64)
        .collect();
    out.set_item("sites", sites.into_pyarray(py))?;
    out.set_item("velocity", grid(field.velocity, width)?.into_pyarray(py))?;
    out.set_item(
        "displacement",
        grid(field.displacement, width)?.into_pyarray(py),
    )?;
    out.set_item("energy", grid(field.energy, width)?.into_pyarray(py))?;
    out.set_item("kinetic", grid(field.kinetic, width)?.into_pyarray(py))?;
    out.set_item("resonator_sites", resonator_sites.into_pyarray(py))?;
    let r = resonators.len();
    out.set_item(
        "resonator_displacement",
        grid(field.resonator_displacement, r)?.into_pyarray(py),
    )?;
    out.set_item(
        "resonator_velocity",
        grid(field.resonator_velocity, r)?.into_pyarray(py),
    )?;
    out.set_item("t", field.t.into_pyarray(py))?;
    Ok(())
}

/// The `SimulationError` of a failed run. A refused `auto` keeps its finest run on it, as
/// `result` (the CLI's `unverified` object: fractions, step and estimate, `verified: false`);
/// any other failure has `result = None`.
fn failure(py: Python<'_>, scene: &Scene, label: &str, error: SimError) -> PyErr {
    let err = SimulationError::new_err(format!("{label}: simulation failed: {error}"));
    let kept = match &error {
        SimError::NotConverged {
            finest: Some(finest),
            ..
        } => Some(unverified_report(scene, finest).to_string()),
        _ => None,
    };
    let result = kept.and_then(|text| {
        let json = py.import("json").ok()?;
        json.call_method1("loads", (text,)).ok()
    });
    // Setting an attribute on a fresh exception cannot fail in practice; if it did, the
    // error itself still says why the run failed.
    let _ = err.value(py).setattr("result", result);
    err
}
