//! Nyström's three-stage Runge–Kutta–Nyström method of order 4, for q'' = a(q):
//!
//! ```text
//! Q1 = q,                      a1 = a(Q1)
//! Q2 = q + h/2 v + h²/8 a1,    a2 = a(Q2)
//! Q3 = q + h v + h²/2 a2,      a3 = a(Q3)
//! q+ = q + h v + h² (a1/6 + a2/3)
//! v+ = v + h (a1/6 + 2 a2/3 + a3/6)
//! ```
//!
//! Why: the chain's equations have no velocity in the force, so a Nyström method reaches
//! order 4 with three force evaluations where classical RK4 spends four. The force's square
//! roots are what a step costs (README "Speed"), so a step is about a quarter cheaper, and on
//! the paper's scenes its R and T errors are also smaller than RK4's at the same step.
//!
//! `rkn4-contact` ([`Rkn4::with_contact_events`]) adds the exact contact events of
//! `rk4-contact` ([`super::contact_event`]), with this method's quadrature in place of RK4's.
//!
//! Why by hand when [`super::Rkn`] with [`super::NYSTROM4`] computes the same method (to
//! 4e-11 in the state after t = 150): written for three stages, with the stage sums fused into
//! the passes that form the next stage, it takes 5.7 ms on the standard scene at dt = 0.02
//! where the tableau stepper takes 6.7 ms (1.18x; best of 15, `cargo run --release -p
//! woodpile-bench --example nystrom4`).

use super::event_correction::Quadrature;
use super::stage_step::{finish_step, stage_accelerations, FixedStepScratch, NYSTROM_VELOCITIES};
use super::{Method, StepOutcome, StepSpan, Stepper};
use crate::model::Model;

/// Stage times c_i.
const C: [f64; 3] = [0.0, 0.5, 1.0];

/// RKN4 with its scratch (allocated once).
#[derive(Debug, Clone)]
pub struct Rkn4 {
    /// The next force's position, the new state, evaluations, and `rkn4-contact`'s stage bond
    /// forces.
    scratch: FixedStepScratch<3>,
    /// The three stage accelerations.
    a: [Vec<f64>; 3],
}

/// RKN4's quadrature of a bond force from its stage values:
/// `(h (F1/6 + 2 F2/3 + F3/6), h² (F1/6 + F2/3))`.
pub(crate) fn rkn4_quadrature(stage_forces: [f64; 3], h: f64) -> (f64, f64) {
    let [f1, f2, f3] = stage_forces;
    (
        h * (f1 / 6.0 + 2.0 * f2 / 3.0 + f3 / 6.0),
        h * h * (f1 / 6.0 + f2 / 3.0),
    )
}

impl Rkn4 {
    /// A stepper for states of `model`.
    pub fn new(model: &Model) -> Self {
        Self::with_quadrature(model, None)
    }

    /// `rkn4-contact`: the same method plus the exact integral of every contact force across
    /// the step in which that contact opens or closes.
    pub fn with_contact_events(model: &Model) -> Self {
        Self::with_quadrature(model, Some(rkn4_quadrature))
    }

    fn with_quadrature(model: &Model, quadrature: Option<Quadrature<3>>) -> Self {
        Self {
            scratch: FixedStepScratch::new(model, ["rkn4", Method::Rkn4Contact.name()], quadrature),
            a: std::array::from_fn(|_| vec![0.0; model.n_dof()]),
        }
    }
}

impl Stepper for Rkn4 {
    fn name(&self) -> &'static str {
        self.scratch.name()
    }

    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        self.three_stage_step(model, y, span);
        StepOutcome::Accepted { h_next: span.h }
    }

    fn reach(&self) -> usize {
        3
    }

    fn rhs_evals(&self) -> u64 {
        self.scratch.evals
    }
}

impl Rkn4 {
    crate::simd::dispatched! {
        /// One step over `span`, corrected for contact events when they are kept; in its AVX2
        /// or AVX-512 copy where the CPU has one (`crate::simd`).
        fn three_stage_step[&mut self](model: &Model, y: &mut [f64], span: StepSpan)
            => three_stage_step_body, three_stage_step_avx2, three_stage_step_avx512
    }

    #[inline(always)]
    fn three_stage_step_body(&mut self, model: &Model, y: &mut [f64], span: StepSpan) {
        let StepSpan { t, h, window } = span;
        let n = model.n_dof();
        let ranges = window.dof_ranges(model);
        let s = &mut self.scratch;
        // Stage 1 is the state itself: its accelerations are taken at q, with no copy.
        stage_accelerations(
            model,
            s.contact.as_mut(),
            (&y[..n], NYSTROM_VELOCITIES, &mut self.a[0]),
            (t, 0),
            window,
        );
        // Q2 from a1, Q3 from a2: Q = q + (cv) v + (ca) a_previous.
        for (stage, (cv, ca)) in [(0.5 * h, h * h / 8.0), (h, h * h / 2.0)]
            .into_iter()
            .enumerate()
        {
            let (q, v) = y.split_at(n);
            for r in ranges.clone() {
                let len = r.len();
                let qs = &mut s.q_stage[r.clone()][..len];
                let (q0, v0) = (&q[r.clone()][..len], &v[r.clone()][..len]);
                let a = &self.a[stage][r][..len];
                for i in 0..len {
                    qs[i] = q0[i] + cv * v0[i] + ca * a[i];
                }
            }
            stage_accelerations(
                model,
                s.contact.as_mut(),
                (&s.q_stage, NYSTROM_VELOCITIES, &mut self.a[stage + 1]),
                (t + C[stage + 1] * h, stage + 1),
                window,
            );
        }
        s.evals += 3;
        let (q, v) = y.split_at(n);
        let (new_q, new_v) = s.y_new.split_at_mut(n);
        let (bq1, bq2) = (h * h / 6.0, h * h / 3.0);
        let (bv1, bv2, bv3) = (h / 6.0, 2.0 * h / 3.0, h / 6.0);
        for r in ranges.clone() {
            let len = r.len();
            let (a1, a2, a3) = (
                &self.a[0][r.clone()][..len],
                &self.a[1][r.clone()][..len],
                &self.a[2][r.clone()][..len],
            );
            let (q0, v0) = (&q[r.clone()][..len], &v[r.clone()][..len]);
            let nq = &mut new_q[r.clone()][..len];
            let nv = &mut new_v[r][..len];
            for i in 0..len {
                nq[i] = q0[i] + h * v0[i] + (bq1 * a1[i] + bq2 * a2[i]);
                nv[i] = v0[i] + (bv1 * a1[i] + bv2 * a2[i] + bv3 * a3[i]);
            }
        }
        finish_step(
            (s.contact.as_mut(), None),
            model,
            (y, &mut s.y_new),
            h,
            window,
        );
    }
}
