//! `kind = "report"`: the reproduction report. Every number the paper quotes, next to ours and
//! the difference; for each, the conventions searched (read-out time, boundaries, region,
//! striker site, stated against derived parameters), what each gives, whether it reproduces the
//! quoted number, and how sensitive the number is. Written as `REPRODUCTION.md` (beside
//! `results/`) and as the stage's parquet table, one row per quote and convention.
//!
//! ```toml
//! kind = "report"
//! inputs = ["f7_fine", "f7_readout_sweep"]   # every stage a source reads
//! markdown = "REPRODUCTION.md"               # relative to the directory holding results/
//! title = "Reproduction report"
//! preamble = "..."
//!
//! [[quote]]
//! figure = "F7"
//! quantity = "fine-grid optimum E_tr"
//! paper = 0.2112                  # or paper_text = "..." with an optional range = [lo, hi]
//! agree = 0.00005                 # |ours - paper| <= agree counts as reproducing it
//! as_run = "read at t = 150"
//! ours = { stage = "f7_fine", column = "E_tr", max = "E_tr", locate = ["eps1", "eps2"] }
//! note = "..."
//! [[quote.convention]]
//! name = "read-out time t"
//! source = { stage = "f7_readout_sweep", column = "E_tr", where = { eps1 = 0.67 }, scan = "t" }
//! ```
//!
//! A source reads one number from a stage's output:
//! - `column` with `where` (numbers or strings, equality): exactly one row, or with
//!   `max = "col"` the row where `col` is largest (its `locate` columns are reported);
//! - `manifest = "/summary/key"`: a JSON pointer into the stage's manifest;
//! - `scan = "col"` (optionally `scan_range = [lo, hi]`): the value as a function of `col` (with `max`, the largest over the other
//!   rows at each `col`): where it comes within `agree` of the paper's number, and its slope
//!   there, so the report says which read-out time reproduces a number and how sensitive it is.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use polars::prelude::DataFrame;
use serde_json::json;

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::layout::output_path;
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::{
    self, f64_column, matching_rows, rows_frame, str_column, Cell, Row,
};
use woodpile_pipeline::Output;

/// A parsed report stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The Markdown file, relative to the directory holding `results/`.
    pub markdown: String,
    /// Its title.
    pub title: String,
    /// Text before the tables.
    pub preamble: String,
    /// The quoted numbers.
    pub quotes: Vec<Quote>,
}

/// One number (or statement) the paper makes.
#[derive(Debug, Clone, PartialEq)]
pub struct Quote {
    /// Figure id, e.g. `F7`.
    pub figure: String,
    /// What the number is.
    pub quantity: String,
    /// What the paper says.
    pub paper: Paper,
    /// Our number as the pipeline runs it.
    pub ours: Source,
    /// The conventions of `ours`, in words.
    pub as_run: String,
    /// Explanation for the reader.
    pub note: String,
    /// The alternatives searched.
    pub conventions: Vec<Convention>,
}

/// The paper's side of a quote.
#[derive(Debug, Clone, PartialEq)]
pub enum Paper {
    /// A number, reproduced when within `agree`.
    Value {
        /// The quoted number.
        value: f64,
        /// Agreement tolerance (half a unit of the quoted number's last digit, or the paper's
        /// "about").
        agree: f64,
    },
    /// A statement; reproduced when the value lies in `range`, if given.
    Text {
        /// The statement.
        text: String,
        /// The range that satisfies it.
        range: Option<[f64; 2]>,
    },
}

/// One alternative convention and where its number comes from.
#[derive(Debug, Clone, PartialEq)]
pub struct Convention {
    /// The convention, in words.
    pub name: String,
    /// Its number.
    pub source: Source,
}

/// Where a number is read.
#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    /// The stage whose output is read.
    pub stage: String,
    /// What is read.
    pub read: Read,
    /// Row filter.
    pub filter: Vec<(String, Match)>,
    /// Take the row where this column is largest.
    pub max: Option<String>,
    /// Columns reported as the location of the row read.
    pub locate: Vec<String>,
    /// Scan this column.
    pub scan: Option<String>,
    /// Only scan values in this inclusive range.
    pub scan_range: Option<[f64; 2]>,
}

