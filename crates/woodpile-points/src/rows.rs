//! Tables as rows of typed cells, with no polars: a kind describes its rows once, as a type
//! ([`Row`]), and [`columns`] turns them into typed columns. The engine makes a parquet table
//! of them; the Python module makes NumPy arrays of the same columns.
//!
//! The sweep's row ([`SweepRow`], columns named in [`sweep`]) lives here too, so a sweep
//! stage's table and Python's `sweep` have the same columns, in the same order, from the same
//! code.

use woodpile_scene::grid::{Axis, AxisValue};
use woodpile_scene::units_out::SiFactors;
use woodpile_sim::ShareSet;

use crate::canonical::Key;
use crate::point::{PointData, PointResult};

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

/// `Cell` from a value and from an optional one (`None` is the null cell), for each scalar
/// kind.
macro_rules! cell_from {
    ($($t:ty => $variant:ident),*) => {$(
        impl From<$t> for Cell {
            fn from(x: $t) -> Self {
                Cell::$variant(Some(x))
            }
        }
        impl From<Option<$t>> for Cell {
            fn from(x: Option<$t>) -> Self {
                Cell::$variant(x)
            }
        }
    )*};
}

cell_from!(f64 => F64, i64 => I64, String => Str);

impl From<&str> for Cell {
    fn from(x: &str) -> Self {
        Cell::Str(Some(x.to_string()))
    }
}

/// A row of an output table: its cells, each under its column's name, in column order.
pub trait Row {
    /// The cells of this row.
    fn cells(&self) -> Vec<(&str, Cell)>;
}

/// One typed column.
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    /// Floats (or nulls).
    F64(Vec<Option<f64>>),
    /// Integers (or nulls).
    I64(Vec<Option<i64>>),
    /// Strings (or nulls).
    Str(Vec<Option<String>>),
    /// Lists of floats.
    F64List(Vec<Vec<f64>>),
    /// Lists of integers.
    I64List(Vec<Vec<i64>>),
}

impl Column {
    /// An empty column of the kind of `cell`.
    fn of_kind(cell: &Cell, rows: usize) -> Column {
        match cell {
            Cell::F64(_) => Column::F64(Vec::with_capacity(rows)),
            Cell::I64(_) => Column::I64(Vec::with_capacity(rows)),
            Cell::Str(_) => Column::Str(Vec::with_capacity(rows)),
            Cell::F64List(_) => Column::F64List(Vec::with_capacity(rows)),
            Cell::I64List(_) => Column::I64List(Vec::with_capacity(rows)),
        }
    }

    /// Appends `cell`, or gives it back if it is of another kind.
    fn push(&mut self, cell: Cell) -> Result<(), Cell> {
        match (self, cell) {
            (Column::F64(v), Cell::F64(x)) => v.push(x),
            (Column::I64(v), Cell::I64(x)) => v.push(x),
            (Column::Str(v), Cell::Str(x)) => v.push(x),
            (Column::F64List(v), Cell::F64List(x)) => v.push(x),
            (Column::I64List(v), Cell::I64List(x)) => v.push(x),
            (_, cell) => return Err(cell),
        }
        Ok(())
    }
}

/// The columns of `rows`, named, in the first row's order. Every row must give the same names
/// with the same kinds of cell: the error names the first that does not. No rows, no columns.
pub fn columns<R: Row>(rows: &[R]) -> Result<Vec<(String, Column)>, String> {
    let Some(first) = rows.first() else {
        return Ok(Vec::new());
    };
    let mut out: Vec<(String, Column)> = first
        .cells()
        .iter()
        .map(|(name, cell)| (name.to_string(), Column::of_kind(cell, rows.len())))
        .collect();
    for (r, row) in rows.iter().enumerate() {
        let cells = row.cells();
        if cells.len() != out.len() {
            return Err(format!(
                "row {r} has {} cells, not {}",
                cells.len(),
                out.len()
            ));
        }
        for (k, ((name, cell), (column_name, column))) in
            cells.into_iter().zip(&mut out).enumerate()
        {
            if name != column_name {
                return Err(format!(
                    "row {r}: column {k} is `{name}`, not `{column_name}`"
                ));
            }
            column
                .push(cell)
                .map_err(|_| format!("column `{name}` mixes kinds of values"))?;
        }
    }
    Ok(out)
}

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

#[cfg(test)]
mod tests {
    use super::*;

    struct Pair(&'static str, Cell);

    impl Row for Pair {
        fn cells(&self) -> Vec<(&str, Cell)> {
            vec![("a", Cell::from(1_i64)), (self.0, self.1.clone())]
        }
    }

    #[test]
    fn rows_become_typed_columns_in_order() {
        let rows = [Pair("b", Cell::from(0.5)), Pair("b", Cell::F64(None))];
        let out = columns(&rows).unwrap();
        assert_eq!(
            out,
            vec![
                ("a".to_string(), Column::I64(vec![Some(1), Some(1)])),
                ("b".to_string(), Column::F64(vec![Some(0.5), None])),
            ]
        );
        assert!(columns::<Pair>(&[]).unwrap().is_empty());
    }

    #[test]
    fn rows_that_disagree_are_refused_by_name() {
        let names = [Pair("b", Cell::from(0.5)), Pair("c", Cell::from(0.5))];
        assert_eq!(
            columns(&names).unwrap_err(),
            "row 1: column 1 is `c`, not `b`"
        );
        let kinds = [Pair("b", Cell::from(0.5)), Pair("b", Cell::from("x"))];
        assert_eq!(
            columns(&kinds).unwrap_err(),
            "column `b` mixes kinds of values"
        );
    }
}
