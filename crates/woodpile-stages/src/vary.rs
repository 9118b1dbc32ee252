//! `kind = "vary"`: the best scenes that `optimize` and `design` stages found, varied along
//! axes their searches did not have (a precompression, a striker's mass). Each input's
//! `results/<stage>.best.toml` gets `[set]` laid over it and its `unset` keys removed, and is
//! then simulated at every point of `[axes]`, as a sweep would.
//!
//! ```toml
//! kind = "vary"
//! inputs = ["f7_coarse_optimum", "trap_design"]   # optimize or design stages
//! unset = ["impulse"]                             # optional: dotted keys of the best scenes to drop
//! [axes]
//! M = { from = 1.0, to = 100.0, count = 9, log = true }
//! [set]                                           # laid over each best scene, "$axis" placeholders
//! striker = { mass = "$M", velocity = 1.0 }
//! chain = { boundary = { left = "free", right = "fixed" } }
//! [set_each]                                      # optional: laid over every element of an array of tables
//! defect = { quality_factor = "$Q" }
//! ```
//!
//! `[set]` merges into the best scene table by table: a key inside a table that both have
//! replaces only that key, and any other value (arrays of tables such as `[[defect]]`
//! included) replaces the best scene's whole value. `[set_each]` reaches inside an array of
//! tables whose length the best scenes decide (each design has its own defects): its table is
//! merged into every element. An `unset` key that the best scene does not have is an error, and
//! so is a `set_each` name that is not an array of tables there, so that a misspelt key cannot
//! silently leave the scene as it was.
//!
//! Output: each input's sweep table (one row per sample of each point, `S` after `E_tr` with a
//! striker), stacked in the order of `inputs`, after a `design` column naming the input stage
//! and `design_index`, its place in `inputs` (a figure draws a curve per design with `series =
//! "design_index"` and `series_label = "design"`).
//! Points are cached and shared as a sweep's are. `units = "SI"` gives the table in SI, as a
//! sweep's (inputs whose best scenes are `[physical]`, such as a design of defect rods).

use crate::grid::{parse_axes, Axis};
use polars::prelude::{Column, DataFrame};
use serde_json::json;
use woodpile_files::PointStats;
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{
    wrong_inputs, Context, Inputs, Kind, KindCheck, PointGrid, PointsAt,
};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::Output;
use woodpile_points::Shares;
use woodpile_scene::template::Template;
use woodpile_scene::units_out::Units;
use woodpile_sim::integrate::MethodChoice;

use crate::sweep::Sweep;
use crate::table_units;

/// The column naming the input stage whose best scene a row varies.
pub const DESIGN: &str = "design";
/// Its place in `inputs`, from 0: what a figure's `series` draws one curve per.
pub const DESIGN_INDEX: &str = "design_index";

/// A parsed vary stage.
#[derive(Debug, Clone)]
pub struct Vary {
    axes: Vec<Axis>,
    set: toml::Table,
    set_each: toml::Table,
    unset: Vec<String>,
    file: std::path::PathBuf,
    /// The units of its table.
    units: Units,
}

impl Vary {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Vary> {
        let table: toml::Table = fields.required("axes")?;
        let axes = parse_axes(fields.nested("axes", table))?;
        let set: toml::Table = fields.required("set")?;
        let set_each: toml::Table = fields.optional("set_each")?.unwrap_or_default();
        if let Some((name, _)) = set_each.iter().find(|(_, v)| !v.is_table()) {
            return Err(fields.error(
                &format!("set_each.{name}"),
                format!(
                    "expected a table, laid over every element of the array of tables `{name}`"
                ),
            ));
        }
        // Every placeholder names an axis and every axis is used, before any input exists.
        let mut placed = set.clone();
        placed.insert("set_each".into(), toml::Value::Table(set_each.clone()));
        Template::new(placed, &axes).map_err(|(key, reason)| {
            let key = match key.strip_prefix("scene.set_each") {
                Some(k) => format!("set_each{k}"),
                None => key
                    .strip_prefix("scene")
                    .map_or(key.clone(), |k| format!("set{k}")),
            };
            fields.error(&key, reason)
        })?;
        let unset: Vec<String> = fields.optional("unset")?.unwrap_or_default();
        let units = table_units::parse(fields)?;
        if let Some(bad) = unset.iter().find(|k| k.split('.').any(str::is_empty)) {
            return Err(fields.error("unset", format!("`{bad}` is not a dotted key")));
        }
        Ok(Vary {
            axes,
            set,
            set_each,
            unset,
            file: fields.file().to_path_buf(),
            units,
        })
    }

