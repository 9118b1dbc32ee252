//! `kind = "optimize"`: beyond the grid. Starting from the best grid points of a reduced
//! sweep, Nelder–Mead searches a continuous box of the parameters for the true maximum,
//! simulating each trial scene (at a tighter tolerance) with the sweep's own scene template.
//!
//! ```toml
//! kind = "optimize"
//! inputs = ["f7_coarse"]        # a reduce stage (no maximize) read at the sweep's t_end
//! column = "E_tr"               # E_tr, R or T
//! over = ["eps1", "eps2"]       # float axes of the sweep; the others stay at the grid optimum
//! tolerance = 1e-8              # scene tolerance of the refinement runs
//! bounds = { eps1 = [1.0, 100.0] }   # optional: the box; an axis not named spans its grid values
//! starts = 3                    # optional: refine from the 3 best grid points (default 1)
//! ```
//!
//! **The box.** Each searched axis ranges over `bounds`, or else from its smallest to its
//! largest grid value; trials outside are clamped to it. Nelder–Mead's first steps are one grid
//! spacing.
//!
//! Output: two rows per start, `grid` (the grid point, re-simulated at the refinement
//! tolerance so the two are comparable) and `refined`, with `start`, the axis values, `R`,
//! `T`, `E_tr`, `error_estimate`, the grid table's value and the simulations spent; and for a
//! refined optimum, `sensitivity_<axis>` (the largest change of the column when that axis
//! alone moves by ±1%: a knife-edge optimum shows a large one) and `edge_<axis>` (1 when the
//! optimum lies on the box's edge). The summary says whether the starts agree and flags a
//! sharp optimum; `results/<stage>.best.toml` is the best optimum as a scene file.

use std::path::{Path, PathBuf};

use serde_json::json;
use woodpile_sim::simulation::Outcome;

use crate::grid::AxisValue;
use crate::reduce::Reduce;
use crate::sweep::Sweep;
use woodpile_files::layout::best_path;
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::{Ends, Fields};
use woodpile_pipeline::kind::{Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::{f64_column, Columns};
use woodpile_pipeline::Output;

use crate::schema::Fraction;

mod search;

use search::{OptimumRow, Search};

/// A parsed optimize stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Optimize {
    /// The fraction maximised.
    pub column: Fraction,
    /// The axes searched.
    pub over: Vec<String>,
    /// Scene tolerance of the refinement runs.
    pub tolerance: f64,
    /// Explicit `[lo, hi]` per searched axis (others span their grid values).
    pub bounds: Vec<(String, f64, f64)>,
    /// How many of the best grid points to refine from.
    pub starts: usize,
}

/// A change of the column this large under a ±1% move flags the optimum as sharp.
const SHARP: f64 = 0.01;
/// Starts agree when their optima's values are this close.
const AGREE: f64 = 1e-3;