/// A column or a manifest entry.
#[derive(Debug, Clone, PartialEq)]
pub enum Read {
    /// A table column.
    Column(String),
    /// A JSON pointer into the manifest.
    Manifest(String),
}

/// One equality of a row filter.
#[derive(Debug, Clone, PartialEq)]
pub enum Match {
    /// Numeric equality.
    Number(f64),
    /// String equality.
    Text(String),
}

/// What a source measured.
#[derive(Debug, Clone, PartialEq)]
struct Measured {
    value: f64,
    location: String,
    scan: Option<Scanned>,
    /// Why the number could not be read (a failed fit upstream, say): shown in its place.
    failure: Option<String>,
}

impl Measured {
    fn failed(reason: String) -> Measured {
        Measured {
            value: f64::NAN,
            location: String::new(),
            scan: None,
            failure: Some(reason),
        }
    }
}

/// Where along a scan the value meets the paper's number.
#[derive(Debug, Clone, PartialEq)]
struct Scanned {
    /// The scanned column.
    column: String,
    /// Runs of consecutive scan values within `agree` of the paper's number (first, last).
    runs: Vec<(f64, f64)>,
    /// The scan value where the number comes closest.
    closest: f64,
    /// |d value / d scan| at the closest approach.
    slope: f64,
}

impl Report {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Report> {
        let markdown: String = fields.required("markdown")?;
        check_markdown_path(&markdown).map_err(|reason| fields.error("markdown", reason))?;
        // One spelling per file (`d//x.md`, `./d/x.md` and `d/x.md` are one file), so that the
        // one-writer check compares files, not strings.
        let markdown = Path::new(&markdown)
            .components()
            .collect::<PathBuf>()
            .to_string_lossy()
            .into_owned();
        let title: String = fields.required("title")?;
        let preamble: String = fields.optional("preamble")?.unwrap_or_default();
        let Some(toml::Value::Array(entries)) = fields.take("quote") else {
            return Err(fields.error("quote", "expected one or more [[quote]] tables"));
        };
        let mut quotes = Vec::with_capacity(entries.len());
        for (i, entry) in entries.into_iter().enumerate() {
            let key = format!("quote[{i}]");
            let toml::Value::Table(table) = entry else {
                return Err(fields.error(&key, "expected a table"));
            };
            quotes.push(parse_quote(fields.nested(&key, table))?);
        }
        if quotes.is_empty() {
            return Err(fields.error("quote", "expected one or more [[quote]] tables"));
        }
        Ok(Report {
            markdown,
            title,
            preamble,
            quotes,
        })
    }

    /// Every source with its dotted key, for the pipeline's input check.
    pub fn sources(&self) -> Vec<(String, &Source)> {
        let mut out = Vec::new();
        for (i, q) in self.quotes.iter().enumerate() {
            out.push((format!("quote[{i}].ours.stage"), &q.ours));
            for (j, c) in q.conventions.iter().enumerate() {
                out.push((
                    format!("quote[{i}].convention[{j}].source.stage"),
                    &c.source,
                ));
            }
        }
        out
    }

    /// Refuses to replace a file at `path` that this stage did not write: a report never
    /// overwrites a hand-written file. Its own are those its previous output's manifest names,
    /// and those that carry its generated mark near the top (what a run killed between the
    /// Markdown and the table, or a damaged table, leaves: never a stuck stage).
    fn check_owned(&self, stage: &str, path: &Path, results: &Path) -> Result<()> {
        // Inside the tree means inside it on disk too: no folder on the way may be a
        // symbolic link (`docs -> /elsewhere`).
        let root = results.parent().unwrap_or_else(|| Path::new(""));
        let mut folder = root.to_path_buf();
        for part in Path::new(&self.markdown)
            .parent()
            .into_iter()
            .flat_map(Path::components)
        {
            folder.push(part);
            if std::fs::symlink_metadata(&folder).is_ok_and(|m| m.file_type().is_symlink()) {
                return Err(PipelineError::stage(
                    stage,
                    format!(
                        "`markdown = \"{}\"`: {} is a symbolic link; a report writes only inside the project",
                        self.markdown,
                        folder.display()
                    ),
                ));
            }
        }
        if std::fs::symlink_metadata(path).is_err() {
            return Ok(());
        }
        let previous = table::read_manifest(&output_path(results, stage))
            .ok()
            .flatten();
        let named = previous.is_some_and(|m| m.summary["markdown"] == self.markdown.as_str());
        let marked = woodpile_pipeline::regular::read(path, 1 << 26)
            .ok()
            .and_then(|bytes| {
                let head = &bytes[..bytes.len().min(4096)];
                String::from_utf8_lossy(head)
                    .lines()
                    .take(5)
                    .any(|line| line == generated_mark(stage))
                    .then_some(())
            })
            .is_some();
        if named || marked {
            Ok(())
        } else {
            Err(PipelineError::stage(
                stage,
                format!(
                    "`markdown = \"{}\"` would overwrite {}, which this stage did not write; move that file or choose another name",
                    self.markdown,
                    path.display()
                ),
            ))
        }
    }

