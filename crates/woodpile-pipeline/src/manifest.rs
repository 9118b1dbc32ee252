//! What a stage output says about itself: the stage, its cache key, and everything the key was
//! computed from, so that `woodpile status` can say *why* a result is stale.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The parquet metadata key holding the manifest.
pub use woodpile_seal::METADATA_KEY;

/// A stage output's description of itself.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The stage name.
    pub stage: String,
    /// Its kind (`sweep`, `reduce`, ...).
    pub kind: String,
    /// The cache key (hex blake3) of everything below.
    pub key: String,
    /// The code version the key includes.
    pub code_version: String,
    /// The stage's parameters: its file without `description`.
    pub params: Value,
    /// Upstream stage name to the key of the output this one was computed from.
    pub inputs: BTreeMap<String, String>,
    /// Kind-specific facts about the result (points, failures, method, tolerance, ...).
    pub summary: Value,
    /// Every file the stage wrote besides its table (figures, Markdown, a design's scene), by
    /// file name, with the blake3 of its bytes: `status` calls the stage fresh only if each
    /// is exactly what this run wrote (`sealed_files.rs`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub files: BTreeMap<String, String>,
    /// The table's seal, set when it is written: blake3 of the whole file with the seal read as
    /// a placeholder (`table::write`). It is the last field, so it ends the manifest's
    /// text. `status` and every reader of the table check it before decoding anything.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub checksum: Option<String>,
}

impl Manifest {
    /// The manifest as one line of JSON.
    pub fn to_json_text(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// The value at `path` in the manifest's JSON ([`lookup`]).
    pub fn lookup(&self, path: &str) -> Option<Value> {
        lookup(&serde_json::to_value(self).ok()?, path).cloned()
    }

    /// Parses [`Manifest::to_json_text`]'s output.
    pub fn from_json_text(text: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(text)
    }
}

/// The one way a manifest value is addressed, by render titles and report sources alike:
/// dotted keys from the top (`summary.tolerance`, `params.scene.defect.0.eps`), a number
/// indexing an array. A path starting with `/` is read as a JSON pointer
/// (`/summary/tolerance`), the same keys with slashes.
pub fn lookup<'v>(value: &'v Value, path: &str) -> Option<&'v Value> {
    let keys = match path.strip_prefix('/') {
        Some(pointer) => pointer.split('/'),
        None => path.split('.'),
    };
    keys.filter(|k| !k.is_empty())
        .try_fold(value, |v, k| match (v, k.parse::<usize>()) {
            (Value::Array(items), Ok(i)) => items.get(i),
            _ => v.get(k),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dotted_paths_and_pointers_address_the_same_values() {
        let v = serde_json::json!({"summary": {"tol": 1e-6}, "params": {"d": [{"eps": 2.0}]}});
        assert_eq!(lookup(&v, "summary.tol"), Some(&serde_json::json!(1e-6)));
        assert_eq!(lookup(&v, "/summary/tol"), lookup(&v, "summary.tol"));
        assert_eq!(lookup(&v, "params.d.0.eps"), Some(&serde_json::json!(2.0)));
        assert_eq!(lookup(&v, "/params/d/0/eps"), Some(&serde_json::json!(2.0)));
        assert_eq!(lookup(&v, "params.d.1.eps"), None);
        assert_eq!(lookup(&v, "summary.missing"), None);
    }
}