    /// The sweep of `design`'s best scene (in `results`), varied.
    fn sweep_of(&self, ctx: &Context<'_>, design: &str) -> Result<Sweep> {
        let stage = ctx.name();
        let path = ctx.best_scene(design)?;
        let text = woodpile_files::input::read_input(&path).map_err(|reason| {
            PipelineError::stage(stage, format!("{}: {reason}", path.display()))
        })?;
        let mut scene: toml::Table = toml::from_str(&text).map_err(|e| {
            let reason = woodpile_files::input::syntax_reason(&e, &text);
            PipelineError::stage(stage, format!("{}: {reason}", path.display()))
        })?;
        for key in &self.unset {
            remove_dotted(&mut scene, key).map_err(|reason| {
                PipelineError::stage(
                    stage,
                    format!("unset: `{key}` {reason} of `{design}`'s best scene"),
                )
            })?;
        }
        woodpile_pipeline::stage::merge(&mut scene, self.set.clone());
        for (name, over) in &self.set_each {
            set_each(&mut scene, name, over).map_err(|reason| {
                PipelineError::stage(
                    stage,
                    format!("set_each: `{name}` {reason} in `{design}`'s best scene"),
                )
            })?;
        }
        let sweep =
            Sweep::over(self.axes.clone(), Shares::Energy, scene, &self.file).map_err(|e| {
                PipelineError::stage(stage, format!("`{design}`'s best scene, varied: {e}"))
            })?;
        sweep.in_units(self.units).map_err(|reason| {
            PipelineError::stage(stage, format!("units: `{design}`'s best scene: {reason}"))
        })
    }
}

/// Merges `over` (a table) into every element of the array of tables `name` of `scene`.
fn set_each(
    scene: &mut toml::Table,
    name: &str,
    over: &toml::Value,
) -> std::result::Result<(), &'static str> {
    let (Some(toml::Value::Array(elements)), toml::Value::Table(over)) =
        (scene.get_mut(name), over)
    else {
        return Err("is not an array of tables");
    };
    for element in elements {
        let toml::Value::Table(element) = element else {
            return Err("is not an array of tables");
        };
        woodpile_pipeline::stage::merge(element, over.clone());
    }
    Ok(())
}

/// Removes the dotted `key` from `table`; the error says why it could not.
fn remove_dotted(table: &mut toml::Table, key: &str) -> std::result::Result<(), &'static str> {
    match key.split_once('.') {
        None => table.remove(key).map(|_| ()).ok_or("names no key"),
        Some((head, rest)) => match table.get_mut(head) {
            Some(toml::Value::Table(inner)) => remove_dotted(inner, rest),
            _ => Err("names no table"),
        },
    }
}

/// `frame` with first columns `design` and `design_index` holding `name` and `index` on
/// every row.
fn with_design(frame: DataFrame, name: &str, index: usize) -> Result<DataFrame> {
    let mut columns = vec![
        Column::new(DESIGN.into(), vec![name; frame.height()]),
        Column::new(DESIGN_INDEX.into(), vec![index as i64; frame.height()]),
    ];
    columns.extend(frame.columns().iter().cloned());
    DataFrame::new_infer_height(columns)
        .map_err(|e| PipelineError::stage(name, format!("its design column: {e}")))
}

impl Kind for Vary {
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck {
        let searches = ["optimize", "design"];
        match stage.inputs.iter().find(|i| !searches.contains(&inputs.kind_of(i))) {
            None if !stage.inputs.is_empty() => Ok(()),
            _ => wrong_inputs("a vary stage reads one or more optimize or design stages, whose best scenes it varies"),
        }
    }