    /// The Markdown file for outputs under `results`.
    pub fn markdown_path(&self, results: &Path) -> PathBuf {
        woodpile_pipeline::layout::markdown_path(results, &self.markdown)
    }

    pub(crate) fn run(&self, stage: &str, results: &Path) -> Result<Output> {
        let mut reader = Reader {
            results,
            frames: HashMap::new(),
        };
        let mut evaluated = Vec::with_capacity(self.quotes.len());
        let mut failures = Vec::new();
        for (i, q) in self.quotes.iter().enumerate() {
            // A number that cannot be read is reported in its place, and the run fails.
            let mut read = |source: &Source, what: &str| match reader.measure(source, &q.paper) {
                Ok(m) => m,
                Err(e) => {
                    let reason = e.to_string();
                    failures.push(format!(
                        "quote[{i}] ({} {}), {what}: {reason}",
                        q.figure, q.quantity
                    ));
                    Measured::failed(reason)
                }
            };
            let ours = read(&q.ours, "ours");
            let mut conventions = Vec::with_capacity(q.conventions.len());
            for (j, c) in q.conventions.iter().enumerate() {
                let m = read(&c.source, &format!("convention[{j}]"));
                conventions.push((c.name.clone(), m));
            }
            evaluated.push((ours, conventions));
        }
        let text = markdown(stage, self, &evaluated);
        let path = self.markdown_path(results);
        self.check_owned(stage, &path, results)?;
        woodpile_pipeline::atomic::write(&path, text.as_bytes())?;
        let reproduced = evaluated
            .iter()
            .zip(&self.quotes)
            .filter(|((ours, _), q)| reproduces(&q.paper, ours) == Some(true))
            .count();
        let by_some = evaluated
            .iter()
            .zip(&self.quotes)
            .filter(|((ours, cs), q)| {
                reproduces(&q.paper, ours) == Some(true)
                    || cs
                        .iter()
                        .any(|(_, m)| reproduces(&q.paper, m) == Some(true))
            })
            .count();
        let rows: Vec<QuoteRow> = self
            .quotes
            .iter()
            .zip(&evaluated)
            .flat_map(|(q, (ours, conventions))| {
                std::iter::once(QuoteRow {
                    quote: q,
                    convention: format!("as run: {}", q.as_run),
                    measured: ours,
                })
                .chain(conventions.iter().map(move |(name, m)| QuoteRow {
                    quote: q,
                    convention: name.clone(),
                    measured: m,
                }))
            })
            .collect();
        Ok(Output {
            frame: rows_frame(&rows)?,
            summary: json!({
                "quotes": self.quotes.len(),
                "reproduced_as_run": reproduced,
                "reproduced_by_some_convention": by_some,
                "failed": failures.len(),
                "markdown": self.markdown,
            }),
            failures,
        })
    }
}

