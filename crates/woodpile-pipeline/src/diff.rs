//! `woodpile diff A B`: two result files, or two result trees, compared column by column.
//!
//! A value pair passes when |a - b| <= abs + rel * max(|a|, |b|) (both nulls, or both NaN,
//! are equal; one null is a difference). Strings must match exactly. Missing files, columns or
//! manifests, damaged tables, changed column types and row-count mismatches are structural
//! problems and always fail. A tolerance for a column no compared table has is an error: it is
//! a typo that would otherwise silently compare that column at the default tolerance; so is a
//! tolerance for a text column (text compares exactly: ignore it instead).
//!
//! Key columns (`scene_key`) are content hashes of what was simulated, so they differ after
//! any parameter change: they are ignored unless asked for, as are the columns named in
//! `ignore`. The report also lists, first, which parameters differ between the two tables'
//! manifests, so that a difference can be read against its cause.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use polars::prelude::DataFrame;

use crate::error::{PipelineError, Result};
use crate::table::{f64_column, read_checked, str_column, Integrity, DAMAGED};

/// Absolute and relative tolerance of one column.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tolerance {
    /// Absolute part.
    pub abs: f64,
    /// Relative part.
    pub rel: f64,
}

/// Tolerances: a default and per-column overrides, and the columns not compared.
#[derive(Debug, Clone, Default)]
pub struct DiffOptions {
    /// For every column not named in `columns`.
    pub default: Tolerance,
    /// Per column name.
    pub columns: BTreeMap<String, Tolerance>,
    /// Columns not compared.
    pub ignore: BTreeSet<String>,
    /// Compare the key columns ([`KEY_COLUMNS`]) too.
    pub compare_keys: bool,
    /// Run on every file that is not a sealed woodpile table before it is decoded here: a
    /// foreign file can make the parquet decoder abort the process (an allocation of 2^61
    /// bytes from a damaged page header), which no error handling here can catch. The CLI
    /// decodes such a file in a child process first. The error is the reason.
    pub probe: Option<Probe>,
}

/// A check of a file before it is decoded in this process: the reason it cannot be, if any.
pub type Probe = fn(&Path) -> std::result::Result<(), String>;

/// Columns that hold content hashes: they differ whenever the parameters do.
pub const KEY_COLUMNS: &[&str] = &["scene_key"];

/// One compared value pair.
#[derive(Debug, Clone, PartialEq)]
pub struct Difference {
    /// File (relative to the compared trees).
    pub file: String,
    /// Column.
    pub column: String,
    /// Row.
    pub row: usize,
    /// Value in A, as text.
    pub a: String,
    /// Value in B, as text.
    pub b: String,
    /// |a - b| (infinite for a null against a value, or unequal strings).
    pub abs: f64,
    /// |a - b| / max(|a|, |b|).
    pub rel: f64,
    /// |a - b| over what the tolerance allows: > 1 fails.
    pub excess: f64,
}

/// The comparison's outcome.
#[derive(Debug, Clone, Default)]
pub struct DiffReport {
    /// Files compared.
    pub files: usize,
    /// Values compared.
    pub values: u64,
    /// Values beyond tolerance.
    pub beyond: u64,
    /// Structural problems (missing files, columns or manifests, damaged tables, different
    /// column types or row counts).
    pub problems: Vec<String>,
    /// Every column name seen in the compared tables.
    pub columns: BTreeSet<String>,
    /// The largest difference of every (file, column) that differs, those beyond tolerance
    /// first, each group by the size of the difference.
    pub worst: Vec<Difference>,
    /// Parameters that differ between the two tables' manifests, `file: path: a -> b`.
    pub parameters: Vec<String>,
    /// Columns that were not compared (ignored, or keys).
    pub skipped: BTreeSet<String>,
}

impl DiffReport {
    /// Whether A and B agree within tolerance.
    pub fn agrees(&self) -> bool {
        self.beyond == 0 && self.problems.is_empty()
    }
}

