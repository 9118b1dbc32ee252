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
//! - `manifest = "summary.key"`: a value of the stage's manifest, addressed as render titles
//!   address it (dotted keys, a number indexing an array; `/summary/key` is the same path);
//! - `scan = "col"` (optionally `scan_range = [lo, hi]`): the value as a function of `col` (with `max`, the largest over the other
//!   rows at each `col`): where it comes within `agree` of the paper's number, and its slope
//!   there, so the report says which read-out time reproduces a number and how sensitive it is.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde_json::json;

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{wrong_inputs, Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::{rows_frame, Cell, Row};
use woodpile_pipeline::Output;

pub use woodpile_pipeline::table::Match;

mod judge;
mod markdown;
mod measure;
mod number;
mod parse;

use judge::{difference, reproduces};
use markdown::{generated_mark, markdown, paper_text, runs_text};
use measure::{Measured, Reader};
use parse::{check_markdown_path, parse_quote};

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
    /// A path into the manifest (`woodpile_pipeline::manifest::lookup`).
    Manifest(String),
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
    /// Markdown and the table, or a damaged table, leaves: never a stuck stage). That the path
    /// stays inside the project on disk is `Context::write_file`'s check.
    fn check_owned(&self, ctx: &Context<'_>, path: &Path) -> Result<()> {
        let stage = ctx.name();
        if std::fs::symlink_metadata(path).is_err() {
            return Ok(());
        }
        let previous = ctx.previous_manifest();
        let named = previous.is_some_and(|m| m.summary["markdown"] == self.markdown.as_str());
        let marked = ctx.existing_head(path, 4096).is_some_and(|head| {
            String::from_utf8_lossy(&head)
                .lines()
                .take(5)
                .any(|line| line == generated_mark(stage))
        });
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
        woodpile_files::layout::markdown_path(results, &self.markdown)
    }

    pub(crate) fn compute(&self, ctx: &Context<'_>) -> Result<Output> {
        let (stage, results) = (ctx.name(), ctx.results);
        let mut reader = Reader {
            ctx,
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
        self.check_owned(ctx, &path)?;
        ctx.write_file(&path, text.as_bytes())?;
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
        let summary = json!({
            "quotes": self.quotes.len(),
            "reproduced_as_run": reproduced,
            "reproduced_by_some_convention": by_some,
            "failed": failures.len(),
            "markdown": self.markdown,
        });
        Ok(Output::table(rows_frame(&rows)?, summary).with_failures(failures))
    }
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
            return wrong_inputs("a report reads the stages its quotes name");
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
        self.compute(ctx)
    }

    fn files(&self, _: &str, results: &Path, _: &Path) -> Vec<PathBuf> {
        vec![self.markdown_path(results)]
    }

    fn claims(&self) -> Vec<(&'static str, String)> {
        vec![("markdown", self.markdown.clone())]
    }
}
