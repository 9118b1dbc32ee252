//! Reading a quote's number from a stage's output: a row under a filter, the maximum of a
//! column, a manifest entry, or a scan along a column for where the paper's number is met.

use std::collections::HashMap;

use polars::prelude::DataFrame;

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::kind::Context;
use woodpile_pipeline::table::{f64_column, matching_rows, str_column};

use super::number::fmt;
use super::{Paper, Read, Source};

/// What a source measured.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Measured {
    pub(super) value: f64,
    pub(super) location: String,
    pub(super) scan: Option<Scanned>,
    /// Why the number could not be read (a failed fit upstream, say): shown in its place.
    pub(super) failure: Option<String>,
}

impl Measured {
    pub(super) fn failed(reason: String) -> Measured {
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
pub(super) struct Scanned {
    /// The scanned column.
    pub(super) column: String,
    /// Runs of consecutive scan values within `agree` of the paper's number (first, last).
    pub(super) runs: Vec<(f64, f64)>,
    /// The scan value where the number comes closest.
    pub(super) closest: f64,
    /// |d value / d scan| at the closest approach.
    pub(super) slope: f64,
}

/// Reads stage outputs once each.
pub(super) struct Reader<'a> {
    pub(super) ctx: &'a Context<'a>,
    pub(super) frames: HashMap<String, DataFrame>,
}

impl Reader<'_> {
    fn frame(&mut self, stage: &str) -> Result<&DataFrame> {
        if !self.frames.contains_key(stage) {
            let frame = self.ctx.input(stage)?;
            self.frames.insert(stage.to_string(), frame);
        }
        Ok(&self.frames[stage])
    }

