//! `spectrum`: a scene's linear picture (`woodpile spectrum`'s JSON and tables), each table a
//! dict of NumPy arrays; with `measure`, its nonlinear run on a worker thread that Ctrl-C
//! stops.

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use woodpile_spectrum::measured::measure as measure_run;
use woodpile_spectrum::scene::{scene_spectrum, Asked, Frequency, Refusal, SceneRequest};
use woodpile_spectrum::tables::{summary, table, Part, Values};

use crate::interrupt::interruptible;
use crate::scene_input::{label_text, Source};
use crate::{SceneError, SimulationError};

/// _spectrum(scene, cell=None, frequencies=None, measure=False, probe=None) -> dict
/// --
///
/// The native call behind `woodpile.spectrum`: a dict with `summary` (the CLI's JSON text) and
/// `tables`, a dict from each table's name to a dict of column arrays (tables the scene has
/// not, such as `damped` without dashpots, are left out).
#[pyfunction]
#[pyo3(signature = (scene, cell = None, frequencies = None, measure = false, probe = None))]
pub(crate) fn spectrum<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    cell: Option<(i64, i64)>,
    frequencies: Option<(Bound<'py, PyAny>, Bound<'py, PyAny>, usize)>,
    measure: bool,
    probe: Option<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let source = Source::of(scene)?;
    let label = label_text(&source.label());
    let scene = source.scene()?;
    let frequencies = match frequencies {
        None => None,
        Some((lower, upper, points)) => Some((frequency(&lower)?, frequency(&upper)?, points)),
    };
    let request = SceneRequest {
        cell: cell.map(|(lo, hi)| [lo, hi]),
        frequencies,
    };
    let refused = |r: Refusal| refusal(&label, r);
    let mut spectrum = scene_spectrum(&scene, &request).map_err(refused)?;
    if measure {
        let measured = interruptible(py, |cancel| {
            let stop = || cancel.load(std::sync::atomic::Ordering::Relaxed);
            measure_run(&scene, &spectrum, probe, &stop)
        })?;
        spectrum.measured = Some(measured.map_err(refused)?);
    }
    let out = PyDict::new(py);
    out.set_item("summary", summary(&spectrum).to_string())?;
    let tables = PyDict::new(py);
    for part in Part::LINEAR.into_iter().chain([Part::Measured]) {
        let Ok(columns) = table(&spectrum, part) else {
            continue;
        };
        let arrays = PyDict::new(py);
        for column in columns {
            match column.values {
                Values::F64(v) => arrays.set_item(column.name, v.into_pyarray(py))?,
                Values::I64(v) => arrays.set_item(column.name, v.into_pyarray(py))?,
            }
        }
        tables.set_item(part.name(), arrays)?;
    }
    out.set_item("tables", tables)?;
    Ok(out)
}

/// A frequency as given: a number, or text with a unit.
fn frequency(value: &Bound<'_, PyAny>) -> PyResult<Frequency> {
    if let Ok(text) = value.extract::<String>() {
        return Ok(Frequency::Text(text));
    }
    value.extract::<f64>().map(Frequency::Number).map_err(|_| {
        SceneError::new_err("frequencies: each end is a number or text such as \"2 kHz\"")
    })
}

/// A refusal as Python's exception: a failed run is a `SimulationError`, anything else a
/// `SceneError` naming the argument it is about.
fn refusal(label: &str, r: Refusal) -> PyErr {
    let argument = match r.asked {
        Asked::Scene => "",
        Asked::Cell => "cell: ",
        Asked::Frequencies => "frequencies: ",
        Asked::Probe => "probe: ",
        Asked::Sampling => "run.sample_every: ",
        Asked::Window => "run.t_end: ",
        Asked::Run => return SimulationError::new_err(format!("{label}: {}", r.reason)),
    };
    SceneError::new_err(format!("{label}: {argument}{}", r.reason))
}
