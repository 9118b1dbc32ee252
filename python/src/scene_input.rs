//! A scene as Python users hold it: a dict with the scene file's keys, a TOML string, or a path
//! (`str` or `os.PathLike`). Dicts are turned into TOML tables value by value, so a dict and
//! the file it mirrors give the same scene and the same errors (named `<dict>` instead of the
//! file).

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use woodpile_scene::Scene;

use crate::SceneError;

/// Where a scene comes from.
pub(crate) enum Source {
    /// A scene file.
    File(PathBuf),
    /// TOML text.
    Text(String),
    /// A dict, already a TOML table.
    Table(toml::Table),
}

/// How errors name a source that is not a file.
const DICT: &str = "<dict>";
const STRING: &str = "<string>";

impl Source {
    /// Reads `obj`: a dict, an `os.PathLike`, or a `str` that is TOML text when it holds a
    /// newline or an `=` and a path otherwise.
    pub(crate) fn of(obj: &Bound<'_, PyAny>) -> PyResult<Source> {
        if let Ok(dict) = obj.cast::<PyDict>() {
            return Ok(Source::Table(table(dict, "")?));
        }
        if let Ok(text) = obj.cast::<PyString>() {
            let text: String = text.extract()?;
            return Ok(if text.contains('\n') || text.contains('=') {
                Source::Text(text)
            } else {
                Source::File(PathBuf::from(text))
            });
        }
        if obj.hasattr("__fspath__")? {
            return Ok(Source::File(obj.call_method0("__fspath__")?.extract()?));
        }
        Err(SceneError::new_err(format!(
            "a scene is a dict, a TOML string or a path, not {}",
            obj.get_type().name()?
        )))
    }

    /// The name errors give this source.
    pub(crate) fn label(&self) -> PathBuf {
        match self {
            Source::File(path) => path.clone(),
            Source::Text(_) => PathBuf::from(STRING),
            Source::Table(_) => PathBuf::from(DICT),
        }
    }

    /// The validated scene, with the CLI's error messages.
    pub(crate) fn scene(self) -> PyResult<Scene> {
        let label = self.label();
        match self {
            Source::File(path) => woodpile_scene::load(&path),
            Source::Text(text) => woodpile_scene::parse(&text, &label),
            Source::Table(table) => woodpile_scene::from_table(table, &label),
        }
        .map_err(|e| SceneError::new_err(e.to_string()))
    }

    /// The source as a TOML table, not yet validated (a sweep's template).
    pub(crate) fn table(self) -> PyResult<toml::Table> {
        let label = self.label();
        let text = match self {
            Source::Table(table) => return Ok(table),
            Source::Text(text) => text,
            Source::File(path) => woodpile_files::input::read_input(&path).map_err(|reason| {
                SceneError::new_err(format!("{}: cannot read: {reason}", path.display()))
            })?,
        };
        toml::from_str(&text).map_err(|e| {
            SceneError::new_err(format!(
                "{}: {}",
                label.display(),
                woodpile_files::input::syntax_reason(&e, &text)
            ))
        })
    }
}

