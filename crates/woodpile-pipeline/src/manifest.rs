//! What a stage output says about itself: the stage, its cache key, and everything the key was
//! computed from, so that `woodpile status` can say *why* a result is stale.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The parquet metadata key holding the manifest.
pub const METADATA_KEY: &str = "woodpile";

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
    /// is exactly what this run wrote ([`crate::sealed_files`]).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub files: BTreeMap<String, String>,
    /// The table's seal, set when it is written: blake3 of the whole file with the seal read as
    /// a placeholder ([`crate::table::write`]). It is the last field, so it ends the manifest's
    /// text. `status` and every reader of the table check it before decoding anything.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub checksum: Option<String>,
}

impl Manifest {
    /// The manifest as one line of JSON.
    pub fn to_json_text(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Parses [`Manifest::to_json_text`]'s output.
    pub fn from_json_text(text: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(text)
    }
}
