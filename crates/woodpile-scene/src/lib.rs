//! The scene file of `woodpile simulate` (docs/scene.md): TOML in two stages, ripgrep-style.
//!
//! `raw` mirrors the file exactly (`deny_unknown_fields`, no defaults applied); [`Scene`] is the
//! validated, typed result with the paper's defaults filled in and paper site numbers (-n..n)
//! translated to the simulator's 0-based indices. Every error names the file, the key and the
//! reason.
#![warn(missing_docs)]

pub mod columns;
pub mod cpu;
pub mod examples;
pub mod grid;
pub mod quantity;
mod raw;
pub mod report;
mod resolve;
pub mod sweep_grid;
pub mod template;
pub mod threads;
pub mod units_out;

pub use resolve::time::seconds;
pub use resolve::{DerivedDefect, Physical, Scene, DEFAULT_RESONATOR_SHARE};

use std::path::{Path, PathBuf};

use woodpile_files::input::{escape_controls, read_input, syntax_reason};

/// A scene file that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read: {reason}")]
    Read {
        /// The file.
        file: PathBuf,
        /// The OS error.
        reason: String,
    },
    /// The TOML is malformed or has an unknown key or a value of the wrong type.
    #[error("{file}: {reason}")]
    Syntax {
        /// The file.
        file: PathBuf,
        /// The parser's message, with line, column and key.
        reason: String,
    },
    /// A key has a value the model cannot accept.
    #[error("{file}: key `{key}`: {reason}")]
    Invalid {
        /// The file.
        file: PathBuf,
        /// Dotted key path, e.g. `defect[1].eps`.
        key: String,
        /// Why the value is rejected.
        reason: String,
    },
}

/// Most defects a scene may have: a thousand times the paper's largest block, and few enough
/// that planning a sweep of such scenes never needs gigabytes.
pub const MAX_DEFECTS: usize = 10_000;

/// Reads and validates the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = read_input(path).map_err(|reason| SceneError::Read {
        file: path.to_path_buf(),
        reason,
    })?;
    parse(&text, path)
}

/// Parses and validates scene TOML `text`; `path` only names the source in errors.
pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let raw: raw::SceneFile = toml::from_str(text).map_err(|e| SceneError::Syntax {
        file: path.to_path_buf(),
        reason: syntax_reason(&e, text),
    })?;
    validated(raw, path)
}

/// Validates a scene given as an already parsed TOML table (a pipeline sweep builds one per
/// parameter point); `path` only names the source in errors.
pub fn from_table(table: toml::Table, path: &Path) -> Result<Scene, SceneError> {
    let raw: raw::SceneFile =
        toml::Value::Table(table)
            .try_into()
            .map_err(|e: toml::de::Error| SceneError::Syntax {
                file: path.to_path_buf(),
                reason: escape_controls(e.message().trim_end()),
            })?;
    validated(raw, path)
}

fn validated(raw: raw::SceneFile, path: &Path) -> Result<Scene, SceneError> {
    resolve::resolve(raw).map_err(|(key, reason)| SceneError::Invalid {
        file: path.to_path_buf(),
        key,
        reason,
    })
}
