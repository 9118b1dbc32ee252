//! Parquet in and out through polars, with the stage's [`Manifest`] in the file's key-value
//! metadata (key `woodpile`), so that every result file explains itself to any reader
//! (`pyarrow.parquet.read_metadata(path).metadata[b"woodpile"]`).

use std::fs::File;
use std::path::Path;

use polars::prelude::*;

use crate::atomic;
use crate::error::{PipelineError, Result};
use crate::manifest::{Manifest, METADATA_KEY};

/// Columns of a table under construction, in output order: for tables whose columns are
/// computed whole (a grid, a field); tables built row by row use [`Row`] and [`rows_frame`].
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

/// One cell of an output row.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// A float (or null).
    F64(Option<f64>),
    /// An integer (or null).
    I64(Option<i64>),
    /// A string (or null).
    Str(Option<String>),
}

impl From<f64> for Cell {
    fn from(x: f64) -> Self {
        Cell::F64(Some(x))
    }
}
impl From<Option<f64>> for Cell {
    fn from(x: Option<f64>) -> Self {
        Cell::F64(x)
    }
}
impl From<i64> for Cell {
    fn from(x: i64) -> Self {
        Cell::I64(Some(x))
    }
}
impl From<Option<i64>> for Cell {
    fn from(x: Option<i64>) -> Self {
        Cell::I64(x)
    }
}
impl From<String> for Cell {
    fn from(x: String) -> Self {
        Cell::Str(Some(x))
    }
}
impl From<&str> for Cell {
    fn from(x: &str) -> Self {
        Cell::Str(Some(x.to_string()))
    }
}
impl From<Option<String>> for Cell {
    fn from(x: Option<String>) -> Self {
        Cell::Str(x)
    }
}

/// A row of an output table: its cells, each under its column's name, in column order. A
/// kind describes its rows once, as a type, and [`rows_frame`] makes the table.
pub trait Row {
    /// The cells of this row.
    fn cells(&self) -> Vec<(&str, Cell)>;
}

/// The table of `rows`: one column per cell name, in the first row's order. Every row must
/// give the same names with the same kinds of cell (an error names the first that does not).
pub fn rows_frame<R: Row>(rows: &[R]) -> Result<DataFrame> {
    let bad = |reason: String| PipelineError::stage("table", reason);
    let Some(first) = rows.first() else {
        return Ok(DataFrame::empty());
    };
    let names: Vec<String> = first.cells().iter().map(|(n, _)| n.to_string()).collect();
    let mut columns: Vec<Vec<Cell>> = vec![Vec::with_capacity(rows.len()); names.len()];
    for (r, row) in rows.iter().enumerate() {
        let cells = row.cells();
        if cells.len() != names.len() {
            return Err(bad(format!(
                "row {r} has {} cells, not {}",
                cells.len(),
                names.len()
            )));
        }
        for (k, (name, cell)) in cells.into_iter().enumerate() {
            if name != names[k] {
                return Err(bad(format!(
                    "row {r}: column {k} is `{name}`, not `{}`",
                    names[k]
                )));
            }
            columns[k].push(cell);
        }
    }
    let mut out = Columns::new();
    for (name, cells) in names.iter().zip(columns) {
        // One kind of value per column: the first cell's.
        fn unpack<T>(
            cells: Vec<Cell>,
            pick: fn(Cell) -> Option<Option<T>>,
            mismatch: impl Fn() -> PipelineError,
        ) -> Result<Vec<Option<T>>> {
            cells
                .into_iter()
                .map(|c| pick(c).ok_or_else(&mismatch))
                .collect()
        }
        let mismatch = || bad(format!("column `{name}` mixes kinds of values"));
        match cells.first() {
            Some(Cell::F64(_)) | None => out.f64(
                name,
                unpack(
                    cells,
                    |c| match c {
                        Cell::F64(x) => Some(x),
                        _ => None,
                    },
                    mismatch,
                )?,
            ),
            Some(Cell::I64(_)) => out.i64(
                name,
                unpack(
                    cells,
                    |c| match c {
                        Cell::I64(x) => Some(x),
                        _ => None,
                    },
                    mismatch,
                )?,
            ),
            Some(Cell::Str(_)) => out.str(
                name,
                unpack(
                    cells,
                    |c| match c {
                        Cell::Str(x) => Some(x),
                        _ => None,
                    },
                    mismatch,
                )?,
            ),
        };
    }
    out.into_frame()
}

