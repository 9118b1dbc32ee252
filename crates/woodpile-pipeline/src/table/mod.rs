//! Parquet in and out through polars, with the stage's [`Manifest`] in the file's key-value
//! metadata (key `woodpile`), so that every result file explains itself to any reader
//! (`pyarrow.parquet.read_metadata(path).metadata[b"woodpile"]`).

use std::path::Path;

use polars::prelude::*;

use crate::error::{PipelineError, Result};
use crate::manifest::{Manifest, METADATA_KEY};
use woodpile_files::atomic;
use woodpile_files::regular;

mod build;
mod columns;

pub use build::{rows_frame, Cell, Columns, Row};
pub use columns::{f64_column, matching_rows, missing_column, str_column, Match};

/// Writes `frame` to `path` atomically, with `manifest` in the metadata, sealed: the manifest's
/// `checksum` is the blake3 of the whole file's bytes with the seal itself replaced by a
/// placeholder ([`seal`]), so that every byte is checked before a reader decodes any.
pub fn write(path: &Path, mut frame: DataFrame, manifest: &Manifest) -> Result<()> {
    let placeholder = Manifest {
        checksum: Some(UNSEALED.into()),
        ..manifest.clone()
    }
    .to_json_text();
    let mut bytes = encode(&mut frame, placeholder)?;
    let at = seal_position(&bytes)
        .filter(|&at| &bytes[at..at + SEAL_LEN] == UNSEALED.as_bytes())
        .ok_or_else(|| {
            PipelineError::io(path, "the parquet writer lost the manifest: cannot seal")
        })?;
    let sealed = seal(&bytes, at);
    bytes[at..at + SEAL_LEN].copy_from_slice(sealed.as_bytes());
    Ok(atomic::write(path, &bytes)?)
}

/// The largest table woodpile reads: a thousand times its largest result. A file beyond it is
/// refused unread, so no decoder is asked to allocate for it.
pub const MAX_TABLE_BYTES: u64 = 1 << 30;

fn encode(frame: &mut DataFrame, manifest_text: String) -> Result<Vec<u8>> {
    let metadata = KeyValueMetadata::from_static(vec![(METADATA_KEY.to_string(), manifest_text)]);
    let mut bytes = Vec::new();
    ParquetWriter::new(&mut bytes)
        .with_compression(ParquetCompression::Zstd(None))
        .with_key_value_metadata(Some(metadata))
        .finish(frame)
        .map_err(|e| PipelineError::stage("table", e.to_string()))?;
    Ok(bytes)
}

pub use woodpile_seal::Integrity;
use woodpile_seal::{position as seal_position, seal, SEAL_LEN, UNSEALED};

/// A table as read, with its manifest and whether its bytes match the manifest's seal.
#[derive(Debug)]
pub struct Checked {
    /// The table (empty when damaged: a damaged file is never decoded).
    pub frame: DataFrame,
    /// Its manifest, if it has one (none when damaged).
    pub manifest: Option<Manifest>,
    /// The bytes against the manifest's seal.
    pub integrity: Integrity,
}

/// The bytes of the table at `path` (a regular file of at most [`MAX_TABLE_BYTES`]) and
/// whether they match their seal ([`woodpile_seal::integrity`]), checked before anything
/// decodes them.
fn sealed_bytes(path: &Path) -> Result<(Vec<u8>, Integrity)> {
    let bytes = regular::read(path, MAX_TABLE_BYTES).map_err(|e| PipelineError::io(path, e))?;
    let integrity = woodpile_seal::integrity(&bytes);
    Ok((bytes, integrity))
}

/// Whether the file at `path` is a woodpile table whose bytes match its seal (what woodpile
/// wrote, and nothing since).
pub fn is_sealed(path: &Path) -> Result<bool> {
    Ok(sealed_bytes(path)?.1 == Integrity::Intact)
}

/// Runs a polars decoder on bytes: some damaged files make it panic rather than return an
/// error (sealed files never reach it damaged; foreign ones may).
fn decode<T>(path: &Path, work: impl FnOnce() -> PolarsResult<T>) -> Result<T> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)) {
        Ok(result) => result.map_err(|e| PipelineError::io(path, e)),
        Err(_) => Err(PipelineError::io(path, "the parquet decoder failed on it")),
    }
}

/// Most memory a table may take once decoded, as its footer states it.
pub const MAX_DECODED_BYTES: f64 = 2e9;

