//! The `units` key of the stages that tabulate scenes (`sweep`, `spacetime`), and the
//! `column_units` their manifests carry, from which `render` takes its axis units.

use serde_json::{json, Map, Value};
use woodpile_pipeline::error::Result;
use woodpile_pipeline::fields::Fields;
use woodpile_scene::units_out::{Units, SCALED};

/// The stage's optional `units = "SI" | "scaled"` (default: scaled, the model's own units).
pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Units> {
    match fields.optional::<String>("units")? {
        None => Ok(Units::Scaled),
        Some(name) => Units::parse(&name).map_err(|reason| fields.error("units", reason)),
    }
}

/// Writes `column_units` into `summary`: each of `columns` (a column and its SI unit) in that
/// unit, or in the model's scaled units; and `units = "SI"` when the table is in SI.
pub(crate) fn declare(summary: &mut Value, units: Units, columns: &[(&str, &str)]) {
    let declared: Map<String, Value> = columns
        .iter()
        .map(|&(column, si)| {
            let unit = match units {
                Units::Si => si,
                Units::Scaled => SCALED,
            };
            (column.to_string(), json!(unit))
        })
        .collect();
    summary["column_units"] = Value::Object(declared);
    if units == Units::Si {
        summary["units"] = json!(Units::Si.name());
    }
}
