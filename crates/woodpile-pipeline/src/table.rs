//! Parquet in and out through polars, with the stage's [`Manifest`] in the file's key-value
//! metadata (key `woodpile`), so that every result file explains itself to any reader
//! (`pyarrow.parquet.read_metadata(path).metadata[b"woodpile"]`).

use std::fs::File;
use std::path::Path;

use polars::prelude::*;

use crate::atomic;
use crate::error::{PipelineError, Result};
use crate::manifest::{Manifest, METADATA_KEY};

/// Columns of a table under construction, in output order.
#[derive(Default)]
pub struct Columns(Vec<Column>);

impl Columns {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends a float column (nulls allowed).
    pub fn f64(&mut self, name: &str, values: Vec<Option<f64>>) -> &mut Self {
        self.0.push(Column::new(name.into(), values));
        self
    }

    /// Appends an integer column (nulls allowed).
    pub fn i64(&mut self, name: &str, values: Vec<Option<i64>>) -> &mut Self {
        self.0.push(Column::new(name.into(), values));
        self
    }

    /// Appends a string column (nulls allowed).
    pub fn str(&mut self, name: &str, values: Vec<Option<String>>) -> &mut Self {
        self.0.push(Column::new(name.into(), values));
        self
    }

    /// The finished frame.
    pub fn into_frame(self) -> Result<DataFrame> {
        DataFrame::new_infer_height(self.0)
            .map_err(|e| PipelineError::stage("table", e.to_string()))
    }
}

/// Writes `frame` to `path` atomically, with `manifest` in the metadata.
pub fn write(path: &Path, mut frame: DataFrame, manifest: &Manifest) -> Result<()> {
    let metadata =
        KeyValueMetadata::from_static(vec![(METADATA_KEY.to_string(), manifest.to_json_text())]);
    atomic::write_with(path, |file| {
        ParquetWriter::new(file)
            .with_compression(ParquetCompression::Zstd(None))
            .with_key_value_metadata(Some(metadata))
            .finish(&mut frame)
            .map(|_| ())
            .map_err(std::io::Error::other)
    })
}

/// Reads the whole table at `path`.
pub fn read(path: &Path) -> Result<DataFrame> {
    let file = File::open(path).map_err(|e| PipelineError::io(path, e))?;
    ParquetReader::new(file)
        .finish()
        .map_err(|e| PipelineError::io(path, e))
}

/// Reads only the manifest in `path`'s footer: `Ok(None)` when the file does not exist.
pub fn read_manifest(path: &Path) -> Result<Option<Manifest>> {
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(PipelineError::io(path, e)),
    };
    let mut reader = ParquetReader::new(file);
    let metadata = reader
        .get_metadata()
        .map_err(|e| PipelineError::io(path, e))?;
    let text = metadata
        .key_value_metadata()
        .iter()
        .flatten()
        .find(|kv| kv.key == METADATA_KEY)
        .and_then(|kv| kv.value.clone())
        .ok_or_else(|| PipelineError::io(path, "no `woodpile` manifest in the metadata"))?;
    Manifest::from_json_text(&text)
        .map(Some)
        .map_err(|e| PipelineError::io(path, format!("unreadable manifest: {e}")))
}

/// A column of `frame` as floats (integers converted), nulls kept.
pub fn f64_column(frame: &DataFrame, name: &str) -> Result<Vec<Option<f64>>> {
    let column = frame
        .column(name)
        .and_then(|c| c.cast(&DataType::Float64))
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?;
    let values = column
        .f64()
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?
        .iter()
        .collect();
    Ok(values)
}

/// The rows of `frame` where every `(column, value)` of `filter` holds (all rows if empty).
pub fn matching_rows(frame: &DataFrame, filter: &[(String, f64)]) -> Result<Vec<usize>> {
    let columns: Vec<(Vec<Option<f64>>, f64)> = filter
        .iter()
        .map(|(c, v)| Ok((f64_column(frame, c)?, *v)))
        .collect::<Result<_>>()?;
    Ok((0..frame.height())
        .filter(|&r| columns.iter().all(|(col, v)| col[r] == Some(*v)))
        .collect())
}

/// A column of `frame` as strings, nulls kept.
pub fn str_column(frame: &DataFrame, name: &str) -> Result<Vec<Option<String>>> {
    let column = frame
        .column(name)
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?;
    let values = column
        .str()
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?
        .iter()
        .map(|v| v.map(str::to_string))
        .collect();
    Ok(values)
}