    /// What `source` reads for a quote of `paper`: a manifest entry, a table row, or the
    /// closest approach of a scan.
    pub(super) fn measure(&mut self, source: &Source, paper: &Paper) -> Result<Measured> {
        let fail = |reason: String| PipelineError::stage(&source.stage, reason);
        let column = match &source.read {
            Read::Manifest(path) => {
                let manifest = self
                    .ctx
                    .input_manifest(&source.stage)?
                    .ok_or_else(|| fail("no manifest".into()))?;
                let value = manifest
                    .lookup(path)
                    .and_then(|x| x.as_f64())
                    .ok_or_else(|| fail(format!("manifest has no number at `{path}`")))?;
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
        let rows = matching_rows(frame, &source.filter)?;
        let read = ColumnRead::of(frame, source, column)?;
        let Some(scan_column) = &source.scan else {
            let r = read.pick(&rows).map_err(fail)?;
            return Ok(Measured {
                value: read.value_at(r).map_err(fail)?,
                location: read.location(r),
                scan: None,
                failure: None,
            });
        };
        let series = read
            .along(frame, &rows, source, scan_column)?
            .map_err(|e| fail(format!("scanning `{scan_column}`: {e}")))?;
        let target = paper_target(paper)
            .ok_or_else(|| fail("a scan needs a paper number or range to aim at".into()))?;
        let best = (0..series.len())
            .min_by(|&a, &b| {
                (series[a].1 - target)
                    .abs()
                    .total_cmp(&(series[b].1 - target).abs())
            })
            .ok_or_else(|| fail(format!("no rows to scan over `{scan_column}`")))?;
        let (s, value, r) = series[best];
        let mut where_text = format!("{scan_column} = {}", fmt(s));
        let located = read.location(r);
        if !located.is_empty() {
            where_text = format!("{where_text}: {located}");
        }
        Ok(Measured {
            value,
            location: where_text,
            scan: Some(Scanned {
                column: scan_column.clone(),
                runs: runs_within(&series, paper),
                closest: s,
                slope: slope_at(&series, best),
            }),
            failure: None,
        })
    }
}

/// One point of a scan: (scan value, value read, row).
type ScanPoint = (f64, f64, usize);

/// A column of a stage's table as a source reads it: its values, the column that ranks rows
/// (`max`), the columns that say where a row is (`locate`), and why rows failed upstream.
struct ColumnRead {
    name: String,
    values: Vec<Option<f64>>,
    ranking: Option<Vec<Option<f64>>>,
    locate: Vec<(String, Vec<Option<f64>>)>,
    failures: Option<Vec<Option<String>>>,
}

impl ColumnRead {
    fn of(frame: &DataFrame, source: &Source, name: String) -> Result<ColumnRead> {
        Ok(ColumnRead {
            values: f64_column(frame, &name)?,
            ranking: match &source.max {
                Some(m) => Some(f64_column(frame, m)?),
                None => None,
            },
            locate: source
                .locate
                .iter()
                .map(|c| Ok((c.clone(), f64_column(frame, c)?)))
                .collect::<Result<_>>()?,
            // A row that failed upstream (a fit that did not converge) says why in `failure`.
            failures: str_column(frame, "failure").ok(),
            name,
        })
    }

    /// `c = v, ...` of the `locate` columns at row `r`.
    fn location(&self, r: usize) -> String {
        self.locate
            .iter()
            .map(|(c, v)| format!("{c} = {}", v[r].map_or("null".into(), fmt)))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The row read within a set of candidate rows: the only one, or the largest.
    fn pick(&self, candidates: &[usize]) -> std::result::Result<usize, String> {
        match &self.ranking {
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
    }

    /// The value at row `r`, or why it has none.
    fn value_at(&self, r: usize) -> std::result::Result<f64, String> {
        self.values[r].filter(|v| v.is_finite()).ok_or_else(|| {
            match self.failures.as_ref().and_then(|f| f[r].clone()) {
                Some(reason) => format!("the row read failed upstream: {reason}"),
                None => format!(
                    "column `{}` is null or not finite in the row read",
                    self.name
                ),
            }
        })
    }

    /// (scan value, value, row) along `scan_column`, one per scan value within the source's
    /// range, in increasing order (rows sharing a scan value picked as one).
    fn along(
        &self,
        frame: &DataFrame,
        rows: &[usize],
        source: &Source,
        scan_column: &str,
    ) -> Result<std::result::Result<Vec<ScanPoint>, String>> {
        let scan_values = f64_column(frame, scan_column)?;
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
        let mut groups: Vec<(f64, Vec<usize>)> = Vec::new();
        for (r, s) in sorted {
            match groups.last_mut() {
                Some((last, members)) if *last == s => members.push(r),
                _ => groups.push((s, vec![r])),
            }
        }
        Ok(groups
            .iter()
            .map(|(s, members)| {
                let r = self.pick(members)?;
                Ok((*s, self.value_at(r)?, r))
            })
            .collect())
    }
}

/// The number a scan aims at: the paper's value, or the middle of its range.
fn paper_target(paper: &Paper) -> Option<f64> {
    match paper {
        Paper::Value { value, .. } => Some(*value),
        Paper::Text {
            range: Some([lo, hi]),
            ..
        } => Some(0.5 * (lo + hi)),
        Paper::Text { range: None, .. } => None,
    }
}

/// The runs of consecutive scan values whose value agrees with `paper` (first, last).
fn runs_within(series: &[ScanPoint], paper: &Paper) -> Vec<(f64, f64)> {
    let within = |v: f64| match paper {
        Paper::Value { value, agree } => (v - value).abs() <= *agree,
        Paper::Text {
            range: Some([lo, hi]),
            ..
        } => (*lo..=*hi).contains(&v),
        Paper::Text { range: None, .. } => false,
    };
    let mut runs: Vec<(f64, f64)> = Vec::new();
    let mut previous_hit = false;
    for &(s, v, _) in series {
        let hit = within(v);
        match runs.last_mut() {
            Some(run) if hit && previous_hit => run.1 = s,
            _ if hit => runs.push((s, s)),
            _ => {}
        }
        previous_hit = hit;
    }
    runs
}

/// |d value / d scan| at point `best` of `series`: the steeper of its two sides.
fn slope_at(series: &[ScanPoint], best: usize) -> f64 {
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
    slope
}
