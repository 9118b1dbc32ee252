//! Explicit Runge–Kutta methods as Butcher tableaus: one stepper generic over the constants.
//!
//! Classical RK4 (Kutta 1901) is the method of the paper. The stage loop is shared with the
//! embedded pair in [`super::dop853`] through [`rk_stages`].

use std::marker::PhantomData;

use super::{Method, StepOutcome, StepSpan, Stepper};
use crate::model::{Model, Window};

/// A Butcher tableau with `STAGES` stages: `A` (strictly lower triangular, row i has i
/// entries), weights `B`, nodes `C`.
pub trait Tableau {
    /// Name used in scene files.
    const NAME: &'static str;
    /// Classical order on smooth problems.
    const ORDER: u32;
    /// Coupling coefficients a_ij, j < i.
    const A: &'static [&'static [f64]];
    /// Weights b_i.
    const B: &'static [f64];
    /// Nodes c_i.
    const C: &'static [f64];
}

/// Classical fourth-order Runge–Kutta.
#[derive(Debug, Clone, Copy)]
pub struct Rk4;

impl Tableau for Rk4 {
    const NAME: &'static str = Method::Rk4.name();
    const ORDER: u32 = 4;
    const A: &'static [&'static [f64]] = &[&[], &[0.5], &[0.0, 0.5], &[0.0, 0.0, 1.0]];
    const B: &'static [f64] = &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
    const C: &'static [f64] = &[0.0, 0.5, 0.5, 1.0];
}

/// Fixed-step explicit Runge–Kutta over tableau `T`. Scratch is allocated once, at construction.
#[derive(Debug, Clone)]
pub struct ExplicitRk<T: Tableau> {
    stages: Vec<f64>,
    scratch: Vec<f64>,
    evals: u64,
    _tableau: PhantomData<T>,
}

impl<T: Tableau> ExplicitRk<T> {
    /// A stepper for states of `model`.
    pub fn new(model: &Model) -> Self {
        let len = model.state_len();
        Self {
            stages: vec![0.0; T::B.len() * len],
            scratch: vec![0.0; len],
            evals: 0,
            _tableau: PhantomData,
        }
    }
}

impl<T: Tableau> Stepper for ExplicitRk<T> {
    fn name(&self) -> &'static str {
        T::NAME
    }

    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        let StepSpan { t, h, window } = span;
        let len = y.len();
        rk_stages(
            model,
            t,
            y,
            h,
            (T::A, T::C),
            &mut self.stages,
            &mut self.scratch,
            true,
            window,
        );
        self.evals += T::B.len() as u64;
        let ranges = window.state_ranges(model);
        for (i, &b) in T::B.iter().enumerate() {
            if b != 0.0 {
                let k = &self.stages[i * len..(i + 1) * len];
                for range in ranges.clone() {
                    for (yi, ki) in y[range.clone()].iter_mut().zip(&k[range]) {
                        *yi += h * b * ki;
                    }
                }
            }
        }
        StepOutcome::Accepted { h_next: h }
    }

    fn reach(&self) -> usize {
        T::B.len()
    }

    fn rhs_evals(&self) -> u64 {
        self.evals
    }
}

/// Computes the stage derivatives k_i = f(t + c_i h, y + h sum_j a_ij k_j) into `stages`
/// (row-major, `a.len()` rows of `y.len()`), for the state entries of `window` only (the rest
/// are at rest and stay zero). With `first_stage = false`, row 0 is assumed to already hold
/// f(t, y) (first-same-as-last reuse).
#[allow(clippy::too_many_arguments)]
pub(crate) fn rk_stages(
    model: &Model,
    t: f64,
    y: &[f64],
    h: f64,
    (a, c): (&[&[f64]], &[f64]),
    stages: &mut [f64],
    scratch: &mut [f64],
    first_stage: bool,
    window: Window,
) {
    let len = y.len();
    let ranges = window.state_ranges(model);
    if first_stage {
        model.rhs_in(t, y, &mut stages[..len], window);
    }
    for i in 1..a.len() {
        for range in ranges.clone() {
            scratch[range.clone()].copy_from_slice(&y[range]);
        }
        let (done, rest) = stages.split_at_mut(i * len);
        for (j, &aij) in a[i].iter().enumerate() {
            if aij != 0.0 {
                let k = &done[j * len..(j + 1) * len];
                let w = h * aij;
                for range in ranges.clone() {
                    for (s, kj) in scratch[range.clone()].iter_mut().zip(&k[range]) {
                        *s += w * kj;
                    }
                }
            }
        }
        model.rhs_in(t + c[i] * h, scratch, &mut rest[..len], window);
    }
}
