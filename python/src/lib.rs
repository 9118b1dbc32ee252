//! `woodpile._core`: the native half of the Python package. It turns Python values into scenes
//! (`scene_input`), simulates one scene with its series and field (`simulate`) or a grid of them
//! on every core (`sweep`), always on a worker thread that Ctrl-C can stop (`interrupt`), and
//! hands results back as NumPy arrays without a copy per sample. The typed, documented API is
//! the pure-Python `woodpile` package around it.

mod calibrate;
mod examples;
mod interrupt;
mod listed;
mod pool;
mod scene_input;
mod series;
mod simulate;
mod spectrum;
mod sweep;

use pyo3::prelude::*;

pyo3::create_exception!(
    woodpile,
    SceneError,
    pyo3::exceptions::PyValueError,
    "A scene (or sweep axes) that cannot be used: the message names the source (file, <dict> or <string>), the key and the reason, as `woodpile simulate` does."
);
pyo3::create_exception!(
    woodpile,
    SimulationError,
    pyo3::exceptions::PyRuntimeError,
    "A simulation that failed (blow-up, energy drift, tolerance out of reach, over budget): never numbers."
);

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    // NumPy's C API is fetched here, once, rather than at the first array a call returns: a
    // table built after Ctrl-C would otherwise import it with a second interrupt pending,
    // and the failed import is a panic, not an exception.
    numpy::PyArray1::<f64>::zeros(py, 0, false);
    // `WOODPILE_SIMD` and `WOODPILE_LANES`, read once, as the command line reads them.
    woodpile_scene::cpu::apply_environment();
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::simulate_many, m)?)?;
    m.add_function(wrap_pyfunction!(spectrum::spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(examples::examples, m)?)?;
    m.add_function(wrap_pyfunction!(examples::example, m)?)?;
    m.add_function(wrap_pyfunction!(scene_input::scene_toml, m)?)?;
    #[cfg(feature = "testing")]
    m.add_function(wrap_pyfunction!(interrupt::panic_in_worker, m)?)?;
    m.add_function(wrap_pyfunction!(table_integrity, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The shares' names in the order every table lists them, for the Python side to iterate.
    let shares = woodpile_sim::Share::ALL.map(woodpile_sim::Share::name);
    m.add("SHARES", pyo3::types::PyTuple::new(py, shares)?)?;
    Ok(())
}

/// Whether a table's bytes match the seal in their manifest: "intact", "damaged" or
/// "unchecked" (no seal: not a woodpile table). The engine's own check, so that
/// `Pipeline.read` refuses exactly the files `woodpile status` calls damaged.
#[pyfunction]
fn table_integrity(data: &[u8]) -> &'static str {
    match woodpile_seal::integrity(data) {
        woodpile_seal::Integrity::Intact => "intact",
        woodpile_seal::Integrity::Damaged => "damaged",
        woodpile_seal::Integrity::Unchecked => "unchecked",
    }
}
