//! `calibrate`: a physical scene's keys fitted to a measured trace
//! (`woodpile_calibrate::calibrate`), on this thread with the GIL released; Ctrl-C stops it
//! between simulations.

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use woodpile_calibrate::{calibrate as fit, Parameter, Trace, STOPPED};

use crate::interrupt::{on_this_thread, quiet};
use crate::scene_input::{label_text, Source};
use crate::SceneError;

/// _calibrate(scene, t, rod, velocity, sigma, parameters) -> dict
/// --
///
/// The native call behind `woodpile.calibrate`. `parameters` is a list of
/// `(key, min, max, start)`; the dict holds `estimates` (a list of dicts), `fitted` and
/// `residuals` (arrays, row by row), `rms`, `method`, `dt_s`, `iterations`, `simulations`,
/// `verification` (a dict) and `scene` (the fitted scene as TOML text).
#[pyfunction]
pub(crate) fn calibrate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    t: Vec<f64>,
    rod: Vec<i64>,
    velocity: Vec<f64>,
    sigma: Option<Vec<f64>>,
    parameters: Vec<(String, f64, f64, Option<f64>)>,
) -> PyResult<Bound<'py, PyDict>> {
    let source = Source::of(scene)?;
    let label = source.label();
    let table = source.table()?;
    let trace = Trace {
        t,
        rod,
        velocity,
        sigma,
    };
    let parameters: Vec<Parameter> = parameters
        .into_iter()
        .map(|(key, min, max, start)| Parameter {
            key,
            min,
            max,
            start,
        })
        .collect();
    let result = on_this_thread(py, &quiet, |stop| {
        fit(&table, &label, &trace, &parameters, stop)
    })?;
    let done = result.map_err(|reason| match reason.as_str() {
        STOPPED => SceneError::new_err("calibration stopped"),
        _ => SceneError::new_err(format!("{}: calibrate: {reason}", label_text(&label))),
    })?;
    let out = PyDict::new(py);
    let estimates = PyList::empty(py);
    for e in &done.estimates {
        let row = PyDict::new(py);
        row.set_item("key", &e.key)?;
        row.set_item("value", e.value)?;
        row.set_item("std_error", e.std_error)?;
        row.set_item("low", e.low)?;
        row.set_item("high", e.high)?;
        row.set_item("at_bound", e.at_bound)?;
        estimates.append(row)?;
    }
    out.set_item("estimates", estimates)?;
    out.set_item("fitted", done.fitted.into_pyarray(py))?;
    out.set_item("residuals", done.residuals.into_pyarray(py))?;
    out.set_item("rms", done.rms)?;
    out.set_item("method", done.method)?;
    out.set_item("dt_s", done.dt_s)?;
    out.set_item("iterations", done.iterations)?;
    out.set_item("simulations", done.simulations)?;
    let verification = PyDict::new(py);
    verification.set_item("max_difference", done.verification.max_difference)?;
    verification.set_item("allowed", done.verification.allowed)?;
    verification.set_item("passed", done.verification.passed)?;
    out.set_item("verification", verification)?;
    out.set_item("scene", toml::to_string(&done.scene).unwrap_or_default())?;
    Ok(out)
}
