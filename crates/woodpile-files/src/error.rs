//! What can go wrong between a results tree's files and the disk: each error names the path
//! it concerns.

use std::path::PathBuf;

/// Any error, as a source.
pub type BoxError = Box<dyn std::error::Error + Send + Sync>;

/// A file of the tree could not be written, or woodpile will not use it as it is.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS's error, kept as the source.
        #[source]
        source: BoxError,
    },
    /// A path that woodpile will not use as it is (a symbolic link or a non-regular file where
    /// its own folders go): bad input, not a failed write.
    #[error("{path}: {reason}")]
    Refused {
        /// The path.
        path: PathBuf,
        /// Why, and what to do.
        reason: String,
    },
}

impl FileError {
    /// An IO error on `path`, keeping `e` as its source.
    pub fn io(path: impl Into<PathBuf>, e: impl Into<BoxError>) -> Self {
        Self::Io {
            path: path.into(),
            source: e.into(),
        }
    }

    /// A path refused for `reason`.
    pub fn refused(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Self::Refused {
            path: path.into(),
            reason: reason.into(),
        }
    }
}

/// Result alias of this crate.
pub type Result<T, E = FileError> = std::result::Result<T, E>;
