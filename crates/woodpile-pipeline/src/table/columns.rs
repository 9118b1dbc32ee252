//! Reading a table's columns by name: as floats or strings, the rows a `where` filter keeps,
//! and a missing column's message with the nearest name.

use polars::prelude::*;

use crate::error::{PipelineError, Result};

/// A column of `frame` as floats (integers converted), nulls kept. A text column is refused:
/// cast, its every value would read as null and a figure would silently draw nothing.
pub fn f64_column(frame: &DataFrame, name: &str) -> Result<Vec<Option<f64>>> {
    let column = frame
        .column(name)
        .map_err(|_| PipelineError::stage("table", missing_column(frame, name)))?;
    let dtype = column.dtype();
    if !(dtype.is_primitive_numeric() || dtype.is_bool() || dtype.is_null()) {
        return Err(PipelineError::stage(
            "table",
            format!("column `{name}` holds {}, not numbers", column.dtype()),
        ));
    }
    let column = column
        .cast(&DataType::Float64)
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?;
    let values = column
        .f64()
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?
        .iter()
        .collect();
    Ok(values)
}

/// Why `name` is not a column of `frame`: the columns that exist, and the nearest one.
pub fn missing_column(frame: &DataFrame, name: &str) -> String {
    let names: Vec<String> = frame
        .get_column_names()
        .iter()
        .map(|n| n.to_string())
        .collect();
    let nearest = names
        .iter()
        .min_by_key(|n| edit_distance(&n.to_lowercase(), &name.to_lowercase()))
        .filter(|n| {
            edit_distance(&n.to_lowercase(), &name.to_lowercase()) <= 2.max(name.len() / 3)
        });
    let hint = nearest.map_or(String::new(), |n| format!("; did you mean `{n}`?"));
    format!(
        "column `{name}` not found (the table has {}){hint}",
        names.join(", ")
    )
}

/// Levenshtein distance, for naming the column a typo meant.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (row[j + 1] + 1)
                .min(row[j] + 1)
                .min(diagonal + usize::from(ca != *cb));
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// The rows of `frame` where every `(column, value)` of `filter` holds (all rows if empty).
pub fn matching_rows(frame: &DataFrame, filter: &[(String, Match)]) -> Result<Vec<usize>> {
    let mut numbers: Vec<(Vec<Option<f64>>, f64)> = Vec::new();
    let mut texts: Vec<(Vec<Option<String>>, &str)> = Vec::new();
    for (column, m) in filter {
        match m {
            Match::Number(x) => numbers.push((f64_column(frame, column)?, *x)),
            Match::Text(t) => texts.push((str_column(frame, column)?, t)),
        }
    }
    Ok((0..frame.height())
        .filter(|&r| numbers.iter().all(|(col, v)| col[r] == Some(*v)))
        .filter(|&r| texts.iter().all(|(col, t)| col[r].as_deref() == Some(*t)))
        .collect())
}

/// One equality of a row filter (`where = { column = value }`).
#[derive(Debug, Clone, PartialEq)]
pub enum Match {
    /// The number in a numeric column.
    Number(f64),
    /// The string in a string column.
    Text(String),
}

/// A column of `frame` as strings, nulls kept; an integer column (a band, a point) is written
/// in decimal, so it can name curves too.
pub fn str_column(frame: &DataFrame, name: &str) -> Result<Vec<Option<String>>> {
    let column = frame
        .column(name)
        .map_err(|_| PipelineError::stage("table", missing_column(frame, name)))?;
    let cast;
    let column = match column.dtype().is_integer() {
        true => {
            cast = column
                .cast(&DataType::String)
                .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?;
            &cast
        }
        false => column,
    };
    let values = column
        .str()
        .map_err(|e| PipelineError::stage("table", format!("column `{name}`: {e}")))?
        .iter()
        .map(|v| v.map(str::to_string))
        .collect();
    Ok(values)
}