    fn sharing(&self) -> woodpile_pipeline::kind::Sharing {
        woodpile_pipeline::kind::Sharing::Parallel
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        let at = PointsAt {
            stage: ctx.name(),
            points: ctx.points,
            events: ctx.events,
        };
        let mut stacked: Option<DataFrame> = None;
        let mut units = json!({});
        let mut stats = PointStats::default();
        let mut tolerance = None;
        for (index, design) in ctx.stage.inputs.iter().enumerate() {
            let sweep = self.sweep_of(ctx, design)?;
            sweep.declare_units(&mut units);
            let all: Vec<usize> = (0..sweep.count()).collect();
            let first = sweep.scene_at(0)?.scenario;
            let asked = first.method == MethodChoice::Auto || first.accuracy.tolerance_explicit;
            tolerance = tolerance.or(asked.then_some(first.accuracy.tolerance));
            let (frame, part) = sweep.run_points(at, &all)?;
            if let Some(first) = &stacked {
                if first.width() != frame.width() + 2 {
                    return Err(PipelineError::stage(
                        ctx.name(),
                        format!("`{design}`'s varied scenes have other columns than the first input's (a striker in one and not the other?): vary inputs whose scenes have the same sections"),
                    ));
                }
            }
            let frame = with_design(frame, design, index)?;
            stats = stats.merge(part);
            stacked = Some(match stacked {
                None => frame,
                Some(f) => f
                    .vstack(&frame)
                    .map_err(|e| PipelineError::stage(ctx.name(), e.to_string()))?,
            });
        }
        let frame = stacked.ok_or_else(|| PipelineError::stage(ctx.name(), "no inputs"))?;
        let mut summary = json!({
                "points": stats.points,
                "failed": stats.failed,
                "designs": ctx.stage.inputs,
                "axes": self.axes.iter().map(|a| a.name.clone()).collect::<Vec<_>>(),
                "tolerance": tolerance,
                "rhs_evals": stats.rhs_evals,
                "max_error_estimate": stats.max_error_estimate,
                "max_energy_drift": stats.max_energy_drift,
        });
        for key in ["units", "column_units"] {
            if let Some(value) = units.get(key) {
                summary[key] = value.clone();
            }
        }
        Ok(Output::table(frame, summary).with_points(stats))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn set_merges_tables_and_replaces_everything_else() {
        let mut base =
            table("chain = { n = 100, boundary = \"fixed\" }\n[[defect]]\nsite = 0\neps = 1.0\n");
        woodpile_pipeline::stage::merge(
            &mut base,
            table("chain = { precompression = 0.5 }\n[[defect]]\nsite = 3\neps = 2.0\n"),
        );
        assert_eq!(
            base,
            table("chain = { n = 100, boundary = \"fixed\", precompression = 0.5 }\n[[defect]]\nsite = 3\neps = 2.0\n")
        );
    }

    #[test]
    fn set_each_reaches_every_element_and_names_a_missing_array() {
        let mut base = table("[[defect]]\nsite = 0\neps = 1.0\n[[defect]]\nsite = 3\neps = 2.0\n");
        let over = toml::Value::Table(table("damping = 0.5\n"));
        set_each(&mut base, "defect", &over).unwrap();
        assert_eq!(
            base,
            table("[[defect]]\nsite = 0\neps = 1.0\ndamping = 0.5\n[[defect]]\nsite = 3\neps = 2.0\ndamping = 0.5\n")
        );
        assert_eq!(
            set_each(&mut base, "segment", &over),
            Err("is not an array of tables")
        );
    }

    #[test]
    fn unset_removes_a_dotted_key_and_names_a_missing_one() {
        let mut base =
            table("impulse = { site = -25 }\nrun = { t_end = 150.0, sample_every = 10.0 }\n");
        remove_dotted(&mut base, "run.sample_every").unwrap();
        remove_dotted(&mut base, "impulse").unwrap();
        assert_eq!(base, table("run = { t_end = 150.0 }\n"));
        assert_eq!(
            remove_dotted(&mut base, "run.tolerance"),
            Err("names no key")
        );
        assert_eq!(
            remove_dotted(&mut base, "striker.mass"),
            Err("names no table")
        );
    }
}