/// An error about `key` of a dict, in the scene errors' form.
fn key_error(key: &str, reason: &str) -> PyErr {
    SceneError::new_err(format!("{DICT}: key `{key}`: {reason}"))
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// Deepest nesting a scene's value may have: a scene file is four levels deep at most, so this
/// stops only values that contain themselves (or a `tolist()` that returns a new such object
/// each time) before the native stack overflows.
const MAX_DEPTH: usize = 64;
/// Most values one scene may hold: far above any real chain's lists, below what would fill the
/// memory (a `tolist()` that grows its own list while it is read).
const MAX_VALUES: usize = 10_000_000;

/// What a conversion may still spend: values in all (the depth is passed down the calls).
struct Budget {
    values: usize,
}

/// A dict as a TOML table; `prefix` is its dotted key, for errors.
pub(crate) fn table(dict: &Bound<'_, PyDict>, prefix: &str) -> PyResult<toml::Table> {
    table_within(dict, prefix, 0, &mut Budget { values: MAX_VALUES })
}

fn table_within(
    dict: &Bound<'_, PyDict>,
    prefix: &str,
    depth: usize,
    budget: &mut Budget,
) -> PyResult<toml::Table> {
    let mut out = toml::Table::new();
    // A snapshot of the items: the dict may be changed by the values' own methods while they
    // are converted (iterating it live would then panic). A change is then refused.
    let items = dict.items();
    for item in items.iter() {
        let (key, value) = item
            .extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>()
            .map_err(|e| key_error(prefix, &e.to_string()))?;
        let Ok(key) = key.extract::<String>() else {
            return Err(key_error(prefix, "keys must be strings of valid text"));
        };
        let path = join(prefix, &key);
        out.insert(key, value_within(&value, &path, depth + 1, budget)?);
    }
    if dict.len() != items.len() {
        return Err(key_error(prefix, "the dict changed while it was read"));
    }
    Ok(out)
}

/// A Python value as a TOML value: bool, int, float, str, dict, list or tuple, and anything
/// with `tolist()` (NumPy arrays) or `__index__`/`__float__` (NumPy scalars). Whatever goes
/// wrong (a method that raises, text that is not valid, a value too deep or too large) is a
/// `SceneError` naming the key.
fn value_within(
    value: &Bound<'_, PyAny>,
    path: &str,
    depth: usize,
    budget: &mut Budget,
) -> PyResult<toml::Value> {
    if depth > MAX_DEPTH {
        return Err(key_error(
            path,
            &format!("nested more than {MAX_DEPTH} levels deep (a value that contains itself?)"),
        ));
    }
    budget.values = budget
        .values
        .checked_sub(1)
        .ok_or_else(|| key_error(path, &format!("more than {MAX_VALUES} values in one scene")))?;
    let failed = |e: PyErr| key_error(path, &e.to_string());
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract().map_err(failed)?));
    }
    if value.is_instance_of::<PyInt>() {
        return value
            .extract::<i64>()
            .map(toml::Value::Integer)
            .map_err(|_| key_error(path, "integer out of range"));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract().map_err(failed)?));
    }
    if let Ok(s) = value.cast::<PyString>() {
        let text = s
            .extract()
            .map_err(|_| key_error(path, "not valid text (a lone surrogate?)"))?;
        return Ok(toml::Value::String(text));
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        return Ok(toml::Value::Table(table_within(dict, path, depth, budget)?));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, item) in value.try_iter().map_err(failed)?.enumerate() {
            let item = item.map_err(failed)?;
            items.push(value_within(
                &item,
                &format!("{path}[{i}]"),
                depth + 1,
                budget,
            )?);
        }
        return Ok(toml::Value::Array(items));
    }
    if value.hasattr("tolist").map_err(failed)? {
        let list = value.call_method0("tolist").map_err(failed)?;
        if !list.is(value) {
            return value_within(&list, path, depth + 1, budget);
        }
    }
    if value.hasattr("__index__").map_err(failed)? {
        return match value.call_method0("__index__") {
            Ok(i) => i
                .extract::<i64>()
                .map(toml::Value::Integer)
                .map_err(|_| key_error(path, "integer out of range")),
            Err(e) => Err(key_error(path, &format!("its __index__ failed: {e}"))),
        };
    }
    if value.hasattr("__float__").map_err(failed)? {
        return match value.extract::<f64>() {
            Ok(x) => Ok(toml::Value::Float(x)),
            Err(e) => Err(key_error(path, &format!("its __float__ failed: {e}"))),
        };
    }
    let type_name = value.get_type().name()?;
    Err(key_error(
        path,
        &format!("a {type_name} has no TOML form (expected a number, string, bool, list or dict)"),
    ))
}

/// scene_toml(scene) -> str
/// --
///
/// The scene (a dict, TOML string or path) as the text of a scene file.
#[pyfunction]
pub(crate) fn scene_toml(scene: &Bound<'_, PyAny>) -> PyResult<String> {
    let table = Source::of(scene)?.table()?;
    toml::to_string(&table).map_err(|e| SceneError::new_err(e.to_string()))
}

/// The label's display form, for messages built outside this module.
pub(crate) fn label_text(label: &Path) -> String {
    label.display().to_string()
}
