//! Parquet in and out through polars, with the stage's [`Manifest`] in the file's key-value
//! metadata (key `woodpile`), so that every result file explains itself to any reader
//! (`pyarrow.parquet.read_metadata(path).metadata[b"woodpile"]`).

use std::path::Path;

use polars::prelude::*;

use crate::atomic;
use crate::error::{PipelineError, Result};
use crate::manifest::{Manifest, METADATA_KEY};
use crate::regular;

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

    /// Appends a column of float lists (one list per row: pandas and polars read them as
    /// lists).
    pub fn f64_list(&mut self, name: &str, values: Vec<Vec<f64>>) -> &mut Self {
        self.list(name, values)
    }

    /// Appends a column of integer lists.
    pub fn i64_list(&mut self, name: &str, values: Vec<Vec<i64>>) -> &mut Self {
        self.list(name, values)
    }

    fn list<T>(&mut self, name: &str, values: Vec<Vec<T>>) -> &mut Self
    where
        Series: NamedFrom<Vec<T>, [T]>,
    {
        let rows: Vec<Series> = values
            .into_iter()
            .map(|v| Series::new(PlSmallStr::EMPTY, v))
            .collect();
        let column = <Series as NamedFrom<Vec<Series>, ListType>>::new(name.into(), rows);
        self.0.push(column.into());
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
    /// A list of floats.
    F64List(Vec<f64>),
    /// A list of integers.
    I64List(Vec<i64>),
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
            Some(Cell::F64List(_)) => out.f64_list(
                name,
                unpack(
                    cells,
                    |c| match c {
                        Cell::F64List(x) => Some(Some(x)),
                        _ => None,
                    },
                    mismatch,
                )?
                .into_iter()
                .flatten()
                .collect(),
            ),
            Some(Cell::I64List(_)) => out.i64_list(
                name,
                unpack(
                    cells,
                    |c| match c {
                        Cell::I64List(x) => Some(Some(x)),
                        _ => None,
                    },
                    mismatch,
                )?
                .into_iter()
                .flatten()
                .collect(),
            ),
        };
    }
    out.into_frame()
}

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
    atomic::write(path, &bytes)
}

/// The seal's placeholder while it is computed: 64 characters, as the seal itself.
const UNSEALED: &str = "unsealed-unsealed-unsealed-unsealed-unsealed-unsealed-unsealed-u";
const SEAL_LEN: usize = 64;
/// What precedes the seal in the manifest's text (its last field).
const SEAL_MARK: &[u8] = b"\"checksum\":\"";

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

/// Where the seal's 64 characters start in a sealed file: after the last `"checksum":"`
/// (the manifest's last field, in the footer near the end of the file).
fn seal_position(bytes: &[u8]) -> Option<usize> {
    let at = bytes
        .windows(SEAL_MARK.len())
        .rposition(|w| w == SEAL_MARK)?
        + SEAL_MARK.len();
    (at + SEAL_LEN <= bytes.len()).then_some(at)
}

/// The seal of a file whose seal starts at `at`: blake3 of every byte, with the seal's own
/// 64 characters read as [`UNSEALED`]. A changed byte anywhere (data, footer, manifest) breaks it.
fn seal(bytes: &[u8], at: usize) -> String {
    let mut hasher = blake3::Hasher::new();
    hasher.update(b"woodpile table seal 2\n");
    hasher.update(&bytes[..at]);
    hasher.update(UNSEALED.as_bytes());
    hasher.update(&bytes[at + SEAL_LEN..]);
    hasher.finalize().to_hex().to_string()
}

/// Whether a table's bytes still match the seal its manifest recorded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Integrity {
    /// They do.
    Intact,
    /// They do not: the file was damaged (or edited) after it was written. It is not decoded.
    Damaged,
    /// There is no seal to check against: not a woodpile table.
    Unchecked,
}

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
/// whether they match their seal, checked before anything decodes them. A file that carries
/// woodpile's marks (the `woodpile` metadata key or a seal field) but no matching seal is
/// damaged; only a file with neither is unchecked (a foreign parquet file).
fn sealed_bytes(path: &Path) -> Result<(Vec<u8>, Integrity)> {
    let bytes = regular::read(path, MAX_TABLE_BYTES).map_err(|e| PipelineError::io(path, e))?;
    let integrity = match seal_position(&bytes) {
        Some(at) if bytes[at..at + SEAL_LEN] == *seal(&bytes, at).as_bytes() => Integrity::Intact,
        Some(_) => Integrity::Damaged,
        None if contains(&bytes, METADATA_KEY.as_bytes()) => Integrity::Damaged,
        None => Integrity::Unchecked,
    };
    Ok((bytes, integrity))
}

fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    haystack.windows(needle.len()).any(|w| w == needle)
}

