//! Everything that can stop the pipeline, each naming the file (and key) it concerns, and
//! keeping the error behind it (the OS's, polars', the TOML parser's, an embedded scene's
//! `SceneError`) as its `source`.

use std::path::PathBuf;

use woodpile_files::FileError;

/// A pipeline failure.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// A stage file (or the pipeline directory as a whole) is not a valid definition.
    #[error("{file}: key `{key}`: {reason}")]
    Definition {
        /// The stage file.
        file: PathBuf,
        /// Dotted key path, e.g. `axes.eps.step`.
        key: String,
        /// Why it is rejected.
        reason: String,
        /// The error behind it, if another layer found it (an embedded scene's `SceneError`).
        #[source]
        source: Option<BoxError>,
    },
    /// A stage file could not be read or parsed as TOML.
    #[error("{file}: {reason}")]
    Syntax {
        /// The stage file.
        file: PathBuf,
        /// The parser's or the OS's message.
        reason: String,
        /// The parser's error, when there is one.
        #[source]
        source: Option<BoxError>,
    },
    /// A stage named on the command line does not exist.
    #[error("no stage named `{name}` (stages: {known})")]
    UnknownStage {
        /// The name asked for.
        name: String,
        /// The names that exist, comma separated.
        known: String,
    },
    /// A file could not be read or written, or a path of the results tree that woodpile will
    /// not use as it is (a symbolic link or a non-regular file where its lock or its own
    /// folders go: bad input, not a failed run).
    #[error(transparent)]
    File(#[from] FileError),
    /// The run finished what it could, but stages failed (or failed in part, or were skipped
    /// because an input failed): each named with its reason.
    #[error("{} failure(s): {}", failures.len(), failures.join("; "))]
    Failed {
        /// One line per failure.
        failures: Vec<String>,
    },
    /// A stage ran but cannot produce its output (bad data from upstream, impossible
    /// reduction, ...).
    #[error("stage `{stage}`: {reason}")]
    Stage {
        /// The stage.
        stage: String,
        /// Why it failed.
        reason: String,
    },
}

impl PipelineError {
    /// A path of the results tree refused for `reason`.
    pub fn refused(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Self::File(FileError::refused(path, reason))
    }

    /// An IO error on `path`, keeping `e` as its source.
    pub fn io(path: impl Into<PathBuf>, e: impl Into<BoxError>) -> Self {
        Self::File(FileError::io(path, e))
    }

    /// A stage failure.
    pub fn stage(stage: &str, reason: impl Into<String>) -> Self {
        Self::Stage {
            stage: stage.to_string(),
            reason: reason.into(),
        }
    }
}

pub use woodpile_files::error::BoxError;

/// Result alias of this crate.
pub type Result<T, E = PipelineError> = std::result::Result<T, E>;
