//! `kind = "table"`: one input's table, or the rows and columns of it you name, as a CSV file
//! beside the stage's parquet (`results/<stage>.csv`), for a spreadsheet, a plotting program
//! or a colleague without a parquet reader.
//!
//! ```toml
//! kind = "table"
//! inputs = ["f4_fractions"]
//! columns = ["eps", "L", "R", "T", "E_tr"]   # optional: these columns, in this order (default: all)
//! where = { L = 2 }                          # optional: only these rows (numbers or strings)
//! ```
//!
//! Numbers are written in their shortest form that reads back as the same double, strings are
//! quoted when they hold a comma, a quote or a line break, and a null is an empty field. The
//! stage's table holds the same rows and columns as the CSV, so `woodpile diff` checks them.
//! A column of lists (a design's `sites`) cannot be written as one CSV field: name the
//! columns you want without it.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use polars::prelude::{AnyValue, DataFrame, IdxCa, IdxSize};
use serde_json::json;

use woodpile_files::layout;
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{wrong_inputs, Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::{matching_rows, missing_column, Match};
use woodpile_pipeline::Output;

/// A parsed table stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The columns written, in order; empty means all of them.
    pub columns: Vec<String>,
    /// Row filter.
    pub filter: Vec<(String, Match)>,
}

impl Table {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Table> {
        let columns: Vec<String> = fields.optional("columns")?.unwrap_or_default();
        if let Some(twice) = columns
            .iter()
            .enumerate()
            .find_map(|(i, c)| columns[..i].contains(c).then_some(c))
        {
            return Err(fields.error("columns", format!("`{twice}` is listed twice")));
        }
        Ok(Table {
            columns,
            filter: fields.equality_filter("where")?,
        })
    }

    /// The selected rows and columns of `input`.
    pub fn select(&self, input: &DataFrame) -> std::result::Result<DataFrame, String> {
        let named = self
            .columns
            .iter()
            .chain(self.filter.iter().map(|(c, _)| c));
        if let Some(missing) = named.into_iter().find(|c| input.column(c).is_err()) {
            return Err(missing_column(input, missing));
        }
        let rows = matching_rows(input, &self.filter).map_err(|e| e.to_string())?;
        let idx = IdxCa::from_vec("idx".into(), rows.iter().map(|&r| r as IdxSize).collect());
        let mut frame = input.take(&idx).map_err(|e| e.to_string())?;
        if !self.columns.is_empty() {
            frame = frame
                .select(self.columns.iter().map(|c| c.as_str()))
                .map_err(|e| e.to_string())?;
        }
        Ok(frame)
    }

    fn compute(&self, ctx: &Context<'_>, input: &DataFrame) -> Result<Output> {
        let stage = ctx.name();
        let fail = |reason: String| PipelineError::stage(stage, reason);
        let frame = self.select(input).map_err(fail)?;
        let text = csv(&frame).map_err(fail)?;
        ctx.write_file(&csv_path(ctx.results, stage), text.as_bytes())?;
        let summary = json!({
            "rows": frame.height(),
            "columns": frame.get_column_names().iter().map(|c| c.to_string()).collect::<Vec<_>>(),
            "csv": format!("{stage}.csv"),
        });
        Ok(Output::table(frame, summary))
    }
}

/// Where stage `name` writes its CSV.
fn csv_path(results: &Path, name: &str) -> PathBuf {
    layout::output_path(results, name).with_extension("csv")
}

/// `frame` as CSV: a header of column names, then a line per row.
pub fn csv(frame: &DataFrame) -> std::result::Result<String, String> {
    let columns = frame.columns();
    let mut out = String::new();
    let names: Vec<String> = columns.iter().map(|c| field(c.name())).collect();
    out.push_str(&names.join(","));
    out.push('\n');
    for row in 0..frame.height() {
        for (k, column) in columns.iter().enumerate() {
            if k > 0 {
                out.push(',');
            }
            let value = column.get(row).map_err(|e| e.to_string())?;
            match value {
                AnyValue::Null => {}
                AnyValue::Float64(x) => write!(out, "{x:?}").unwrap_or(()),
                AnyValue::Float32(x) => write!(out, "{x:?}").unwrap_or(()),
                AnyValue::Int64(i) => write!(out, "{i}").unwrap_or(()),
                AnyValue::Int32(i) => write!(out, "{i}").unwrap_or(()),
                AnyValue::UInt64(i) => write!(out, "{i}").unwrap_or(()),
                AnyValue::UInt32(i) => write!(out, "{i}").unwrap_or(()),
                AnyValue::Boolean(b) => write!(out, "{b}").unwrap_or(()),
                AnyValue::String(s) => out.push_str(&field(s)),
                AnyValue::StringOwned(s) => out.push_str(&field(&s)),
                other => {
                    return Err(format!(
                        "column `{}` holds {} values, which a CSV field cannot hold: leave it out of `columns`",
                        column.name(),
                        other.dtype()
                    ))
                }
            }
        }
        out.push('\n');
    }
    Ok(out)
}

/// A text field, quoted (with its quotes doubled) when it holds a comma, a quote or a line
/// break (RFC 4180).
fn field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

impl Kind for Table {
    fn check_inputs(&self, stage: &Stage, _: &Inputs<'_>) -> KindCheck {
        match stage.inputs.len() {
            1 => Ok(()),
            _ => wrong_inputs("a table stage reads exactly one stage"),
        }
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        let input = ctx.input(&ctx.stage.inputs[0])?;
        self.compute(ctx, &input)
    }

    fn files(&self, stage: &str, results: &Path, _: &Path) -> Vec<PathBuf> {
        vec![csv_path(results, stage)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use woodpile_pipeline::table::Columns;

    #[test]
    fn csv_writes_numbers_exactly_nulls_empty_and_quotes_what_needs_it() {
        let mut columns = Columns::new();
        columns
            .f64("x", vec![Some(0.1), None, Some(1e-300)])
            .i64("n", vec![Some(1), Some(2), Some(3)])
            .str("why", vec![None, Some("a, \"b\"".into()), Some("c".into())]);
        let text = csv(&columns.into_frame().unwrap()).unwrap();
        assert_eq!(text, "x,n,why\n0.1,1,\n,2,\"a, \"\"b\"\"\"\n1e-300,3,c\n");
    }

    #[test]
    fn rows_and_columns_are_selected_by_name() {
        let mut columns = Columns::new();
        columns.f64("a", vec![Some(1.0), Some(2.0), Some(3.0)]).str(
            "b",
            vec![Some("x".into()), Some("y".into()), Some("x".into())],
        );
        let frame = columns.into_frame().unwrap();
        let table = Table {
            columns: vec!["a".into()],
            filter: vec![("b".into(), Match::Text("x".into()))],
        };
        assert_eq!(
            csv(&table.select(&frame).unwrap()).unwrap(),
            "a\n1.0\n3.0\n"
        );
        let missing = Table {
            columns: vec!["c".into()],
            filter: Vec::new(),
        };
        assert!(missing.select(&frame).unwrap_err().contains("`c`"));
    }
}