/// Compares `a` and `b`: two parquet files, or two directories of them (the point cache
/// under `points/` and shard parts under `parts/` are skipped: they are inputs to results, not
/// results).
pub fn diff(a: &Path, b: &Path, options: &DiffOptions) -> Result<DiffReport> {
    let mut report = DiffReport::default();
    if a.is_dir() && b.is_dir() {
        let (fa, fb) = (parquet_files(a)?, parquet_files(b)?);
        for name in fa.keys().filter(|n| !fb.contains_key(*n)) {
            report
                .problems
                .push(format!("{name}: only in {}", a.display()));
        }
        for name in fb.keys().filter(|n| !fa.contains_key(*n)) {
            report
                .problems
                .push(format!("{name}: only in {}", b.display()));
        }
        if fa.is_empty() && fb.is_empty() {
            report.problems.push(format!(
                "no tables in {} or {}: nothing to compare",
                a.display(),
                b.display()
            ));
        }
        for (name, pa) in &fa {
            if let Some(pb) = fb.get(name) {
                compare_files(name, pa, pb, options, &mut report)?;
            }
        }
    } else if a.is_file() && b.is_file() {
        let name = a
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        compare_files(&name, a, b, options, &mut report)?;
    } else {
        return Err(PipelineError::io(
            if a.exists() { b } else { a },
            "expected two files or two directories that exist",
        ));
    }
    if let Some(unknown) = options
        .columns
        .keys()
        .chain(&options.ignore)
        .find(|c| !report.columns.contains(*c))
    {
        return Err(PipelineError::io(
            a,
            format!("a tolerance or --ignore is given for column `{unknown}`, which no compared table has"),
        ));
    }
    // Beyond tolerance first; within each group the largest differences first.
    report.worst.sort_by(|x, y| {
        (y.excess > 1.0)
            .cmp(&(x.excess > 1.0))
            .then(y.abs.total_cmp(&x.abs))
            .then(y.rel.total_cmp(&x.rel))
    });
    Ok(report)
}

fn parquet_files(root: &Path) -> Result<BTreeMap<String, PathBuf>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, PathBuf>) -> Result<()> {
        let entries = std::fs::read_dir(dir).map_err(|e| PipelineError::io(dir, e))?;
        for entry in entries.flatten() {
            let path = entry.path();
            let rel = path
                .strip_prefix(root)
                .unwrap_or(&path)
                .to_string_lossy()
                .into_owned();
            // The entry's own type: a symbolic link to a folder is not followed (a link to
            // `.` would make the walk endless).
            let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
            if is_dir {
                if rel != "points" && rel != "parts" {
                    walk(root, &path, out)?;
                }
            } else if path.extension().is_some_and(|x| x == "parquet") {
                out.insert(rel, path);
            }
        }
        Ok(())
    }
    let mut out = BTreeMap::new();
    walk(root, root, &mut out)?;
    Ok(out)
}

/// Compares the tables `a` and `b` (named `name` in the report): their integrity and
/// manifests, their parameters, their columns, then every shared column value by value.
fn compare_files(
    name: &str,
    a: &Path,
    b: &Path,
    options: &DiffOptions,
    report: &mut DiffReport,
) -> Result<()> {
    if let Some(probe) = options.probe {
        for path in [a, b] {
            if !crate::table::is_sealed(path)? {
                probe(path).map_err(|reason| PipelineError::io(path, reason))?;
            }
        }
    }
    let (ca, cb) = (read_checked(a)?, read_checked(b)?);
    for (checked, path) in [(&ca, a), (&cb, b)] {
        if checked.manifest.is_none() {
            report.problems.push(format!(
                "{name}: no `woodpile` manifest in {}",
                path.display()
            ));
        } else if checked.integrity == Integrity::Damaged {
            report
                .problems
                .push(format!("{name}: {} {DAMAGED}", path.display()));
        }
    }
    if let (Some(ma), Some(mb)) = (&ca.manifest, &cb.manifest) {
        for change in woodpile_files::key::changed_paths(&ma.params, &mb.params) {
            report.parameters.push(format!("{name}: {change}"));
        }
    }
    let pair = Pair {
        name,
        a: (&ca.frame, a),
        b: (&cb.frame, b),
    };
    report.files += 1;
    let Some(shared) = pair.shared_columns(report) else {
        return Ok(());
    };
    for column in shared {
        let key = KEY_COLUMNS.contains(&column.as_str()) && !options.compare_keys;
        if key || options.ignore.contains(&column) {
            report.skipped.insert(column);
            continue;
        }
        pair.compare_column(&column, options, report)?;
    }
    Ok(())
}