/// A report's Markdown must stay inside the tree that holds `results/` (a relative path of
/// plain names, no `..`; `.` and repeated slashes are dropped) and be Markdown: any other extension could overwrite another stage's
/// table or figure.
fn check_markdown_path(markdown: &str) -> std::result::Result<(), String> {
    let path = Path::new(markdown);
    let plain = path.components().all(|c| {
        matches!(
            c,
            std::path::Component::Normal(_) | std::path::Component::CurDir
        )
    }) && path
        .components()
        .any(|c| matches!(c, std::path::Component::Normal(_)));
    if markdown.is_empty() || !plain {
        return Err(format!(
            "`{markdown}` must be a relative path inside the project (no `..`, not absolute)"
        ));
    }
    if path.extension().is_none_or(|e| e != "md") {
        return Err(format!(
            "`{markdown}` must end in `.md`: a report writes Markdown, and another name could replace a stage's table or figure"
        ));
    }
    Ok(())
}

fn parse_quote(mut f: Fields<'_>) -> Result<Quote> {
    let figure: String = f.required("figure")?;
    let quantity: String = f.required("quantity")?;
    let paper = match (
        f.optional::<f64>("paper")?,
        f.optional::<String>("paper_text")?,
    ) {
        (Some(value), None) => Paper::Value {
            value,
            agree: f.required::<f64>("agree")?.abs(),
        },
        (None, Some(text)) => Paper::Text {
            text,
            range: match f.optional::<Vec<f64>>("range")?.as_deref() {
                None => None,
                Some(&[lo, hi]) if lo <= hi => Some([lo, hi]),
                Some(_) => return Err(f.error("range", "expected [lo, hi] with lo <= hi")),
            },
        },
        _ => {
            return Err(f.error(
                "paper",
                "give exactly one of `paper` (a number) and `paper_text`",
            ))
        }
    };
    let as_run: String = f.required("as_run")?;
    let note: String = f.optional("note")?.unwrap_or_default();
    let ours_table: toml::Table = f.required("ours")?;
    let ours = parse_source(f.nested("ours", ours_table))?;
    let mut conventions = Vec::new();
    if let Some(value) = f.take("convention") {
        let toml::Value::Array(entries) = value else {
            return Err(f.error("convention", "expected [[quote.convention]] tables"));
        };
        for (j, entry) in entries.into_iter().enumerate() {
            let key = format!("convention[{j}]");
            let toml::Value::Table(table) = entry else {
                return Err(f.error(&key, "expected a table"));
            };
            let mut c = f.nested(&key, table);
            let name: String = c.required("name")?;
            let source_table: toml::Table = c.required("source")?;
            let source = parse_source(c.nested("source", source_table))?;
            c.finish()?;
            conventions.push(Convention { name, source });
        }
    }
    f.finish()?;
    Ok(Quote {
        figure,
        quantity,
        paper,
        ours,
        as_run,
        note,
        conventions,
    })
}

fn parse_source(mut f: Fields<'_>) -> Result<Source> {
    let stage: String = f.required("stage")?;
    let read = match (
        f.optional::<String>("column")?,
        f.optional::<String>("manifest")?,
    ) {
        (Some(c), None) => Read::Column(c),
        (None, Some(p)) if p.starts_with('/') => Read::Manifest(p),
        (None, Some(_)) => {
            return Err(f.error(
                "manifest",
                "expected a JSON pointer such as \"/summary/rms_error\"",
            ))
        }
        _ => return Err(f.error("column", "give exactly one of `column` and `manifest`")),
    };
    let mut filter = Vec::new();
    if let Some(table) = f.optional::<toml::Table>("where")? {
        for (column, value) in table {
            let m = match value {
                toml::Value::Float(x) => Match::Number(x),
                toml::Value::Integer(i) => Match::Number(i as f64),
                toml::Value::String(s) => Match::Text(s),
                _ => {
                    return Err(f.error(&format!("where.{column}"), "expected a number or a string"))
                }
            };
            filter.push((column, m));
        }
    }
    let max = f.optional::<String>("max")?;
    let locate = f.optional::<Vec<String>>("locate")?.unwrap_or_default();
    let scan = f.optional::<String>("scan")?;
    let scan_range = match f.optional::<Vec<f64>>("scan_range")?.as_deref() {
        None => None,
        Some(&[lo, hi]) if lo <= hi && scan.is_some() => Some([lo, hi]),
        Some(&[_, _]) if scan.is_none() => return Err(f.error("scan_range", "needs `scan`")),
        Some(_) => return Err(f.error("scan_range", "expected [lo, hi] with lo <= hi")),
    };
    if matches!(read, Read::Manifest(_))
        && (!filter.is_empty() || max.is_some() || scan.is_some() || !locate.is_empty())
    {
        return Err(f.error(
            "manifest",
            "a manifest entry takes no `where`, `max`, `locate` or `scan`",
        ));
    }
    f.finish()?;
    Ok(Source {
        stage,
        read,
        filter,
        max,
        locate,
        scan,
        scan_range,
    })
}

