//! Classical RK4 written for the chain's second-order form q' = v, v' = a(q): the same
//! arithmetic as [`super::ExplicitRk`]`<`[`super::Rk4`]`>`, operation for operation (so the
//! result is the same bits, which a test checks), with each stage's state, derivative and
//! contribution to the new state computed in one pass over memory instead of four.
//!
//! With k_i = (v_i, a_i): q_{i+1} = q + (c h) v_i, v_{i+1} = v + (c h) a_i, a_{i+1} = a(q_{i+1});
//! the new state accumulates y + (h b_1) k_1 + (h b_2) k_2 + ... in that order.

use super::{StepOutcome, Stepper};
use crate::model::{Model, Window};

const B: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
/// a_{i+1, i} of the tableau: the weight of stage i in stage i + 1.
const A_NEXT: [f64; 3] = [0.5, 0.5, 1.0];
const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];

/// Fused RK4 stepper with its scratch (allocated once).
#[derive(Debug, Clone)]
pub struct Rk4Fused {
    /// Stage positions.
    q_stage: Vec<f64>,
    /// Stage velocities (the position derivatives k_q).
    v_stage: Vec<f64>,
    /// Stage accelerations (the velocity derivatives k_v).
    a_stage: Vec<f64>,
    /// The new state being accumulated.
    y_new: Vec<f64>,
    evals: u64,
}

impl Rk4Fused {
    /// A stepper for states of `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.n_dof();
        Self {
            q_stage: vec![0.0; n],
            v_stage: vec![0.0; n],
            a_stage: vec![0.0; n],
            y_new: vec![0.0; 2 * n],
            evals: 0,
        }
    }
}

impl Stepper for Rk4Fused {
    fn name(&self) -> &'static str {
        "rk4"
    }

    fn step(
        &mut self,
        model: &Model,
        t: f64,
        y: &mut [f64],
        h: f64,
        window: Window,
    ) -> StepOutcome {
        let n = model.n_dof();
        let ranges = window.dof_ranges(model);
        let (q, v) = y.split_at(n);
        let (new_q, new_v) = self.y_new.split_at_mut(n);
        // Stage 1: (q, v), a(q).
        for r in ranges.clone() {
            new_q[r.clone()].copy_from_slice(&q[r.clone()]);
            new_v[r.clone()].copy_from_slice(&v[r.clone()]);
            self.v_stage[r.clone()].copy_from_slice(&v[r]);
        }
        model.accelerations_in(t, q, &mut self.a_stage, window);
        for stage in 0..4 {
            let hb = h * B[stage];
            let next = A_NEXT.get(stage).map(|&a| h * a);
            for r in ranges.clone() {
                let len = r.len();
                let vs = &mut self.v_stage[r.clone()];
                let as_ = &self.a_stage[r.clone()][..len];
                let qs = &mut self.q_stage[r.clone()][..len];
                let nq = &mut new_q[r.clone()][..len];
                let nv = &mut new_v[r.clone()][..len];
                let q0 = &q[r.clone()][..len];
                let v0 = &v[r][..len];
                // Two loops rather than a branch inside one, so that both vectorise.
                match next {
                    Some(w) => {
                        for i in 0..len {
                            nq[i] += hb * vs[i];
                            nv[i] += hb * as_[i];
                            qs[i] = q0[i] + w * vs[i];
                            vs[i] = v0[i] + w * as_[i];
                        }
                    }
                    None => {
                        for i in 0..len {
                            nq[i] += hb * vs[i];
                            nv[i] += hb * as_[i];
                        }
                    }
                }
            }
            if stage < 3 {
                model.accelerations_in(
                    t + C[stage + 1] * h,
                    &self.q_stage,
                    &mut self.a_stage,
                    window,
                );
            }
        }
        self.evals += 4;
        let (q, v) = y.split_at_mut(n);
        for r in ranges {
            q[r.clone()].copy_from_slice(&new_q[r.clone()]);
            v[r.clone()].copy_from_slice(&new_v[r]);
        }
        StepOutcome::Accepted { h_next: h }
    }

    fn reach(&self) -> usize {
        4
    }

    fn rhs_evals(&self) -> u64 {
        self.evals
    }
}