/// Two tables being compared, each with the path it came from.
struct Pair<'a> {
    name: &'a str,
    a: (&'a DataFrame, &'a Path),
    b: (&'a DataFrame, &'a Path),
}

impl Pair<'_> {
    /// The columns both tables have, after reporting those only one has; `None` when their
    /// heights differ (reported too), so that no row is compared with another's.
    fn shared_columns(&self, report: &mut DiffReport) -> Option<Vec<String>> {
        let names = |f: &DataFrame| {
            f.get_column_names()
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
        };
        let (ca, cb) = (names(self.a.0), names(self.b.0));
        report.columns.extend(ca.iter().chain(&cb).cloned());
        for (mine, theirs, path) in [(&ca, &cb, self.a.1), (&cb, &ca, self.b.1)] {
            for c in mine.iter().filter(|c| !theirs.contains(c)) {
                report.problems.push(format!(
                    "{}: column `{c}` only in {}",
                    self.name,
                    path.display()
                ));
            }
        }
        if self.a.0.height() != self.b.0.height() {
            report.problems.push(format!(
                "{}: {} rows against {}",
                self.name,
                self.a.0.height(),
                self.b.0.height()
            ));
            return None;
        }
        Some(ca.into_iter().filter(|c| cb.contains(c)).collect())
    }

    /// One shared column: its type in both, then its values (numbers within the column's
    /// tolerance, text exactly); the worst difference goes into the report.
    fn compare_column(
        &self,
        column: &str,
        options: &DiffOptions,
        report: &mut DiffReport,
    ) -> Result<()> {
        let (fa, fb) = (self.a.0, self.b.0);
        let dtype = |f: &DataFrame| f.column(column).map(|c| c.dtype().clone()).ok();
        let (ta, tb) = (dtype(fa), dtype(fb));
        if ta != tb {
            let show =
                |t: Option<polars::prelude::DataType>| t.map_or("?".into(), |t| t.to_string());
            report.problems.push(format!(
                "{}: column `{column}` is {} in {} but {} in {}",
                self.name,
                show(ta),
                self.a.1.display(),
                show(tb),
                self.b.1.display()
            ));
        }
        let numeric = |f: &DataFrame| {
            f.column(column)
                .map(|c| c.dtype().is_primitive_numeric())
                .unwrap_or(false)
        };
        let mut worst = Worst::default();
        if numeric(fa) && numeric(fb) {
            let tol = options
                .columns
                .get(column)
                .copied()
                .unwrap_or(options.default);
            let (va, vb) = (f64_column(fa, column)?, f64_column(fb, column)?);
            for (row, (x, y)) in va.iter().zip(&vb).enumerate() {
                worst.consider(row, compare_numbers(*x, *y, tol), report);
            }
        } else {
            if options.columns.contains_key(column) {
                return Err(PipelineError::io(
                    self.name,
                    format!("column `{column}` holds text, which compares exactly: drop its --tol (or --ignore it)"),
                ));
            }
            let (va, vb) = (self.text(fa, column)?, self.text(fb, column)?);
            for (row, (x, y)) in va.iter().zip(&vb).enumerate() {
                worst.consider(row, compare_text(x, y), report);
            }
        }
        report.worst.extend(worst.0.map(|d| Difference {
            file: self.name.into(),
            column: column.to_string(),
            ..d
        }));
        Ok(())
    }

    /// A column of `f` as text, row by row (a list as its values' text).
    fn text(&self, f: &DataFrame, column: &str) -> Result<Vec<Option<String>>> {
        let c = f
            .column(column)
            .map_err(|e| PipelineError::io(self.name, e))?;
        if matches!(c.dtype(), polars::prelude::DataType::List(_)) {
            return Ok((0..c.len())
                .map(|i| c.get(i).ok().map(|v| v.to_string()))
                .collect());
        }
        let c = c
            .cast(&polars::prelude::DataType::String)
            .map_err(|e| PipelineError::io(self.name, e))?;
        str_column(
            &DataFrame::new_infer_height(vec![c]).map_err(|e| PipelineError::io(self.name, e))?,
            column,
        )
    }
}

