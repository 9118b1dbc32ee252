//! Tables as rows of typed cells, with no polars: a kind describes its rows once, as a type
//! ([`Row`]), and [`columns`] turns them into typed columns. The engine makes a parquet table
//! of them; the Python module makes NumPy arrays of the same columns.

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
