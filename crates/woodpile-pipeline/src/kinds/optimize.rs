//! `kind = "optimize"`: beyond the grid. Starting from the best grid point of a reduced sweep,
//! Nelder–Mead searches the continuous parameter box for the true maximum, simulating each
//! trial scene (at a tighter tolerance) with the sweep's own scene template.
//!
//! ```toml
//! kind = "optimize"
//! inputs = ["f7_coarse"]        # a reduce stage (no maximize) read at the sweep's t_end
//! column = "E_tr"               # E_tr, R or T
//! over = ["eps1", "eps2"]       # float axes of the sweep; the others stay at the grid optimum
//! tolerance = 1e-8              # scene tolerance of the refinement runs
//! ```
//!
//! Output: two rows, `grid` (the grid maximum, re-simulated at the refinement tolerance so the
//! two are comparable) and `refined`, with the axis values, the column's value and the number
//! of simulations.

use serde_json::json;
use woodpile_sim::run::simulate;

use crate::error::{PipelineError, Result};
use crate::fields::Fields;
use crate::grid::AxisValue;
use crate::kind::{Context, Inputs, Kind, KindCheck};
use crate::reduce::Reduce;
use crate::reduce::MAXIMIZABLE;
use crate::stage::Stage;
use crate::sweep::Sweep;
use crate::table::{f64_column, Columns};
use crate::Output;

/// A parsed optimize stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Optimize {
    /// The column maximised.
    pub column: String,
    /// The axes searched.
    pub over: Vec<String>,
    /// Scene tolerance of the refinement runs.
    pub tolerance: f64,
}

/// Most simulations one search may spend.
const MAX_EVALUATIONS: usize = 120;

impl Optimize {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Optimize> {
        let column: String = fields.optional("column")?.unwrap_or_else(|| "E_tr".into());
        if !MAXIMIZABLE.contains(&column.as_str()) {
            return Err(fields.error("column", format!("expected one of {MAXIMIZABLE:?}")));
        }
        let over: Vec<String> = fields.required("over")?;
        if over.is_empty() {
            return Err(fields.error("over", "name at least one axis"));
        }
        let tolerance: f64 = fields.optional("tolerance")?.unwrap_or(1e-8);
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(fields.error("tolerance", "expected a number in (0, 1)"));
        }
        Ok(Optimize {
            column,
            over,
            tolerance,
        })
    }

    /// Checks `over` against the sweep: float axes only.
    pub(crate) fn check_axes(&self, sweep: &Sweep) -> Result<(), String> {
        for name in &self.over {
            match sweep.axes.iter().find(|a| &a.name == name) {
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

    pub(crate) fn run(
        &self,
        stage: &str,
        input: &polars::prelude::DataFrame,
        sweep: &Sweep,
    ) -> Result<Output> {
        let fail = |reason: String| PipelineError::stage(stage, reason);
        let col = |name: &str| f64_column(input, name).map_err(|e| fail(e.to_string()));
        let target = col(&self.column)?;
        let best_row = (0..input.height())
            .filter(|&r| target[r].is_some_and(f64::is_finite))
            .max_by(|&a, &b| {
                target[a]
                    .unwrap_or(f64::MIN)
                    .total_cmp(&target[b].unwrap_or(f64::MIN))
            })
            .ok_or_else(|| fail("no finite values to maximise".into()))?;
        let grid_values: Vec<AxisValue> = sweep
            .axes
            .iter()
            .map(|a| {
                let v = col(&a.name)?[best_row].unwrap_or(f64::NAN);
                Ok(if a.is_integer() {
                    AxisValue::Int(v as i64)
                } else {
                    AxisValue::Float(v)
                })
            })
            .collect::<Result<_>>()?;
        let searched: Vec<usize> = self
            .over
            .iter()
            .filter_map(|n| sweep.axes.iter().position(|a| &a.name == n))
            .collect();
        let bounds: Vec<(f64, f64, f64)> = searched
            .iter()
            .map(|&k| {
                let values: Vec<f64> = sweep.axes[k].values.iter().map(|v| v.as_f64()).collect();
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
                (lo, hi, spacing)
            })
            .collect();
        let mut evaluations = 0;
        let mut objective = |x: &[f64]| -> Result<f64> {
            evaluations += 1;
            let mut values = grid_values.clone();
            for (slot, &k) in searched.iter().enumerate() {
                let (lo, hi, _) = bounds[slot];
                values[k] = AxisValue::Float(x[slot].clamp(lo, hi));
            }
            let scene = sweep.scene_with(&values, Some(self.tolerance))?;
            crate::points::count_simulation();
            let out = simulate(&scene.scenario, &mut ())
                .map_err(|e| fail(format!("refinement scene failed: {e}")))?;
            let f = out.fractions;
            Ok(match self.column.as_str() {
                "R" => f.reflected,
                "T" => f.transmitted,
                _ => f.trapped,
            })
        };
        let start: Vec<f64> = searched.iter().map(|&k| grid_values[k].as_f64()).collect();
        let grid_value = objective(&start)?;
        let steps: Vec<f64> = bounds.iter().map(|b| b.2).collect();
        let (best_x, best_value) = woodpile_analysis::nelder_mead::maximise(
            &mut objective,
            &start,
            &steps,
            grid_value,
            MAX_EVALUATIONS,
        )?;
        let clamped: Vec<f64> = best_x
            .iter()
            .zip(&bounds)
            .map(|(x, b)| x.clamp(b.0, b.1))
            .collect();
        let mut columns = Columns::new();
        columns.str("point", vec![Some("grid".into()), Some("refined".into())]);
        for (slot, &k) in searched.iter().enumerate() {
            columns.f64(
                &sweep.axes[k].name,
                vec![Some(start[slot]), Some(clamped[slot])],
            );
        }
        columns.f64(&self.column, vec![Some(grid_value), Some(best_value)]);
        columns.f64("grid_table_value", vec![target[best_row], None]);
        columns.i64("simulations", vec![Some(1), Some(evaluations as i64)]);
        Ok(Output {
            failures: Vec::new(),
            frame: columns.into_frame()?,
            summary: json!({"grid": grid_value, "refined": best_value, "gain": best_value - grid_value, "simulations": evaluations}),
        })
    }
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
            .pipeline
            .stage(input)?
            .inputs
            .first()
            .and_then(|s| ctx.pipeline.sweep(s))
            .ok_or_else(|| {
                PipelineError::stage(ctx.name(), format!("`{input}` does not read a sweep"))
            })?;
        self.run(ctx.name(), &frame, sweep)
    }
}
