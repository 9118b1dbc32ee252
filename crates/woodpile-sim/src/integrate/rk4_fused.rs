//! Classical RK4 written for the chain's second-order form q' = v, v' = a(q): the same
//! arithmetic as [`super::ExplicitRk`]`<`[`super::Rk4`]`>`, operation for operation (so the
//! result is the same bits, which a test checks), with each stage's state, derivative and
//! contribution to the new state computed in one pass over memory instead of four.
//!
//! With k_i = (v_i, a_i): q_{i+1} = q + (c h) v_i, v_{i+1} = v + (c h) a_i, a_{i+1} = a(q_{i+1});
//! the new state accumulates y + (h b_1) k_1 + (h b_2) k_2 + ... in that order.
//!
//! The same stepper is `rk4-contact` when made by [`Rk4Fused::with_contact_events`]: it records
//! each stage's bond forces and, after the step, replaces RK4's quadrature of every bond whose
//! contact opened or closed by the integral along the bond's path ([`super::contact_event`]).

use super::contact_event::rk4_quadrature;
use super::event_correction::Quadrature;
use super::stage_step::{stage_accelerations, FixedStepScratch};
use super::switches::{self, Staged};
use super::{Method, StepOutcome, StepSpan, Stepper};
use crate::model::Model;

const B: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
/// a_{i+1, i} of the tableau: the weight of stage i in stage i + 1.
const A_NEXT: [f64; 3] = [0.5, 0.5, 1.0];
const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];

/// Fused RK4 stepper with its scratch (allocated once).
#[derive(Debug, Clone)]
pub struct Rk4Fused {
    /// Stage positions, the new state, evaluations, and `rk4-contact`'s stage bond forces.
    scratch: FixedStepScratch<4>,
    /// Stage velocities (the position derivatives k_q).
    v_stage: Vec<f64>,
    /// Stage accelerations (the velocity derivatives k_v).
    a_stage: Vec<f64>,
}

impl Rk4Fused {
    /// A stepper for states of `model`.
    pub fn new(model: &Model) -> Self {
        Self::with_quadrature(model, None)
    }

    /// `rk4-contact`: the same RK4, plus the exact integral of every contact force across the
    /// step in which that contact opens or closes ([`super::contact_event`]).
    pub fn with_contact_events(model: &Model) -> Self {
        Self::with_quadrature(model, Some(rk4_quadrature))
    }

    fn with_quadrature(model: &Model, quadrature: Option<Quadrature<4>>) -> Self {
        let n = model.n_dof();
        Self {
            scratch: FixedStepScratch::new(
                model,
                [Method::Rk4.name(), Method::Rk4Contact.name()],
                quadrature,
            ),
            v_stage: vec![0.0; n],
            a_stage: vec![0.0; n],
        }
    }
}

impl Stepper for Rk4Fused {
    fn name(&self) -> &'static str {
        self.scratch.name()
    }

    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        switches::step(self, model, y, span)
    }

    fn reach(&self) -> usize {
        4
    }

    fn rhs_evals(&self) -> u64 {
        self.scratch.evals
    }
}

impl Staged<4> for Rk4Fused {
    fn stages(&mut self, model: &Model, y: &[f64], span: StepSpan) {
        self.four_stages(model, y, span);
    }

    fn scratch(&mut self) -> &mut FixedStepScratch<4> {
        &mut self.scratch
    }
}

impl Rk4Fused {
    crate::simd::dispatched! {
        /// RK4's four stages from `y` over `span`, the new state (uncorrected) left in the
        /// scratch's `y_new`; in its AVX2 or AVX-512 copy where the CPU has one (`crate::simd`).
        fn four_stages[&mut self](model: &Model, y: &[f64], span: StepSpan)
            => stages_body, stages_avx2, stages_avx512
    }

    #[inline(always)]
    fn stages_body(&mut self, model: &Model, y: &[f64], span: StepSpan) {
        let StepSpan { t, h, window } = span;
        let n = model.n_dof();
        let ranges = window.dof_ranges(model);
        let (q, v) = y.split_at(n);
        let s = &mut self.scratch;
        let (new_q, new_v) = s.y_new.split_at_mut(n);
        // Stage 1 is the state itself: its accelerations are taken at q directly, and the
        // first pass below writes y + (h b_1) k_1 and stage 2 from (q, v) instead of copying
        // (q, v) into four buffers first. Same operations on the same operands, same bits.
        let mut power = stage_accelerations(
            model,
            s.contact.as_mut(),
            (q, v, &mut self.a_stage),
            (t, 0),
            window,
        );
        // D, the dissipated energy (a dissipative chain only), is the state's last entry: RK4
        // integrates its rate, the power, with the same weights and in the same order.
        let mut dissipated = model.dissipated(y);
        for stage in 0..4 {
            let hb = h * B[stage];
            dissipated += hb * power;
            let next = A_NEXT.get(stage).map(|&a| h * a);
            for r in ranges.clone() {
                let len = r.len();
                let vs = &mut self.v_stage[r.clone()];
                let as_ = &self.a_stage[r.clone()][..len];
                let qs = &mut s.q_stage[r.clone()][..len];
                let nq = &mut new_q[r.clone()][..len];
                let nv = &mut new_v[r.clone()][..len];
                let q0 = &q[r.clone()][..len];
                let v0 = &v[r][..len];
                // Separate loops rather than a branch inside one, so that each vectorises.
                match next {
                    Some(w) if stage == 0 => {
                        for i in 0..len {
                            nq[i] = q0[i] + hb * v0[i];
                            nv[i] = v0[i] + hb * as_[i];
                            qs[i] = q0[i] + w * v0[i];
                            vs[i] = v0[i] + w * as_[i];
                        }
                    }
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
                power = stage_accelerations(
                    model,
                    s.contact.as_mut(),
                    (&s.q_stage, &self.v_stage, &mut self.a_stage),
                    (t + C[stage + 1] * h, stage + 1),
                    window,
                );
            }
        }
        if model.is_dissipative() {
            s.y_new[2 * n] = dissipated;
        }
        s.evals += 4;
    }
}
