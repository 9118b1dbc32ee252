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
use crate::reduce::MAXIMIZABLE;
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
        let (best_x, best_value) =
            nelder_mead(&mut objective, &start, &steps, grid_value, MAX_EVALUATIONS)?;
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

/// Maximises `f` by Nelder–Mead from `start` with initial steps `steps`, in at most `budget`
/// evaluations; `f(start)` is given.
pub(crate) fn nelder_mead(
    f: &mut dyn FnMut(&[f64]) -> Result<f64>,
    start: &[f64],
    steps: &[f64],
    f_start: f64,
    budget: usize,
) -> Result<(Vec<f64>, f64)> {
    let n = start.len();
    // Minimise -f.
    let mut simplex: Vec<(Vec<f64>, f64)> = vec![(start.to_vec(), -f_start)];
    for i in 0..n {
        let mut x = start.to_vec();
        x[i] += 0.5 * steps[i];
        let v = -f(&x)?;
        simplex.push((x, v));
    }
    let size = |s: &[(Vec<f64>, f64)]| -> f64 {
        (0..n)
            .map(|i| {
                let (lo, hi) = s
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                        (l.min(p.0[i]), h.max(p.0[i]))
                    });
                (hi - lo) / steps[i]
            })
            .fold(0.0, f64::max)
    };
    let mut spent = n + 1;
    while spent < budget && size(&simplex) > 1e-3 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let centroid: Vec<f64> = (0..n)
            .map(|i| simplex[..n].iter().map(|p| p.0[i]).sum::<f64>() / n as f64)
            .collect();
        let worst = simplex[n].clone();
        let along = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|i| centroid[i] + t * (worst.0[i] - centroid[i]))
                .collect()
        };
        let xr = along(-1.0);
        let fr = -f(&xr)?;
        spent += 1;
        if fr < simplex[0].1 {
            let xe = along(-2.0);
            let fe = -f(&xe)?;
            spent += 1;
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let xc = if fr < worst.1 {
                along(-0.5)
            } else {
                along(0.5)
            };
            let fc = -f(&xc)?;
            spent += 1;
            if fc < worst.1.min(fr) {
                simplex[n] = (xc, fc);
            } else {
                // Shrink towards the best vertex.
                let best = simplex[0].0.clone();
                for p in simplex.iter_mut().skip(1) {
                    p.0 = (0..n).map(|i| best[i] + 0.5 * (p.0[i] - best[i])).collect();
                    p.1 = -f(&p.0)?;
                    spent += 1;
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    Ok((simplex[0].0.clone(), -simplex[0].1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nelder_mead_finds_a_smooth_maximum_between_grid_points() {
        let mut f = |x: &[f64]| -> Result<f64> {
            Ok(1.0 - (x[0] - 0.37).powi(2) - 2.0 * (x[1] + 0.21).powi(2))
        };
        let start = [0.0, 0.0];
        let f0 = f(&start).unwrap();
        let (x, v) = nelder_mead(&mut f, &start, &[0.1, 0.1], f0, MAX_EVALUATIONS).unwrap();
        assert!(
            (x[0] - 0.37).abs() < 1e-3 && (x[1] + 0.21).abs() < 1e-3,
            "{x:?}"
        );
        assert!(v > f0 && (v - 1.0).abs() < 1e-5);
    }
}