impl Optimize {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Optimize> {
        let column = fields.choice("column", &Fraction::OPTIONS, Some(Fraction::Trapped))?;
        let over: Vec<String> = fields.required("over")?;
        if over.is_empty() {
            return Err(fields.error("over", "name at least one axis"));
        }
        let tolerance: f64 = fields.optional("tolerance")?.unwrap_or(1e-8);
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(fields.error("tolerance", "expected a number in (0, 1)"));
        }
        let mut bounds = Vec::new();
        if let Some(table) = fields.optional::<toml::Table>("bounds")? {
            let mut f = fields.nested("bounds", table);
            for name in f.keys() {
                if let Some([lo, hi]) = f.interval(&name, Ends::Apart)? {
                    if !over.contains(&name) {
                        return Err(f.error(&name, "bounds only axes named in `over`"));
                    }
                    bounds.push((name, lo, hi));
                }
            }
        }
        let starts = match fields.optional::<i64>("starts")? {
            None => 1,
            Some(n) if (1..=20).contains(&n) => n as usize,
            Some(_) => return Err(fields.error("starts", "expected 1 to 20")),
        };
        Ok(Optimize {
            column,
            over,
            tolerance,
            bounds,
            starts,
        })
    }

    /// Checks `over` against the sweep: float axes only.
    pub(crate) fn check_axes(&self, sweep: &Sweep) -> Result<(), String> {
        for name in &self.over {
            match sweep.grid.axes.iter().find(|a| &a.name == name) {
                None => return Err(format!("`{name}` is not an axis of the sweep")),
                Some(a) if a.is_integer() => {
                    return Err(format!(
                        "`{name}` is an integer axis: nothing between grid points"
                    ))
                }
                Some(_) => {}
            }
        }
        Ok(())
    }

    /// The stage: the best grid rows ranked, each refined by Nelder–Mead inside the box, the
    /// best optimum written as a scene file, then the table and its summary.
    pub(crate) fn compute(
        &self,
        ctx: &Context<'_>,
        input: &polars::prelude::DataFrame,
        sweep: &Sweep,
    ) -> Result<Output> {
        let stage = ctx.name();
        let fail = |reason: String| PipelineError::stage(stage, reason);
        let target = f64_column(input, self.column.column()).map_err(|e| fail(e.to_string()))?;
        let ranked = ranked(&target);
        if ranked.is_empty() {
            return Err(fail("no finite values to maximise".into()));
        }
        let search = Search::new(self, stage, sweep);
        let mut rows: Vec<OptimumRow> = Vec::new();
        for (start_index, &row) in ranked.iter().take(self.starts).enumerate() {
            let base = grid_values_of(input, sweep, row).map_err(|e| fail(e.to_string()))?;
            rows.extend(search.refine_from(start_index, &base, target[row])?);
        }
        let refined: Vec<&OptimumRow> = rows.iter().filter(|r| r.point == "refined").collect();
        let best = refined
            .iter()
            .max_by(|a, b| {
                self.value_of(&a.outcome)
                    .total_cmp(&self.value_of(&b.outcome))
            })
            .copied()
            .ok_or_else(|| fail("no start".into()))?;
        let path = self.write_best(ctx, sweep, best)?;
        let simulations = search.evaluated.borrow().len();
        let summary = self.summary(&search, &rows, best, &path);
        let frame = self.frame(&rows, sweep, &search.searched)?;
        Ok(Output::table(frame, summary).with_simulated(simulations))
    }

    /// The (lo, hi, initial simplex step) of searching `axis`: the grid's range and spacing,
    /// or the stage's own bounds for it.
    fn bounds_of(&self, axis: &crate::grid::Axis) -> (f64, f64, f64) {
        let values: Vec<f64> = axis.values.iter().map(|v| v.as_f64()).collect();
        let (lo, hi) = values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        let spacing = if values.len() > 1 {
            (hi - lo) / (values.len() - 1) as f64
        } else {
            1.0
        };
        match self.bounds.iter().find(|b| b.0 == axis.name) {
            Some(&(_, l, h)) => (l, h, spacing.min(h - l)),
            None => (lo, hi, spacing),
        }
    }

    /// The fraction this stage maximises, of `out`.
    fn value_of(&self, out: &Outcome) -> f64 {
        let f = &out.fractions;
        self.column.of(f.reflected, f.transmitted, f.trapped)
    }

    /// Writes the best optimum as a scene file; its path.
    fn write_best(&self, ctx: &Context<'_>, sweep: &Sweep, best: &OptimumRow) -> Result<PathBuf> {
        let stage = ctx.name();
        let fail = |reason: String| PipelineError::stage(stage, reason);
        let scene = sweep.scene_with(&best.values, Some(self.tolerance))?;
        let path = best_path(ctx.results, stage);
        let table = sweep
            .table_with(&best.values, Some(self.tolerance))
            .map_err(|e| fail(e.to_string()))?;
        let text = toml::to_string(&table).map_err(|e| fail(e.to_string()))?;
        let header = format!(
            "# The optimum stage `{stage}` found: {} = {} at t_end = {}, tolerance {:e}.\n# Run it with: woodpile simulate {}\n",
            self.column.column(),
            self.value_of(&best.outcome),
            scene.scenario.t_end,
            self.tolerance,
            path.display()
        );
        ctx.write_file(&path, (header + &text).as_bytes())?;
        Ok(path)
    }

    /// The manifest's summary: the grid's best against the refined best, whether the starts
    /// agree, whether the optimum is sharp or on the box's edge.
    fn summary(
        &self,
        search: &Search<'_>,
        rows: &[OptimumRow],
        best: &OptimumRow,
        path: &Path,
    ) -> serde_json::Value {
        let best_value = self.value_of(&best.outcome);
        let agree = rows
            .iter()
            .filter(|r| r.point == "refined")
            .all(|r| (self.value_of(&r.outcome) - best_value).abs() <= AGREE);
        let sharp = best
            .sensitivity
            .as_ref()
            .is_some_and(|s| s.iter().any(|&d| d > SHARP));
        let axes = &search.sweep.grid.axes;
        let edge: Vec<&str> = search
            .searched
            .iter()
            .enumerate()
            .filter(|(slot, _)| best.on_edge.as_ref().is_some_and(|e| e[*slot]))
            .map(|(_, &k)| axes[k].name.as_str())
            .collect();
        let grid_first = rows
            .first()
            .map(|r| self.value_of(&r.outcome))
            .unwrap_or(f64::NAN);
        json!({
            "grid": grid_first,
            "refined": best_value,
            "gain": best_value - grid_first,
            "simulations": search.evaluated.borrow().len(),
            "starts": self.starts,
            "starts_agree": agree,
            "sharp": sharp,
            "on_edge": edge,
            "box": search.searched.iter().zip(&search.bounds).map(|(&k, b)| json!({
                "axis": axes[k].name, "lo": b.0, "hi": b.1
            })).collect::<Vec<_>>(),
            "best_error_estimate": best.outcome.error_estimate,
            "best_file": path.file_name().map(|n| n.to_string_lossy().into_owned()),
        })
    }

    fn frame(
        &self,
        rows: &[OptimumRow],
        sweep: &Sweep,
        searched: &[usize],
    ) -> Result<polars::prelude::DataFrame> {
        let mut columns = Columns::new();
        columns.i64("start", rows.iter().map(|r| Some(r.start as i64)).collect());
        columns.str(
            "point",
            rows.iter().map(|r| Some(r.point.to_string())).collect(),
        );
        for &k in searched {
            columns.f64(
                &sweep.grid.axes[k].name,
                rows.iter().map(|r| Some(r.values[k].as_f64())).collect(),
            );
        }
        let f = |pick: fn(&OptimumRow) -> Option<f64>| rows.iter().map(pick).collect::<Vec<_>>();
        columns
            .f64("R", f(|r| Some(r.outcome.fractions.reflected)))
            .f64("T", f(|r| Some(r.outcome.fractions.transmitted)))
            .f64("E_tr", f(|r| Some(r.outcome.fractions.trapped)))
            .f64("error_estimate", f(|r| r.outcome.error_estimate))
            .f64("grid_table_value", f(|r| r.grid_table_value));
        columns.i64(
            "simulations",
            rows.iter().map(|r| Some(r.simulations as i64)).collect(),
        );
        for (slot, &k) in searched.iter().enumerate() {
            let name = &sweep.grid.axes[k].name;
            columns.f64(
                &format!("sensitivity_{name}"),
                rows.iter()
                    .map(|r| r.sensitivity.as_ref().map(|s| s[slot]))
                    .collect(),
            );
            columns.i64(
                &format!("edge_{name}"),
                rows.iter()
                    .map(|r| r.on_edge.as_ref().map(|e| i64::from(e[slot])))
                    .collect(),
            );
        }
        columns.into_frame()
    }
}