/// Whether a table, by its footer, is one woodpile can decode: columns of 32- and 64-bit
/// numbers, booleans, text or lists of them (the polars build here has no decimal, map, struct
/// or small integer types, and panics on some), and at most [`MAX_DECODED_BYTES`] once decoded (a small file of run-length encoded
/// values can claim gigabytes). The error is the reason.
fn decodable(
    metadata: &FileMetadataRef,
    schema: &polars::prelude::ArrowSchema,
) -> std::result::Result<(), String> {
    use polars::prelude::ArrowDataType as A;
    fn readable(dtype: &A) -> bool {
        match dtype {
            A::Null | A::Boolean | A::Utf8 | A::LargeUtf8 | A::Utf8View => true,
            A::List(f) | A::LargeList(f) | A::FixedSizeList(f, _) => readable(f.dtype()),
            // The integer and float widths this build of polars decodes.
            A::Int32 | A::Int64 | A::UInt32 | A::UInt64 | A::Float32 | A::Float64 => true,
            _ => false,
        }
    }
    if let Some((name, field)) = schema.iter().find(|(_, f)| !readable(f.dtype())) {
        return Err(format!(
            "column `{name}` is {:?}: woodpile reads columns of numbers, text and lists of them",
            field.dtype()
        ));
    }
    let stated: usize = metadata
        .row_groups
        .iter()
        .map(|g| g.total_byte_size())
        .sum();
    let cells = metadata.num_rows as f64 * schema.len() as f64 * 8.0;
    let bytes = (stated as f64).max(cells);
    if bytes > MAX_DECODED_BYTES {
        return Err(format!(
            "its footer states {} rows, about {:.1} GB decoded, more than the {:.0} GB woodpile reads",
            metadata.num_rows,
            bytes / 1e9,
            MAX_DECODED_BYTES / 1e9
        ));
    }
    Ok(())
}

/// Reads the whole table at `path`, after checking its bytes against its manifest's seal.
pub fn read_checked(path: &Path) -> Result<Checked> {
    let (bytes, integrity) = sealed_bytes(path)?;
    if integrity == Integrity::Damaged {
        return Ok(Checked {
            frame: DataFrame::empty(),
            manifest: None,
            integrity,
        });
    }
    // The footer first: what decoding would hold, and whether it is columns woodpile reads.
    let (metadata, schema) = decode(path, || {
        let mut reader = ParquetReader::new(std::io::Cursor::new(&bytes));
        let metadata = reader.get_metadata()?.clone();
        Ok((metadata, reader.schema()?))
    })?;
    decodable(&metadata, &schema).map_err(|reason| PipelineError::io(path, reason))?;
    let frame = decode(path, || {
        ParquetReader::new(std::io::Cursor::new(&bytes)).finish()
    })?;
    let manifest = manifest_text(&metadata)
        .map(|t| parse_manifest(path, &t))
        .transpose()?;
    Ok(Checked {
        frame,
        manifest,
        integrity,
    })
}

/// The manifest of the table at `path` and the table's integrity, from its footer alone (no
/// data page is decoded): what `status` needs. `Ok(None)` when the file does not exist.
pub fn read_checked_manifest(path: &Path) -> Result<Option<(Option<Manifest>, Integrity)>> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(None);
    }
    let (bytes, integrity) = sealed_bytes(path)?;
    if integrity == Integrity::Damaged {
        return Ok(Some((None, integrity)));
    }
    let metadata = decode(path, || {
        ParquetReader::new(std::io::Cursor::new(&bytes))
            .get_metadata()
            .cloned()
    })?;
    let manifest = manifest_text(&metadata)
        .map(|t| parse_manifest(path, &t))
        .transpose()?;
    Ok(Some((manifest, integrity)))
}

/// Reads the whole table at `path` (a stage's input): an error if its bytes no longer
/// match the seal in its manifest, so a damaged table never flows downstream.
pub fn read(path: &Path) -> Result<DataFrame> {
    let checked = read_checked(path)?;
    if checked.integrity == Integrity::Damaged {
        return Err(PipelineError::io(path, DAMAGED));
    }
    Ok(checked.frame)
}

/// [`read`], with the table's manifest (for a stage that quotes its inputs' parameters).
pub fn read_with_manifest(path: &Path) -> Result<(DataFrame, Manifest)> {
    let checked = read_checked(path)?;
    match (checked.integrity, checked.manifest) {
        (Integrity::Damaged, _) => Err(PipelineError::io(path, DAMAGED)),
        (_, None) => Err(PipelineError::io(
            path,
            "no `woodpile` manifest in the metadata",
        )),
        (_, Some(manifest)) => Ok((checked.frame, manifest)),
    }
}

/// What a table that fails its seal is told.
pub const DAMAGED: &str = "damaged: its bytes no longer match the seal in its manifest";

/// Reads only the manifest of the table at `path`: `Ok(None)` when the file does not exist,
/// an error when it is damaged or has no manifest.
pub fn read_manifest(path: &Path) -> Result<Option<Manifest>> {
    match read_checked_manifest(path)? {
        None => Ok(None),
        Some((_, Integrity::Damaged)) => Err(PipelineError::io(path, DAMAGED)),
        Some((None, _)) => Err(PipelineError::io(
            path,
            "no `woodpile` manifest in the metadata",
        )),
        Some((Some(manifest), _)) => Ok(Some(manifest)),
    }
}

/// The manifest's text in a parquet footer, `None` when it has none.
fn manifest_text(metadata: &FileMetadataRef) -> Option<String> {
    metadata
        .key_value_metadata()
        .iter()
        .flatten()
        .find(|kv| kv.key == METADATA_KEY)
        .and_then(|kv| kv.value.clone())
}

fn parse_manifest(path: &Path, text: &str) -> Result<Manifest> {
    Manifest::from_json_text(text)
        .map_err(|e| PipelineError::io(path, format!("unreadable manifest: {e}")))
}

#[cfg(test)]
mod tests;
