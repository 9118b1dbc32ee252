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
