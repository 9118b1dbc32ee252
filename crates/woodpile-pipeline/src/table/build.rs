//! Building a table: columns by name (`Columns`), or rows of a kind's own type (`Row`) whose
//! cells are collected into typed columns (`rows_frame`).

use polars::prelude::*;

use crate::error::{PipelineError, Result};

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
        // The closure that takes a cell of one variant apart (`None` for any other).
        macro_rules! take {
            ($variant:ident) => {
                |c| match c {
                    Cell::$variant(x) => Some(x),
                    _ => None,
                }
            };
        }
        // List cells are never null: each is unpacked as present, then unwrapped.
        match cells.first() {
            Some(Cell::F64(_)) | None => out.f64(name, unpack(cells, take!(F64), mismatch)?),
            Some(Cell::I64(_)) => out.i64(name, unpack(cells, take!(I64), mismatch)?),
            Some(Cell::Str(_)) => out.str(name, unpack(cells, take!(Str), mismatch)?),
            Some(Cell::F64List(_)) => {
                let lists = unpack(cells, |c| take!(F64List)(c).map(Some), mismatch)?;
                out.f64_list(name, lists.into_iter().flatten().collect())
            }
            Some(Cell::I64List(_)) => {
                let lists = unpack(cells, |c| take!(I64List)(c).map(Some), mismatch)?;
                out.i64_list(name, lists.into_iter().flatten().collect())
            }
        };
    }
    out.into_frame()
}
