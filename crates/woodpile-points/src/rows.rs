//! The sweep's row ([`SweepRow`], columns named in [`sweep`]): the one row schema of a sweep
//! stage and of Python's `sweep`, so that both have the same columns, in the same order, from
//! the same code.

use woodpile_scene::grid::{Axis, AxisValue};
use woodpile_scene::units_out::SiFactors;
use woodpile_sim::ShareSet;

use crate::point::{PointData, PointResult};
use woodpile_files::key::Key;
use woodpile_files::rows::{Cell, Row};

/// The columns of a sweep's table, named where the axes are checked against them
/// ([`woodpile_scene::grid::RESERVED`]).
pub use woodpile_scene::columns as sweep;

/// What every row of one sweep shares: its axes, and which optional shares it has.
#[derive(Debug, Clone, Copy)]
pub struct SweepShape<'a> {
    /// The grid's axes, in order.
    pub axes: &'a [Axis],
    /// Its shares: `S` when its scenes have a striker, `D` on every row when its scene
    /// declares dissipation.
    pub shares: ShareSet,
    /// Whether `E` is the kinetic share of the impact energy (a kinetic series), which has
    /// no unit, rather than an energy.
    pub kinetic: bool,
}

/// One point of a sweep, as its rows need it.
#[derive(Debug, Clone, Copy)]
pub struct SweepPoint<'a> {
    /// Its index in the grid (or in the list).
    pub index: usize,
    /// Its axis values, one per axis.
    pub values: &'a [AxisValue],
    /// Its cache key.
    pub key: &'a Key,
    /// Its series, or why it failed.
    pub result: &'a PointResult,
    /// Its SI factors, when the table is asked in SI: `t`, `dt` and `end_reached_at` in s,
    /// `E` in J.
    pub si: Option<SiFactors>,
}

impl<'a> SweepShape<'a> {
    /// The rows of `points`: one per sample of each, or one with the reason for a point that
    /// failed.
    pub fn rows(&self, points: &[SweepPoint<'a>]) -> Vec<SweepRow<'a>> {
        let mut rows = Vec::new();
        for point in points {
            let samples = point.result.as_ref().map_or(1, |p| p.t.len());
            rows.extend((0..samples).map(|sample| SweepRow {
                shape: *self,
                point: *point,
                sample,
            }));
        }
        rows
    }
}

/// One output row of a sweep: a sample of a point's series, or the one row of a failed point.
#[derive(Debug, Clone, Copy)]
pub struct SweepRow<'a> {
    shape: SweepShape<'a>,
    point: SweepPoint<'a>,
    sample: usize,
}

impl Row for SweepRow<'_> {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let mut cells = vec![(sweep::POINT, Cell::from(self.point.index as i64))];
        for (axis, value) in self.shape.axes.iter().zip(self.point.values) {
            let cell = match (axis.is_integer(), *value) {
                (true, AxisValue::Int(i)) => Cell::from(i),
                (true, AxisValue::Float(x)) => Cell::from(x as i64),
                (false, v) => Cell::from(v.as_f64()),
            };
            cells.push((axis.name.as_str(), cell));
        }
        let ok = self.point.result.as_ref().ok();
        let at = |series: fn(&PointData) -> &Vec<f64>| ok.map(|p| series(p)[self.sample]);
        // Scaled units multiply by 1, which leaves every bit as it was.
        let (time, energy) = match self.point.si {
            Some(f) if self.shape.kinetic => (f.time_s, 1.0),
            Some(f) => (f.time_s, f.energy_j),
            None => (1.0, 1.0),
        };
        cells.push((sweep::TIME, at(|p| &p.t).map(|t| t * time).into()));
        for share in self.shape.shares.iter() {
            let value = ok.and_then(|p| p.share_at(share, self.sample));
            cells.push((share.name(), value.into()));
        }
        cells.extend([
            (sweep::ENERGY, at(|p| &p.energy).map(|e| e * energy).into()),
            (sweep::METHOD, ok.map(|p| p.method.clone()).into()),
            (sweep::DT, ok.and_then(|p| p.dt).map(|dt| dt * time).into()),
            (sweep::STEPS, ok.map(|p| p.steps as i64).into()),
            (
                sweep::ERROR_ESTIMATE,
                ok.and_then(|p| p.error_estimate).into(),
            ),
            (sweep::ENERGY_DRIFT, ok.and_then(|p| p.energy_drift).into()),
            (
                sweep::END_REACHED_AT,
                ok.and_then(|p| p.end_reached_at).map(|t| t * time).into(),
            ),
            (
                sweep::FAILURE,
                self.point.result.as_ref().err().cloned().into(),
            ),
            (sweep::SCENE_KEY, self.point.key.to_string().into()),
        ]);
        cells
    }
}
