//! The files a stage writes besides its table (figures, Markdown, a design's scene), covered by
//! its seal: the table is written last, with each file's blake3 in its manifest, so a stage is
//! fresh only if every file is exactly what the run that wrote the table produced. A run
//! killed between the figures and the table, a figure whose table write failed, or a file
//! edited by hand all read as stale and are written again.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::error::{PipelineError, Result};
use woodpile_files::regular;

/// Most bytes a stage's file may have (figures are a few MB).
const MAX_FILE_BYTES: u64 = 1 << 30;

/// The name a file is recorded under: its file name (a stage's files have distinct names, and
/// the name does not change when the tree is written elsewhere, as `make check` does).
fn name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

fn hash(path: &Path) -> std::io::Result<String> {
    regular::read(path, MAX_FILE_BYTES).map(|bytes| blake3::hash(&bytes).to_hex().to_string())
}

/// The checksums to record for `files`, just written by a stage.
pub fn record(files: &[PathBuf]) -> Result<BTreeMap<String, String>> {
    files
        .iter()
        .map(|f| Ok((name(f), hash(f).map_err(|e| PipelineError::io(f, e))?)))
        .collect()
}

/// Why `files` are not what `recorded` says (empty when all are).
pub fn changed(files: &[PathBuf], recorded: &BTreeMap<String, String>) -> Vec<String> {
    files
        .iter()
        .filter_map(|f| match (hash(f), recorded.get(&name(f))) {
            (Ok(h), Some(r)) if h == *r => None,
            (Err(_), _) if !f.exists() => Some(format!("{} missing", f.display())),
            (Err(e), _) => Some(format!("{}: {e}", f.display())),
            (Ok(_), None) => Some(format!("{} not recorded by its stage", f.display())),
            (Ok(_), Some(_)) => Some(format!(
                "{} is not what this stage wrote (edited, or left by an interrupted run)",
                f.display()
            )),
        })
        .collect()
}
