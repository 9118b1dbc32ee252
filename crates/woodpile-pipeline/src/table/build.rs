//! Building a table: columns by name (`Columns`), or rows of a kind's own type (`Row`) whose
//! cells are collected into typed columns (`rows_frame`).

use polars::prelude::*;

use woodpile_files::rows::Column as Typed;
pub use woodpile_files::rows::{Cell, Row};

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

/// The table of `rows`: one column per cell name, in the first row's order. Every row must
/// give the same names with the same kinds of cell (an error names the first that does not).
pub fn rows_frame<R: Row>(rows: &[R]) -> Result<DataFrame> {
    let columns = woodpile_files::rows::columns(rows)
        .map_err(|reason| PipelineError::stage("table", reason))?;
    if columns.is_empty() {
        return Ok(DataFrame::empty());
    }
    let mut out = Columns::new();
    for (name, column) in columns {
        match column {
            Typed::F64(v) => out.f64(&name, v),
            Typed::I64(v) => out.i64(&name, v),
            Typed::Str(v) => out.str(&name, v),
            Typed::F64List(v) => out.f64_list(&name, v),
            Typed::I64List(v) => out.i64_list(&name, v),
        };
    }
    out.into_frame()
}