/// Writes `frame` to `path` atomically, with `manifest` in the metadata, sealed: the manifest's
/// `checksum` covers the file's data pages, the decoded content and the manifest itself
/// ([`seal`]), so that a byte changed anywhere that matters is caught on reading.
pub fn write(path: &Path, mut frame: DataFrame, manifest: &Manifest) -> Result<()> {
    // The manifest's text with a placeholder seal: the seal is computed over this exact text,
    // then written in the placeholder's place, so checking it needs no re-serialisation.
    let placeholder = Manifest {
        checksum: Some(UNSEALED.into()),
        ..manifest.clone()
    }
    .to_json_text();
    // The data pages come before the footer that holds the manifest, so they are the same
    // bytes with either text: encode once to learn them, then again with the seal.
    let unsealed = encode(&mut frame, placeholder.clone())?;
    let pages = data_pages(&unsealed)
        .ok_or_else(|| PipelineError::io(path, "parquet writer produced no footer"))?;
    let seal = seal(pages, &checksum(&frame)?, &placeholder);
    let bytes = encode(&mut frame, placeholder.replace(UNSEALED, &seal))?;
    if data_pages(&bytes) != Some(pages) {
        return Err(PipelineError::io(
            path,
            "parquet writer is not deterministic: cannot seal",
        ));
    }
    atomic::write(path, &bytes)
}

/// The seal's placeholder while it is computed: 64 characters, as the seal itself.
const UNSEALED: &str = "unsealed-unsealed-unsealed-unsealed-unsealed-unsealed-unsealed-u";

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

/// A parquet file's bytes before its footer (magic, column chunks, page headers, pages), or
/// `None` when the trailer is not a parquet one.
fn data_pages(bytes: &[u8]) -> Option<&[u8]> {
    let n = bytes.len();
    if n < 12 || &bytes[n - 4..] != b"PAR1" {
        return None;
    }
    let footer = u32::from_le_bytes(bytes[n - 8..n - 4].try_into().ok()?) as usize;
    let start = n.checked_sub(8)?.checked_sub(footer)?;
    (start >= 4).then(|| &bytes[..start])
}

/// The checksum a manifest records: blake3 over the data pages' bytes, the decoded content's
/// [`checksum`] and the manifest's exact text with the seal replaced by [`UNSEALED`]. A changed
/// page, a footer change that alters what is decoded, and an edited manifest all break it.
fn seal(pages: &[u8], content: &str, placeholder_text: &str) -> String {
    let mut hasher = blake3::Hasher::new();
    hasher.update(&(pages.len() as u64).to_le_bytes());
    hasher.update(pages);
    hasher.update(content.as_bytes());
    hasher.update(placeholder_text.as_bytes());
    hasher.finalize().to_hex().to_string()
}

/// Whether a table's content still matches the checksum its manifest recorded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Integrity {
    /// It does.
    Intact,
    /// It does not: the file was damaged after it was written.
    Damaged,
    /// There is no manifest, or the manifest records no checksum: nothing to check against.
    Unchecked,
}

/// A table as read, with its manifest and whether its content matches the manifest.
#[derive(Debug)]
pub struct Checked {
    /// The table.
    pub frame: DataFrame,
    /// Its manifest, if it has one.
    pub manifest: Option<Manifest>,
    /// Content against the manifest's checksum.
    pub integrity: Integrity,
}

/// Reads the whole table at `path` and checks its content against its manifest's checksum.
pub fn read_checked(path: &Path) -> Result<Checked> {
    let bytes = std::fs::read(path).map_err(|e| PipelineError::io(path, e))?;
    // polars' decoder panics on some damaged files (a page header out of range) instead of
    // returning an error: a damaged file is an error here, never a crash.
    let decoded = std::panic::catch_unwind(|| {
        let mut reader = ParquetReader::new(std::io::Cursor::new(&bytes));
        let metadata = reader.get_metadata()?.clone();
        reader.finish().map(|frame| (metadata, frame))
    });
    let (metadata, frame) = match decoded {
        Ok(result) => result.map_err(|e| PipelineError::io(path, e))?,
        Err(_) => return Err(PipelineError::io(path, "the parquet decoder failed on it")),
    };
    let text = manifest_text(&metadata);
    let manifest = text
        .as_deref()
        .map(|t| parse_manifest(path, t))
        .transpose()?;
    let integrity = match (&manifest, &text, data_pages(&bytes)) {
        (Some(m), Some(text), Some(pages)) => match &m.checksum {
            None => Integrity::Unchecked,
            Some(recorded) => {
                let placeholder = text.replacen(recorded.as_str(), UNSEALED, 1);
                match *recorded == seal(pages, &checksum(&frame)?, &placeholder) {
                    true => Integrity::Intact,
                    false => Integrity::Damaged,
                }
            }
        },
        (Some(_), _, _) => Integrity::Damaged,
        (None, _, _) => Integrity::Unchecked,
    };
    Ok(Checked {
        frame,
        manifest,
        integrity,
    })
}

