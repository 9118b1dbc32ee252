//! The design table: one row per evaluated design, with where it stands in its search.

use polars::prelude::DataFrame;

use woodpile_pipeline::error::Result;
use woodpile_pipeline::table::{rows_frame, Cell, Row};
use woodpile_points::PointData;

use super::{Design, Evaluated, Search};

impl Design {
    /// The stage's table: one row per evaluation, numbered within its search.
    pub(super) fn frame(&self, rows: &[Evaluated]) -> Result<DataFrame> {
        let mut counters = [0i64; Search::ALL.len()];
        let mut bests = [f64::NEG_INFINITY; Search::ALL.len()];
        let mut out: Vec<TrialRow> = rows
            .iter()
            .map(|e| {
                let s = e.search as usize;
                counters[s] += 1;
                bests[s] = bests[s].max(e.score);
                TrialRow {
                    trial: e,
                    search_index: s,
                    evaluation: counters[s],
                    best_so_far: bests[s].is_finite().then(|| self.fraction_of(bests[s])),
                    quantile: None,
                    rods: self.space.length.is_some(),
                }
            })
            .collect();
        // Robustness samples: each one's rank among its spread's samples, as a quantile, so
        // that E_tr against `quantile` draws the distribution.
        for search in Search::ALL.into_iter().filter(|s| s.is_robustness()) {
            let mut members: Vec<usize> = (0..rows.len())
                .filter(|&i| rows[i].search == search)
                .collect();
            members.sort_by(|&a, &b| rows[a].score.total_cmp(&rows[b].score).then(a.cmp(&b)));
            let n = members.len();
            for (rank, &i) in members.iter().enumerate() {
                out[i].quantile = Some(if n > 1 {
                    rank as f64 / (n - 1) as f64
                } else {
                    0.5
                });
            }
        }
        rows_frame(&out)
    }
}

/// One row of the design table: an evaluated design and where it stands in its search.
struct TrialRow<'a> {
    trial: &'a Evaluated,
    search_index: usize,
    evaluation: i64,
    best_so_far: Option<f64>,
    quantile: Option<f64>,
    /// Whether the design places rods: the table then has their `length` (m).
    rods: bool,
}

impl Row for TrialRow<'_> {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let e = self.trial;
        let ok = e.result.as_ref().ok();
        let last = |pick: fn(&PointData) -> &Vec<f64>| ok.and_then(|p| pick(p).last().copied());
        let mut cells = vec![
            ("search", e.search.label().into()),
            ("search_index", Cell::from(self.search_index as i64)),
            ("evaluation", Cell::from(self.evaluation)),
            ("resonators", Cell::from(e.layout.resonators.len() as i64)),
            (
                "sites",
                Cell::I64List(e.layout.resonators.iter().map(|r| r.site).collect()),
            ),
            (
                "eps",
                Cell::F64List(e.layout.resonators.iter().map(|r| r.eps).collect()),
            ),
            (
                "kappa",
                Cell::F64List(e.layout.resonators.iter().map(|r| r.kappa).collect()),
            ),
            (
                "p",
                Cell::I64List(e.layout.resonators.iter().map(|r| r.p).collect()),
            ),
            ("total_eps", Cell::from(e.layout.total_eps())),
            ("R", last(|p| &p.reflected).into()),
            ("T", last(|p| &p.transmitted).into()),
            ("E_tr", last(|p| &p.trapped).into()),
            ("error_estimate", ok.and_then(|p| p.error_estimate).into()),
            ("best_so_far", self.best_so_far.into()),
            ("quantile", self.quantile.into()),
            ("failure", e.result.as_ref().err().cloned().into()),
            (
                "scene_key",
                (!e.key.is_empty()).then(|| e.key.clone()).into(),
            ),
        ];
        if self.rods {
            let lengths = e.layout.resonators.iter();
            let metres = lengths.map(|r| r.length.unwrap_or(f64::NAN)).collect();
            cells.insert(5, ("length", Cell::F64List(metres)));
        }
        cells
    }
}
