//! The scene file of `woodpile simulate` (SPEC §3): TOML in two stages, ripgrep-style.
//!
//! [`raw`] mirrors the file exactly (`deny_unknown_fields`, no defaults applied); [`Scene`] is the
//! validated, typed result with the paper's defaults filled in and paper site numbers (-n..n)
//! translated to the simulator's 0-based indices. Every error names the file, the key and the
//! reason.
#![warn(missing_docs)]

mod raw;
mod resolve;

pub use resolve::{DerivedDefect, Physical, Scene};

use std::path::{Path, PathBuf};

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

/// Reads and validates the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError::Read {
        file: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    parse(&text, path)
}

/// Parses and validates scene TOML `text`; `path` only names the source in errors.
pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let raw: raw::SceneFile = toml::from_str(text).map_err(|e| SceneError::Syntax {
        file: path.to_path_buf(),
        reason: e.to_string().trim_end().to_string(),
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
                reason: e.to_string().trim_end().to_string(),
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
