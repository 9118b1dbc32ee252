//! Axis units from the tables. A label may end with its unit in parentheses, `"t (µs)"`: when
//! the input's manifest says the column's unit (`column_units`, written by stages over scenes
//! with scales), the column is drawn in the label's unit (seconds × 1e6 for µs), and a label
//! whose unit the column cannot be in (µs on a column in the model's scaled units, or m/s on a
//! time) is refused. A figure of scaled numbers can then not be labelled in µs.

use polars::prelude::*;
use serde_json::Value;
use woodpile_pipeline::error::Result;
use woodpile_pipeline::manifest::Manifest;
use woodpile_pipeline::table::f64_column;
use woodpile_scene::quantity::{self, Unit};
use woodpile_scene::units_out::SCALED;

use super::spec::{PanelSpec, Plot};

/// The unit named at the end of `label`, in parentheses, if woodpile knows it.
fn label_unit(label: &str) -> Option<Unit> {
    let inner = label.trim_end().strip_suffix(')')?;
    quantity::named(inner[inner.rfind('(')? + 1..].trim())
}

/// By how much to multiply `column` so that it is in `label`'s unit: `None` when the label
/// names no unit or the manifest says nothing of the column; an error when the two disagree.
fn factor(
    label: &str,
    column: &str,
    input: &str,
    manifest: &Manifest,
) -> std::result::Result<Option<f64>, String> {
    let Some(Unit {
        name: unit,
        measures,
        size,
    }) = label_unit(label)
    else {
        return Ok(None);
    };
    let Some(declared) = manifest.summary["column_units"]
        .get(column)
        .and_then(Value::as_str)
    else {
        return Ok(None);
    };
    if declared == SCALED {
        return Err(format!(
            "the label \"{label}\" names {unit}, but column `{column}` of `{input}` is in the model's scaled units: give `{input}` units = \"SI\", or label the axis in scaled units"
        ));
    }
    match quantity::named(declared) {
        Some(column) if column.measures == measures => Ok(Some(column.size / size)),
        _ => Err(format!(
            "the label \"{label}\" names {unit} ({measures}), but column `{column}` of `{input}` is in {declared}"
        )),
    }
}

/// `frame` with each column `spec` draws in the unit its label names (see the module
/// documentation); the frame itself when no label names a unit.
pub(super) fn in_label_units(
    spec: &PanelSpec,
    frame: &DataFrame,
    manifest: &Manifest,
) -> std::result::Result<DataFrame, String> {
    let axes: Vec<(&str, &str)> = match &spec.plot {
        Plot::Lines {
            x,
            y,
            x_label,
            y_label,
            ..
        } => std::iter::once((x.as_str(), x_label.as_str()))
            .chain(y.iter().map(|c| (c.as_str(), y_label.as_str())))
            .collect(),
        Plot::Heatmap {
            x,
            y,
            z,
            x_label,
            y_label,
            z_label,
            ..
        } => vec![
            (x.as_str(), x_label.as_str()),
            (y.as_str(), y_label.as_str()),
            (z.as_str(), z_label.as_str()),
        ],
    };
    let mut scaled = frame.clone();
    for (column, label) in axes {
        let Some(f) = factor(label, column, &spec.input, manifest)? else {
            continue;
        };
        if f != 1.0 {
            scale(&mut scaled, column, f).map_err(|e| e.to_string())?;
        }
    }
    Ok(scaled)
}

/// Multiplies `column` of `frame` by `factor`.
fn scale(frame: &mut DataFrame, column: &str, factor: f64) -> Result<()> {
    let values: Vec<Option<f64>> = f64_column(frame, column)?
        .into_iter()
        .map(|v| v.map(|x| x * factor))
        .collect();
    frame
        .with_column(Column::new(column.into(), values))
        .map_err(|e| woodpile_pipeline::error::PipelineError::stage("render", e.to_string()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_read_from_the_end_of_a_label() {
        assert_eq!(label_unit("t (µs)").map(|u| u.name), Some("µs"));
        assert_eq!(label_unit("frequency (kHz)").map(|u| u.size), Some(1e3));
        assert_eq!(label_unit("t (1 unit = 9.08 µs)"), None);
        assert_eq!(label_unit("log₁₀ wall time (ms) of runs"), None);
        assert_eq!(label_unit("velocity"), None);
    }
}