/// Reads stage outputs once each.
struct Reader<'a> {
    results: &'a Path,
    frames: HashMap<String, DataFrame>,
}

impl Reader<'_> {
    fn frame(&mut self, stage: &str) -> Result<&DataFrame> {
        if !self.frames.contains_key(stage) {
            let frame = table::read(&output_path(self.results, stage))?;
            self.frames.insert(stage.to_string(), frame);
        }
        Ok(&self.frames[stage])
    }

    fn measure(&mut self, source: &Source, paper: &Paper) -> Result<Measured> {
        let fail = |reason: String| PipelineError::stage(&source.stage, reason);
        let column = match &source.read {
            Read::Manifest(pointer) => {
                let manifest = table::read_manifest(&output_path(self.results, &source.stage))?
                    .ok_or_else(|| fail("no manifest".into()))?;
                let value = serde_json::to_value(&manifest)
                    .ok()
                    .and_then(|v| v.pointer(pointer).and_then(|x| x.as_f64()))
                    .ok_or_else(|| fail(format!("manifest has no number at `{pointer}`")))?;
                return Ok(Measured {
                    value,
                    location: String::new(),
                    scan: None,
                    failure: None,
                });
            }
            Read::Column(c) => c.clone(),
        };
        let frame = self.frame(&source.stage)?;
        let rows = filtered_rows(frame, &source.filter)?;
        let values = f64_column(frame, &column)?;
        let ranking = match &source.max {
            Some(m) => Some(f64_column(frame, m)?),
            None => None,
        };
        let locate: Vec<(String, Vec<Option<f64>>)> = source
            .locate
            .iter()
            .map(|c| Ok((c.clone(), f64_column(frame, c)?)))
            .collect::<Result<_>>()?;
        let location = |r: usize| -> String {
            locate
                .iter()
                .map(|(c, v)| format!("{c} = {}", v[r].map_or("null".into(), fmt)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        // The row read within a set of candidate rows: the only one, or the largest.
        let pick = |candidates: &[usize]| -> std::result::Result<usize, String> {
            match &ranking {
                Some(rank) => candidates
                    .iter()
                    .copied()
                    .filter_map(|r| rank[r].filter(|v| v.is_finite()).map(|v| (r, v)))
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(r, _)| r)
                    .ok_or_else(|| "no finite row to maximise".to_string()),
                None => match candidates {
                    [r] => Ok(*r),
                    _ => Err(format!(
                        "{} rows match where exactly one was expected (add `where` or `max`)",
                        candidates.len()
                    )),
                },
            }
        };
        // A row that failed upstream (a fit that did not converge) says why in `failure`.
        let failures = str_column(frame, "failure").ok();
        let value_at = |r: usize| -> std::result::Result<f64, String> {
            values[r].filter(|v| v.is_finite()).ok_or_else(|| {
                match failures.as_ref().and_then(|f| f[r].clone()) {
                    Some(reason) => format!("the row read failed upstream: {reason}"),
                    None => format!("column `{column}` is null or not finite in the row read"),
                }
            })
        };
        let Some(scan_column) = &source.scan else {
            let r = pick(&rows).map_err(fail)?;
            return Ok(Measured {
                value: value_at(r).map_err(fail)?,
                location: location(r),
                scan: None,
                failure: None,
            });
        };
        let scan_values = f64_column(frame, scan_column)?;
        let mut groups: Vec<(f64, Vec<usize>)> = Vec::new();
        let mut sorted: Vec<(usize, f64)> = rows
            .iter()
            .filter_map(|&r| scan_values[r].filter(|s| s.is_finite()).map(|s| (r, s)))
            .filter(|&(_, s)| {
                source
                    .scan_range
                    .is_none_or(|[lo, hi]| (lo..=hi).contains(&s))
            })
            .collect();
        sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
        for (r, s) in sorted {
            match groups.last_mut() {
                Some((last, members)) if *last == s => members.push(r),
                _ => groups.push((s, vec![r])),
            }
        }
        let series: Vec<(f64, f64, usize)> = groups
            .iter()
            .map(|(s, members)| {
                let r = pick(members)?;
                Ok((*s, value_at(r)?, r))
            })
            .collect::<std::result::Result<_, String>>()
            .map_err(|e| fail(format!("scanning `{scan_column}`: {e}")))?;
        let target = match paper {
            Paper::Value { value, .. } => *value,
            Paper::Text {
                range: Some([lo, hi]),
                ..
            } => 0.5 * (lo + hi),
            Paper::Text { range: None, .. } => {
                return Err(fail(
                    "a scan needs a paper number or range to aim at".into(),
                ))
            }
        };
        let within = |v: f64| match paper {
            Paper::Value { value, agree } => (v - value).abs() <= *agree,
            Paper::Text {
                range: Some([lo, hi]),
                ..
            } => (*lo..=*hi).contains(&v),
            Paper::Text { range: None, .. } => false,
        };
        let best = (0..series.len())
            .min_by(|&a, &b| {
                (series[a].1 - target)
                    .abs()
                    .total_cmp(&(series[b].1 - target).abs())
            })
            .ok_or_else(|| fail(format!("no rows to scan over `{scan_column}`")))?;
        let mut runs: Vec<(f64, f64)> = Vec::new();
        let mut previous_hit = false;
        for &(s, v, _) in &series {
            let hit = within(v);
            match runs.last_mut() {
                Some(run) if hit && previous_hit => run.1 = s,
                _ if hit => runs.push((s, s)),
                _ => {}
            }
            previous_hit = hit;
        }
        let slope_between = |a: usize, b: usize| {
            let ds = series[b].0 - series[a].0;
            if ds > 0.0 {
                ((series[b].1 - series[a].1) / ds).abs()
            } else {
                0.0
            }
        };
        let mut slope: f64 = 0.0;
        if best > 0 {
            slope = slope.max(slope_between(best - 1, best));
        }
        if best + 1 < series.len() {
            slope = slope.max(slope_between(best, best + 1));
        }
        let (s, value, r) = series[best];
        let mut where_text = format!("{scan_column} = {}", fmt(s));
        let located = location(r);
        if !located.is_empty() {
            where_text = format!("{where_text}: {located}");
        }
        Ok(Measured {
            value,
            location: where_text,
            scan: Some(Scanned {
                column: scan_column.clone(),
                runs,
                closest: s,
                slope,
            }),
            failure: None,
        })
    }
}

/// The rows where every equality holds: the numeric ones by [`matching_rows`] (the filter of
/// fit and render), then the string ones.
fn filtered_rows(frame: &DataFrame, filter: &[(String, Match)]) -> Result<Vec<usize>> {
    let numeric: Vec<(String, f64)> = filter
        .iter()
        .filter_map(|(c, m)| match m {
            Match::Number(x) => Some((c.clone(), *x)),
            Match::Text(_) => None,
        })
        .collect();
    let mut rows = matching_rows(frame, &numeric)?;
    for (column, m) in filter {
        if let Match::Text(text) = m {
            let values = str_column(frame, column)?;
            rows.retain(|&r| values[r].as_deref() == Some(text.as_str()));
        }
    }
    Ok(rows)
}

/// Whether `m` reproduces the paper's number (None for a statement without a range).
fn reproduces(paper: &Paper, m: &Measured) -> Option<bool> {
    if m.failure.is_some() {
        return None;
    }
    match paper {
        Paper::Value { value, agree } => Some((m.value - value).abs() <= *agree),
        Paper::Text {
            range: Some([lo, hi]),
            ..
        } => Some((*lo..=*hi).contains(&m.value)),
        Paper::Text { range: None, .. } => None,
    }
}

/// A measured value as the report shows it: the number, or that it failed.
fn shown(m: &Measured) -> String {
    match m.failure {
        Some(_) => "**failed**".into(),
        None => fmt(m.value),
    }
}

/// Four significant digits, without exponent for the magnitudes a report shows.
fn fmt(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    if !(-4..=7).contains(&magnitude) {
        return format!("{x:.3e}");
    }
    let decimals = (3 - magnitude).clamp(0, 8) as usize;
    format!("{x:.decimals$}")
}

/// The runs of a scan in words: "t in [30.25, 31.00], t = 35.50, … (7 runs)".
fn runs_text(s: &Scanned) -> String {
    const SHOWN: usize = 3;
    if s.runs.is_empty() {
        return format!("never (closest at {} = {})", s.column, fmt(s.closest));
    }
    let mut parts: Vec<String> = s
        .runs
        .iter()
        .take(SHOWN)
        .map(|&(a, b)| {
            if a == b {
                format!("{} = {}", s.column, fmt(a))
            } else {
                format!("{} in [{}, {}]", s.column, fmt(a), fmt(b))
            }
        })
        .collect();
    if let (true, Some(last)) = (s.runs.len() > SHOWN, s.runs.last()) {
        parts.push(format!(
            "… ({} runs, the last ending at {})",
            s.runs.len(),
            fmt(last.1)
        ));
    }
    parts.join(", ")
}

fn paper_text(p: &Paper) -> String {
    match p {
        Paper::Value { value, .. } => fmt(*value),
        Paper::Text { text, .. } => text.clone(),
    }
}

fn difference(p: &Paper, m: &Measured) -> (Option<f64>, Option<f64>) {
    if m.failure.is_some() {
        return (None, None);
    }
    match p {
        Paper::Value { value, .. } => (
            Some(m.value - value),
            (*value != 0.0).then(|| (m.value - value) / value.abs()),
        ),
        Paper::Text { .. } => (None, None),
    }
}

fn verdict(p: &Paper, m: &Measured) -> &'static str {
    match reproduces(p, m) {
        Some(true) => "yes",
        Some(false) => "no",
        None => "–",
    }
}