/// Reads the whole table at `path` (a stage's input): an error if its content no longer
/// matches the checksum in its manifest, so a damaged table never flows downstream.
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

/// What a table that fails its checksum is told.
pub const DAMAGED: &str = "damaged: its bytes no longer match the checksum in its manifest";

/// The blake3 checksum (hex) of a table's content: every column's name, type and values in
/// order, nulls marked. It is computed from the decoded values, so it catches a damaged data
/// page whatever the parquet encoding, and it does not depend on how the file was compressed.
pub fn checksum(frame: &DataFrame) -> Result<String> {
    let mut hasher = blake3::Hasher::new();
    let mut put = |bytes: &[u8]| {
        hasher.update(&(bytes.len() as u64).to_le_bytes());
        hasher.update(bytes);
    };
    put(&(frame.height() as u64).to_le_bytes());
    for column in frame.columns() {
        let name = column.name().as_str();
        let bad = |e: PolarsError| PipelineError::stage("table", format!("column `{name}`: {e}"));
        put(name.as_bytes());
        let dtype = column.dtype();
        put(dtype.to_string().as_bytes());
        if dtype.is_float() {
            let values = column.cast(&DataType::Float64).map_err(bad)?;
            for v in values.f64().map_err(bad)?.iter() {
                put(&v.map_or([0xff; 8], |x| x.to_bits().to_le_bytes()));
                put(&[u8::from(v.is_some())]);
            }
        } else if dtype.is_integer() || dtype.is_bool() {
            let values = column.cast(&DataType::Int64).map_err(bad)?;
            for v in values.i64().map_err(bad)?.iter() {
                put(&v.unwrap_or(0).to_le_bytes());
                put(&[u8::from(v.is_some())]);
            }
        } else {
            let values = column.cast(&DataType::String).map_err(bad)?;
            for v in values.str().map_err(bad)?.iter() {
                put(v.unwrap_or("").as_bytes());
                put(&[u8::from(v.is_some())]);
            }
        }
    }
    Ok(hasher.finalize().to_hex().to_string())
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
    let text = manifest_text(metadata)
        .ok_or_else(|| PipelineError::io(path, "no `woodpile` manifest in the metadata"))?;
    parse_manifest(path, &text).map(Some)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest() -> Manifest {
        Manifest {
            stage: "s".into(),
            kind: "sweep".into(),
            key: "k".into(),
            code_version: "v".into(),
            params: serde_json::json!({"a": 1e-6, "b": [1, 2.5], "c": "x"}),
            inputs: Default::default(),
            summary: serde_json::json!({"points": 3}),
            checksum: None,
        }
    }

    struct Pair(i64, Option<f64>, bool);

    impl Row for Pair {
        fn cells(&self) -> Vec<(&str, Cell)> {
            let second = match self.2 {
                true => Cell::from("text"),
                false => Cell::from(self.1),
            };
            vec![("n", Cell::from(self.0)), ("x", second)]
        }
    }

    #[test]
    fn rows_make_typed_columns_and_mixed_kinds_are_an_error() {
        let frame = rows_frame(&[Pair(1, Some(0.5), false), Pair(2, None, false)]).unwrap();
        assert_eq!(frame.height(), 2);
        assert_eq!(f64_column(&frame, "x").unwrap(), vec![Some(0.5), None]);
        assert_eq!(frame.column("n").unwrap().dtype(), &DataType::Int64);
        let e = rows_frame(&[Pair(1, Some(0.5), false), Pair(2, None, true)]).unwrap_err();
        assert!(e.to_string().contains("`x` mixes"), "{e}");
    }

    #[test]
    fn a_written_table_reads_back_intact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.parquet");
        let mut columns = Columns::new();
        columns
            .f64("x", vec![Some(1.0), None, Some(f64::NAN)])
            .i64("n", vec![Some(1), Some(2), None])
            .str("s", vec![Some("a".into()), None, Some("c".into())]);
        let frame = columns.into_frame().unwrap();
        let before = checksum(&frame).unwrap();
        write(&path, frame, &manifest()).unwrap();
        let checked = read_checked(&path).unwrap();
        assert_eq!(checksum(&checked.frame).unwrap(), before, "content");
        let mut m = checked.manifest.clone().unwrap();
        m.checksum = None;
        assert_eq!(m.to_json_text(), manifest().to_json_text(), "manifest");
        assert_eq!(checked.integrity, Integrity::Intact);
    }
}