/// The rows with a finite `target`, best first (ties in row order).
fn ranked(target: &[Option<f64>]) -> Vec<usize> {
    let mut ranked: Vec<usize> = (0..target.len())
        .filter(|&r| target[r].is_some_and(f64::is_finite))
        .collect();
    ranked.sort_by(|&a, &b| {
        target[b]
            .unwrap_or(f64::MIN)
            .total_cmp(&target[a].unwrap_or(f64::MIN))
            .then(a.cmp(&b))
    });
    ranked
}

/// The axis values of `sweep`'s point on row `row` of its table `input`.
fn grid_values_of(
    input: &polars::prelude::DataFrame,
    sweep: &Sweep,
    row: usize,
) -> std::result::Result<Vec<AxisValue>, PipelineError> {
    sweep
        .grid
        .axes
        .iter()
        .map(|a| {
            let v = f64_column(input, &a.name)?[row].unwrap_or(f64::NAN);
            Ok(if a.is_integer() {
                AxisValue::Int(v as i64)
            } else {
                AxisValue::Float(v)
            })
        })
        .collect()
}

impl Kind for Optimize {
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck {
        let error = |key: &str, reason: String| Err((key.to_string(), reason));
        let [input] = stage.inputs.as_slice() else {
            return error(
                "inputs",
                "an optimize stage reads exactly one reduce stage".into(),
            );
        };
        let Some(reduce) = inputs.get::<Reduce>(input) else {
            return error(
                "inputs[0]",
                format!(
                    "`{input}` is a {} stage; expected a reduce stage",
                    inputs.kind_of(input)
                ),
            );
        };
        if reduce.maximize.is_some() {
            return error(
                "inputs[0]",
                format!("`{input}` maximises already; read a plain reduce"),
            );
        }
        let sweep = inputs
            .stage(input)
            .and_then(|s| s.inputs.first())
            .and_then(|s| inputs.get::<Sweep>(s));
        match sweep {
            Some(sweep) => self
                .check_axes(sweep)
                .map_err(|reason| ("over".to_string(), reason)),
            None => error("inputs[0]", format!("`{input}` does not read a sweep")),
        }
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        let input = &ctx.stage.inputs[0];
        let frame = ctx.input(input)?;
        let sweep = ctx
            .upstream(input)?
            .inputs
            .first()
            .and_then(|s| ctx.upstream(s).ok()?.get::<Sweep>())
            .ok_or_else(|| {
                PipelineError::stage(ctx.name(), format!("`{input}` does not read a sweep"))
            })?;
        self.compute(ctx, &frame, sweep)
    }

    fn files(&self, stage: &str, results: &Path, _: &Path) -> Vec<PathBuf> {
        vec![best_path(results, stage)]
    }
}