/// The line that marks a Markdown file as written by report stage `stage`.
fn generated_mark(stage: &str) -> String {
    format!("<!-- Generated by `woodpile run {stage}`; do not edit by hand. -->")
}

fn markdown(
    stage: &str,
    report: &Report,
    evaluated: &[(Measured, Vec<(String, Measured)>)],
) -> String {
    let mut out = String::new();
    out.push_str(&format!("# {}\n\n", report.title));
    out.push_str(&generated_mark(stage));
    out.push_str("\n\n");
    if !report.preamble.is_empty() {
        out.push_str(report.preamble.trim());
        out.push_str("\n\n");
    }
    out.push_str("## Summary\n\n");
    out.push_str("| figure | quantity | paper | ours (as run) | difference | reproduced as run | conventions that reproduce it |\n");
    out.push_str("|---|---|---|---|---|---|---|\n");
    for (q, (ours, conventions)) in report.quotes.iter().zip(evaluated) {
        let (diff, _) = difference(&q.paper, ours);
        let by: Vec<&str> = conventions
            .iter()
            .filter(|(_, m)| reproduces(&q.paper, m) == Some(true))
            .map(|(name, _)| name.as_str())
            .collect();
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} |\n",
            q.figure,
            q.quantity,
            paper_text(&q.paper),
            shown(ours),
            diff.map_or("–".into(), fmt),
            verdict(&q.paper, ours),
            if by.is_empty() {
                "none".to_string()
            } else {
                by.join("; ")
            },
        ));
    }
    let mut figures: Vec<&str> = Vec::new();
    for q in &report.quotes {
        if !figures.contains(&q.figure.as_str()) {
            figures.push(&q.figure);
        }
    }
    for figure in figures {
        out.push_str(&format!("\n## {figure}\n"));
        for (q, (ours, conventions)) in report.quotes.iter().zip(evaluated) {
            if q.figure != figure {
                continue;
            }
            out.push_str(&format!("\n### {}\n\n", q.quantity));
            let agree = match &q.paper {
                Paper::Value { agree, .. } => format!(" (reproduced when within ±{})", fmt(*agree)),
                Paper::Text {
                    range: Some([lo, hi]),
                    ..
                } => {
                    format!(" (taken as {} to {})", fmt(*lo), fmt(*hi))
                }
                Paper::Text { range: None, .. } => String::new(),
            };
            out.push_str(&format!("Paper: **{}**{agree}.\n\n", paper_text(&q.paper)));
            if !q.note.is_empty() {
                out.push_str(q.note.trim());
                out.push_str("\n\n");
            }
            out.push_str("| convention | value | where | difference | reproduces | scan: within tolerance at | sensitivity |\n");
            out.push_str("|---|---|---|---|---|---|---|\n");
            let as_run = format!("as run: {}", q.as_run);
            for (name, m) in
                std::iter::once((&as_run, ours)).chain(conventions.iter().map(|(n, m)| (n, m)))
            {
                let (diff, _) = difference(&q.paper, m);
                let (range, slope) = match &m.scan {
                    Some(s) => (
                        runs_text(s),
                        format!("{} per unit {}", fmt(s.slope), s.column),
                    ),
                    None => ("–".into(), "–".into()),
                };
                out.push_str(&format!(
                    "| {} | {} | {} | {} | {} | {} | {} |\n",
                    name,
                    shown(m),
                    match (&m.failure, m.location.is_empty()) {
                        (Some(reason), _) => reason.replace('|', "/"),
                        (None, true) => "–".into(),
                        (None, false) => m.location.clone(),
                    },
                    diff.map_or("–".into(), fmt),
                    verdict(&q.paper, m),
                    range,
                    slope,
                ));
            }
        }
    }
    out
}