/// The largest difference of a column so far: beyond tolerance first, then by size.
#[derive(Default)]
struct Worst(Option<Difference>);

impl Worst {
    /// Counts the value at `row` (and, when it differs beyond tolerance, one beyond), and
    /// keeps its difference if it is the worst yet.
    fn consider(&mut self, row: usize, d: Option<Difference>, report: &mut DiffReport) {
        report.values += 1;
        let Some(d) = d else { return };
        if d.excess > 1.0 {
            report.beyond += 1;
        }
        let larger =
            |w: &Difference| (d.excess > 1.0, d.abs, d.rel) > (w.excess > 1.0, w.abs, w.rel);
        if self.0.as_ref().is_none_or(larger) {
            self.0 = Some(Difference { row, ..d });
        }
    }
}

/// `None` when equal; otherwise the difference of two texts, infinite (file, column and row
/// left blank).
fn compare_text(x: &Option<String>, y: &Option<String>) -> Option<Difference> {
    let show = |v: &Option<String>| v.clone().unwrap_or_else(|| "null".into());
    (x != y).then(|| Difference {
        file: String::new(),
        column: String::new(),
        row: 0,
        a: show(x),
        b: show(y),
        abs: f64::INFINITY,
        rel: f64::INFINITY,
        excess: f64::INFINITY,
    })
}

/// `None` when equal; otherwise the difference (file, column and row left blank).
fn compare_numbers(x: Option<f64>, y: Option<f64>, tol: Tolerance) -> Option<Difference> {
    let show = |v: Option<f64>| v.map_or("null".to_string(), |v| format!("{v:e}"));
    let blank = |abs: f64, rel: f64, excess: f64| Difference {
        file: String::new(),
        column: String::new(),
        row: 0,
        a: show(x),
        b: show(y),
        abs,
        rel,
        excess,
    };
    match (x, y) {
        (None, None) => None,
        (Some(a), Some(b)) if a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()) => None,
        (Some(a), Some(b)) => {
            let abs = (a - b).abs();
            let scale = a.abs().max(b.abs());
            let rel = if scale > 0.0 { abs / scale } else { 0.0 };
            let allowed = tol.abs + tol.rel * scale;
            let excess = if allowed > 0.0 {
                abs / allowed
            } else if abs > 0.0 {
                f64::INFINITY
            } else {
                0.0
            };
            let excess = if abs.is_nan() { f64::INFINITY } else { excess };
            Some(blank(abs, rel, excess))
        }
        _ => Some(blank(f64::INFINITY, f64::INFINITY, f64::INFINITY)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerance_is_absolute_plus_relative() {
        let tol = Tolerance {
            abs: 1e-9,
            rel: 1e-6,
        };
        assert!(compare_numbers(Some(1.0), Some(1.0), Tolerance::default()).is_none());
        assert!(compare_numbers(None, None, Tolerance::default()).is_none());
        assert!(compare_numbers(Some(f64::NAN), Some(f64::NAN), Tolerance::default()).is_none());
        let within = compare_numbers(Some(1.0), Some(1.0 + 5e-7), tol).unwrap();
        assert!(within.excess < 1.0);
        let beyond = compare_numbers(Some(1.0), Some(1.0 + 5e-6), tol).unwrap();
        assert!(beyond.excess > 1.0);
        assert!(
            compare_numbers(Some(0.0), Some(1e-300), Tolerance::default())
                .unwrap()
                .excess
                > 1.0
        );
        assert_eq!(
            compare_numbers(None, Some(0.0), tol).unwrap().excess,
            f64::INFINITY
        );
    }
}
