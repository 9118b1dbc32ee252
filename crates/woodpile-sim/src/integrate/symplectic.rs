//! Störmer–Verlet and its symmetric compositions (Hairer, Lubich & Wanner, *Geometric Numerical
//! Integration*, 2nd ed., Sections II.4 and V.3).
//!
//! The Hamiltonian is separable (kinetic + potential), so velocity Verlet (kick–drift–kick) is
//! symplectic and time-reversible; a symmetric composition of Verlet sub-steps of lengths
//! gamma_i h raises the order while keeping both properties, and keeps energy bounded with no
//! secular drift. A time-dependent coupling kappa(t) is handled in extended phase space: time
//! advances with the drifts, and kicks read kappa at the current time.
//!
//! Each sub-step costs one force evaluation: the closing kick's acceleration is cached and opens
//! the next sub-step (first-same-as-last).

use super::{Method, StepOutcome, StepSpan, Stepper};
use crate::model::Model;

/// A symmetric composition of Verlet sub-steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Composition {
    /// Name used in scene files.
    pub name: &'static str,
    /// Order on smooth problems.
    pub order: u32,
    /// Sub-step fractions gamma_i (sum to 1).
    pub gammas: &'static [f64],
}

/// Störmer–Verlet (velocity Verlet), order 2.
pub const VERLET: Composition = Composition {
    name: Method::Verlet.name(),
    order: 2,
    gammas: &[1.0],
};

/// Yoshida's / Forest–Ruth's triple jump, order 4: gamma_1 = gamma_3 = 1/(2 - 2^{1/3}),
/// gamma_2 = -2^{1/3}/(2 - 2^{1/3}).
pub const YOSHIDA4: Composition = Composition {
    name: Method::Yoshida4.name(),
    order: 4,
    gammas: &[
        1.351_207_191_959_657_8,
        -1.702_414_383_919_315_5,
        1.351_207_191_959_657_8,
    ],
};

/// Yoshida's 7-stage composition of order 6, solution A (Yoshida 1990; HLW Eq. V.3.11).
#[allow(clippy::excessive_precision)] // digits as published
pub const YOSHIDA6: Composition = Composition {
    name: Method::Yoshida6.name(),
    order: 6,
    gammas: &[
        0.784_513_610_477_557_263_8,
        0.235_573_213_359_358_133_7,
        -1.177_679_984_178_871_007,
        1.315_186_320_683_911_218_9,
        -1.177_679_984_178_871_007,
        0.235_573_213_359_358_133_7,
        0.784_513_610_477_557_263_8,
    ],
};

/// A composition method with its scratch: the cached acceleration and the time it belongs to.
#[derive(Debug, Clone)]
pub struct SymplecticStepper {
    composition: Composition,
    acc: Vec<f64>,
    cached_at: Option<f64>,
    evals: u64,
}

impl SymplecticStepper {
    /// A stepper for `model` using `composition`.
    pub fn new(model: &Model, composition: Composition) -> Self {
        Self {
            composition,
            acc: vec![0.0; model.n_dof()],
            cached_at: None,
            evals: 0,
        }
    }
}

impl Stepper for SymplecticStepper {
    fn name(&self) -> &'static str {
        self.composition.name
    }

    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        self.composed_step(model, y, span)
    }

    fn reach(&self) -> usize {
        self.composition.gammas.len() + 1
    }

    fn rhs_evals(&self) -> u64 {
        self.evals
    }
}

impl SymplecticStepper {
    crate::simd::dispatched! {
        /// One step: the composition's kick-drift-kick substeps over `span`'s window, in its
        /// AVX2 or AVX-512 copy where the CPU has one (`crate::simd`).
        fn composed_step[&mut self](model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome
            => composed_step_body, composed_step_avx2, composed_step_avx512
    }

    #[inline(always)]
    fn composed_step_body(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        let StepSpan { t, h, window } = span;
        let n_dof = model.n_dof();
        let (q, v) = y.split_at_mut(n_dof);
        let ranges = window.dof_ranges(model);
        if self.cached_at != Some(t) {
            model.accelerations_in(t, q, &mut self.acc, window);
            self.evals += 1;
        }
        let mut time = t;
        for &gamma in self.composition.gammas {
            let sub = gamma * h;
            for range in ranges.clone() {
                for (vi, ai) in v[range.clone()].iter_mut().zip(&self.acc[range.clone()]) {
                    *vi += 0.5 * sub * ai;
                }
                for (qi, vi) in q[range.clone()].iter_mut().zip(&v[range]) {
                    *qi += sub * vi;
                }
            }
            time += sub;
            model.accelerations_in(time, q, &mut self.acc, window);
            for range in ranges.clone() {
                for (vi, ai) in v[range.clone()].iter_mut().zip(&self.acc[range]) {
                    *vi += 0.5 * sub * ai;
                }
            }
        }
        self.evals += self.composition.gammas.len() as u64;
        // The driver reports the end of this step as exactly t + h; rounding of the sub-step
        // sum is irrelevant to a cache keyed by that value.
        self.cached_at = Some(t + h);
        StepOutcome::Accepted { h_next: h }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compositions_are_consistent_and_symmetric() {
        for c in [VERLET, YOSHIDA4, YOSHIDA6] {
            let sum: f64 = c.gammas.iter().sum();
            assert!((sum - 1.0).abs() < 1e-14, "{}: sum {sum}", c.name);
            let n = c.gammas.len();
            for i in 0..n {
                assert_eq!(c.gammas[i], c.gammas[n - 1 - i]);
            }
        }
        // Order-3 condition of a symmetric composition: sum gamma^3 = 0.
        let cubes: f64 = YOSHIDA4.gammas.iter().map(|g| g * g * g).sum();
        assert!(cubes.abs() < 1e-14);
        let cubes6: f64 = YOSHIDA6.gammas.iter().map(|g| g * g * g).sum();
        let fifths6: f64 = YOSHIDA6.gammas.iter().map(|g| g.powi(5)).sum();
        assert!(
            cubes6.abs() < 1e-12 && fifths6.abs() < 1e-12,
            "{cubes6} {fifths6}"
        );
    }
}