/// A parquet row: one quote under one convention (`as run` or a searched one).
struct QuoteRow<'a> {
    quote: &'a Quote,
    convention: String,
    measured: &'a Measured,
}

impl Row for QuoteRow<'_> {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let (q, m) = (self.quote, self.measured);
        let (diff, rel) = difference(&q.paper, m);
        let scan = m.scan.as_ref();
        vec![
            ("figure", q.figure.clone().into()),
            ("quantity", q.quantity.clone().into()),
            ("convention", self.convention.clone().into()),
            (
                "paper",
                match q.paper {
                    Paper::Value { value, .. } => Some(value),
                    Paper::Text { .. } => None,
                }
                .into(),
            ),
            ("paper_text", paper_text(&q.paper).into()),
            ("value", m.failure.is_none().then_some(m.value).into()),
            (
                "location",
                (!m.location.is_empty()).then(|| m.location.clone()).into(),
            ),
            ("difference", diff.into()),
            ("relative_difference", rel.into()),
            ("reproduces", reproduces(&q.paper, m).map(i64::from).into()),
            ("scan_column", scan.map(|s| s.column.clone()).into()),
            ("scan_closest", scan.map(|s| s.closest).into()),
            ("scan_within_tolerance", scan.map(runs_text).into()),
            ("sensitivity", scan.map(|s| s.slope).into()),
            ("failure", m.failure.clone().into()),
        ]
    }
}

impl Kind for Report {
    fn check_inputs(&self, stage: &Stage, _: &Inputs<'_>) -> KindCheck {
        if stage.inputs.is_empty() {
            return Err((
                "inputs".into(),
                "a report reads the stages its quotes name".into(),
            ));
        }
        for (key, source) in self.sources() {
            if !stage.inputs.contains(&source.stage) {
                return Err((
                    key,
                    format!("`{}` is not among this stage's inputs", source.stage),
                ));
            }
        }
        Ok(())
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        self.run(ctx.name(), ctx.results)
    }

    fn files(&self, _: &str, results: &Path, _: &Path) -> Vec<PathBuf> {
        vec![self.markdown_path(results)]
    }

    fn claims(&self) -> Vec<(&'static str, String)> {
        vec![("markdown", self.markdown.clone())]
    }
}

#[cfg(test)]
mod tests {
    use super::fmt;

    #[test]
    fn four_significant_digits() {
        assert_eq!(fmt(0.21116587), "0.2112");
        assert_eq!(fmt(3961000.0), "3961000");
        assert_eq!(fmt(-0.0110), "-0.01100");
        assert_eq!(fmt(124.0), "124.0");
        assert_eq!(fmt(1.5e-9), "1.500e-9");
    }
}
