//! One optimisation over a sweep's box: Nelder–Mead from a grid point, each trial a scene
//! simulated once, and the optimum's sensitivity and place in the box.

use std::cell::RefCell;

use woodpile_sim::simulation::{simulate, Outcome};

use super::Optimize;
use crate::grid::AxisValue;
use crate::sweep::Sweep;
use woodpile_pipeline::error::{PipelineError, Result};

/// Relative move of one coordinate in the sensitivity check.
const NUDGE: f64 = 0.01;

/// Most simulations one search may spend.
const MAX_EVALUATIONS: usize = 120;

/// One row of an optimize table.
pub(super) struct OptimumRow {
    pub(super) start: usize,
    pub(super) point: &'static str,
    pub(super) values: Vec<AxisValue>,
    pub(super) outcome: Outcome,
    pub(super) grid_table_value: Option<f64>,
    pub(super) simulations: usize,
    pub(super) sensitivity: Option<Vec<f64>>,
    pub(super) on_edge: Option<Vec<bool>>,
}

/// One optimisation over a sweep's box: the searched axes, their bounds and the simulations
/// made so far (each point once, for the rows and the best file).
pub(super) struct Search<'a> {
    optimize: &'a Optimize,
    stage: &'a str,
    pub(super) sweep: &'a Sweep,
    /// The searched axes (indices into the sweep's axes).
    pub(super) searched: Vec<usize>,
    /// (lo, hi, initial simplex step) of each searched axis.
    pub(super) bounds: Vec<(f64, f64, f64)>,
    pub(super) evaluated: RefCell<Vec<(Vec<AxisValue>, Outcome)>>,
}

impl<'a> Search<'a> {
    pub(super) fn new(optimize: &'a Optimize, stage: &'a str, sweep: &'a Sweep) -> Self {
        let searched: Vec<usize> = optimize
            .over
            .iter()
            .filter_map(|n| sweep.grid.axes.iter().position(|a| &a.name == n))
            .collect();
        let bounds = searched
            .iter()
            .map(|&k| optimize.bounds_of(&sweep.grid.axes[k]))
            .collect();
        Search {
            optimize,
            stage,
            sweep,
            searched,
            bounds,
            evaluated: RefCell::new(Vec::new()),
        }
    }

    /// The outcome at `values`: simulated once, then remembered.
    fn simulate_at(&self, values: &[AxisValue]) -> Result<Outcome> {
        if let Some((_, out)) = self.evaluated.borrow().iter().find(|(v, _)| v == values) {
            return Ok(out.clone());
        }
        let scene = self
            .sweep
            .scene_with(values, Some(self.optimize.tolerance))?;
        let out = simulate(&scene.scenario, &mut ()).map_err(|e| {
            PipelineError::stage(self.stage, format!("refinement scene failed: {e}"))
        })?;
        self.evaluated
            .borrow_mut()
            .push((values.to_vec(), out.clone()));
        Ok(out)
    }

    /// `base` with its searched coordinates set to `x`, clamped to the box.
    fn at(&self, base: &[AxisValue], x: &[f64]) -> Vec<AxisValue> {
        let mut values = base.to_vec();
        for (slot, &k) in self.searched.iter().enumerate() {
            let (lo, hi, _) = self.bounds[slot];
            values[k] = AxisValue::Float(x[slot].clamp(lo, hi));
        }
        values
    }

    /// Start `start_index` from the grid point `base` (whose table value is `table_value`):
    /// its grid row and its refined row, with the optimum's sensitivity and whether it lies
    /// on the box's edge.
    pub(super) fn refine_from(
        &self,
        start_index: usize,
        base: &[AxisValue],
        table_value: Option<f64>,
    ) -> Result<[OptimumRow; 2]> {
        let value_of = |out: &Outcome| self.optimize.value_of(out);
        let start: Vec<f64> = self.searched.iter().map(|&k| base[k].as_f64()).collect();
        let before = self.evaluated.borrow().len();
        let grid_out = self.simulate_at(&self.at(base, &start))?;
        let grid_value = value_of(&grid_out);
        let mut objective = |x: &[f64]| -> Result<f64> {
            self.simulate_at(&self.at(base, x)).map(|o| value_of(&o))
        };
        let steps: Vec<f64> = self.bounds.iter().map(|b| b.2).collect();
        let (best_x, _) = woodpile_analysis::nelder_mead::maximise(
            &mut objective,
            &start,
            &steps,
            grid_value,
            MAX_EVALUATIONS,
        )?;
        let best_values = self.at(base, &best_x);
        let best_out = self.simulate_at(&best_values)?;
        let sensitivity = self.sensitivity(base, &best_values, value_of(&best_out))?;
        let simulations = self.evaluated.borrow().len() - before;
        let on_edge: Vec<bool> = self
            .searched
            .iter()
            .zip(&self.bounds)
            .map(|(&k, &(lo, hi, _))| {
                let x = best_values[k].as_f64();
                (x - lo).abs() <= 1e-9 * lo.abs().max(1.0)
                    || (x - hi).abs() <= 1e-9 * hi.abs().max(1.0)
            })
            .collect();
        Ok([
            OptimumRow {
                start: start_index,
                point: "grid",
                values: self.at(base, &start),
                outcome: grid_out,
                grid_table_value: table_value,
                simulations: 1,
                sensitivity: None,
                on_edge: None,
            },
            OptimumRow {
                start: start_index,
                point: "refined",
                values: best_values,
                outcome: best_out,
                grid_table_value: None,
                simulations,
                sensitivity: Some(sensitivity),
                on_edge: Some(on_edge),
            },
        ])
    }

    /// How far the value moves with each searched coordinate alone nudged by ±1%.
    fn sensitivity(&self, base: &[AxisValue], best: &[AxisValue], value: f64) -> Result<Vec<f64>> {
        let mut sensitivity = Vec::with_capacity(self.searched.len());
        for slot in 0..self.searched.len() {
            let mut spread: f64 = 0.0;
            for sign in [-1.0, 1.0] {
                let mut x: Vec<f64> = best_values_of(best, &self.searched);
                x[slot] *= 1.0 + sign * NUDGE;
                let out = self.simulate_at(&self.at(base, &x))?;
                spread = spread.max((self.optimize.value_of(&out) - value).abs());
            }
            sensitivity.push(spread);
        }
        Ok(sensitivity)
    }
}

/// The searched coordinates of `values`.
fn best_values_of(values: &[AxisValue], searched: &[usize]) -> Vec<f64> {
    searched.iter().map(|&k| values[k].as_f64()).collect()
}