/// Runs a polars decoder on bytes: some damaged files make it panic rather than return an
/// error (sealed files never reach it damaged; foreign ones may).
fn decode<T>(path: &Path, work: impl FnOnce() -> PolarsResult<T>) -> Result<T> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)) {
        Ok(result) => result.map_err(|e| PipelineError::io(path, e)),
        Err(_) => Err(PipelineError::io(path, "the parquet decoder failed on it")),
    }
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
    let (metadata, frame) = decode(path, || {
        let mut reader = ParquetReader::new(std::io::Cursor::new(&bytes));
        let metadata = reader.get_metadata()?.clone();
        reader.finish().map(|frame| (metadata, frame))
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

/// A column of `frame` as floats (integers converted), nulls kept.
pub fn f64_column(frame: &DataFrame, name: &str) -> Result<Vec<Option<f64>>> {
    let column = frame
        .column(name)
        .map_err(|_| PipelineError::stage("table", missing_column(frame, name)))?
        .cast(&DataType::Float64)
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?;
    let values = column
        .f64()
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?
        .iter()
        .collect();
    Ok(values)
}

/// Why `name` is not a column of `frame`: the columns that exist, and the nearest one.
pub fn missing_column(frame: &DataFrame, name: &str) -> String {
    let names: Vec<String> = frame
        .get_column_names()
        .iter()
        .map(|n| n.to_string())
        .collect();
    let nearest = names
        .iter()
        .min_by_key(|n| edit_distance(&n.to_lowercase(), &name.to_lowercase()))
        .filter(|n| {
            edit_distance(&n.to_lowercase(), &name.to_lowercase()) <= 2.max(name.len() / 3)
        });
    let hint = nearest.map_or(String::new(), |n| format!("; did you mean `{n}`?"));
    format!(
        "column `{name}` not found (the table has {}){hint}",
        names.join(", ")
    )
}

/// Levenshtein distance, for naming the column a typo meant.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (row[j + 1] + 1)
                .min(row[j] + 1)
                .min(diagonal + usize::from(ca != *cb));
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// The rows of `frame` where every `(column, value)` of `filter` holds (all rows if empty).
pub fn matching_rows(frame: &DataFrame, filter: &[(String, Match)]) -> Result<Vec<usize>> {
    let mut numbers: Vec<(Vec<Option<f64>>, f64)> = Vec::new();
    let mut texts: Vec<(Vec<Option<String>>, &str)> = Vec::new();
    for (column, m) in filter {
        match m {
            Match::Number(x) => numbers.push((f64_column(frame, column)?, *x)),
            Match::Text(t) => texts.push((str_column(frame, column)?, t)),
        }
    }
    Ok((0..frame.height())
        .filter(|&r| numbers.iter().all(|(col, v)| col[r] == Some(*v)))
        .filter(|&r| texts.iter().all(|(col, t)| col[r].as_deref() == Some(*t)))
        .collect())
}

/// One equality of a row filter (`where = { column = value }`).
#[derive(Debug, Clone, PartialEq)]
pub enum Match {
    /// The number in a numeric column.
    Number(f64),
    /// The string in a string column.
    Text(String),
}

/// A column of `frame` as strings, nulls kept.
pub fn str_column(frame: &DataFrame, name: &str) -> Result<Vec<Option<String>>> {
    let column = frame
        .column(name)
        .map_err(|_| PipelineError::stage("table", missing_column(frame, name)))?;
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
            files: Default::default(),
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
        write(&path, frame.clone(), &manifest()).unwrap();
        let checked = read_checked(&path).unwrap();
        assert!(checked.frame.equals_missing(&frame), "content");
        let mut m = checked.manifest.clone().unwrap();
        m.checksum = None;
        assert_eq!(m.to_json_text(), manifest().to_json_text(), "manifest");
        assert_eq!(checked.integrity, Integrity::Intact);
    }

    /// Every single-bit flip of a sealed table reads as damaged (and is never decoded), or
    /// leaves a table that is still intact: never an abort, a panic or a different table.
    #[test]
    fn every_flipped_bit_is_caught_before_decoding() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.parquet");
        let mut columns = Columns::new();
        columns
            .f64("R", (0..40).map(|i| Some(f64::from(i) * 0.25)).collect())
            .i64("point", (0..40).map(Some).collect())
            .str(
                "failure",
                (0..40)
                    .map(|i| (i % 7 == 0).then(|| format!("f{i}")))
                    .collect(),
            );
        write(&path, columns.into_frame().unwrap(), &manifest()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let flipped = dir.path().join("flipped.parquet");
        for byte in 0..bytes.len() {
            for bit in 0..8 {
                let mut copy = bytes.clone();
                copy[byte] ^= 1 << bit;
                std::fs::write(&flipped, &copy).unwrap();
                let checked = read_checked(&flipped).unwrap();
                assert_eq!(
                    checked.integrity,
                    Integrity::Damaged,
                    "byte {byte} bit {bit}"
                );
                assert!(read(&flipped).is_err());
                assert!(read_manifest(&flipped).is_err());
            }
        }
    }
}
