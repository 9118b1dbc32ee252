//! The example scenes the package carries (`woodpile_scene::examples`), for `woodpile.example`.

use pyo3::prelude::*;
use woodpile_scene::examples::{example as text_of, names};

use crate::SceneError;

/// examples() -> list[str]
/// --
///
/// The names of the example scenes.
#[pyfunction]
pub(crate) fn examples() -> Vec<&'static str> {
    names()
}

/// example(name) -> str
/// --
///
/// The TOML text of example `name`.
#[pyfunction]
pub(crate) fn example(name: &str) -> PyResult<&'static str> {
    text_of(name).map_err(SceneError::new_err)
}
