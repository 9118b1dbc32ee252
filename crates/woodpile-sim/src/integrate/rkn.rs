//! Explicit Runge–Kutta–Nyström methods given by a tableau, for q'' = a(q):
//!
//! ```text
//! Q_i = q + c_i h v + h² Σ_j a_ij a(Q_j)      (j < i)
//! q+  = q + h v + h² Σ_i b_i a(Q_i)
//! v+  = v + h Σ_i b'_i a(Q_i)
//! ```
//!
//! This is `auto`'s stepper: with [`DPRKN6`], Dormand, El-Mikkawy and Prince's RKN6(4)
//! (1987), six stages of which the last is the force at the new position, it is
//! `rkn6-contact`. It is generic over the tableau so that the contact treatments below are one
//! piece of code for any order; [`NYSTROM4`] runs through it in the `error_split` example to
//! compare treatments at order 4, where `rkn4-contact` itself is the hand-written
//! [`super::Rkn4`] (faster; its doc comment has the figure).
//!
//! A contact that opens or closes inside a step can be treated in one of two ways
//! ([`ContactMode`]): *corrected* as in `rk4-contact` (the method's quadrature of that bond's
//! force replaced by the integral along the bond's path, [`super::contact_event`]), or
//! *located*: the step is cut short at the first moment any contact of the window opens or
//! closes, so that no step contains a kink, and the next step starts there.

use super::erkn_weights::NystromWeights;
use super::event_correction::{ContactEvents, Quadrature};
use super::exact_resonator::ExactResonators;
use super::stage_step::{copy_window, finish_step, stage_accelerations, NYSTROM_VELOCITIES};
use super::stage_sum::{sum_into, Base, Terms, MAX_TERMS};
use super::{Method, StepOutcome, StepSpan, Stepper};
use crate::dofs::StepStates;
use crate::model::{Model, Window};

/// An explicit Nyström tableau of `S` stages. `a` is strictly lower triangular.
#[derive(Debug, Clone, Copy)]
pub struct RknTableau<const S: usize> {
    /// The method's names, plain, with contact events corrected, and with them located (the
    /// order of [`ContactMode`]).
    pub names: [&'static str; 3],
    /// Stage times.
    pub c: [f64; S],
    /// Position coefficients of the stages (times h²).
    pub a: [[f64; S]; S],
    /// Position weights (times h²).
    pub b: [f64; S],
    /// Velocity weights (times h).
    pub b_prime: [f64; S],
    /// The method's quadrature of a bond force from its stage values, for the correction.
    pub(crate) quadrature: Quadrature<S>,
}

/// Dormand, El-Mikkawy and Prince's RKN6(4), "Families of Runge–Kutta–Nyström formulae", IMA J.
/// Numer. Anal. 7 (1987): order 6, six stages, the sixth at the new position (so a method that
/// reuses it spends five evaluations a step). The coefficients involve √8581; these are their
/// values rounded to double precision (the order conditions hold to 1e-16, tested).
pub const DPRKN6: RknTableau<6> = RknTableau {
    names: ["rkn6", Method::Rkn6Contact.name(), "rkn6-located"],
    c: [
        0.0,
        0.129_295_903_136_704_42,
        0.258_591_806_273_408_83,
        0.670_297_082_615_48,
        0.9,
        1.0,
    ],
    a: [
        [0.0; 6],
        [0.008_358_715_283_968_025, 0.0, 0.0, 0.0, 0.0, 0.0],
        [
            0.011_144_953_711_957_367,
            0.022_289_907_423_914_734,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.145_474_742_801_091_8,
            -0.229_860_640_522_647_49,
            0.309_034_987_202_967_5,
            0.0,
            0.0,
            0.0,
        ],
        [
            -0.207_668_262_950_789_97,
            0.686_366_784_292_514_3,
            -0.199_549_277_872_349_25,
            0.125_850_756_530_624_89,
            0.0,
            0.0,
        ],
        DPRKN6_B,
    ],
    b: DPRKN6_B,
    b_prime: DPRKN6_B_PRIME,
    quadrature: dprkn6_quadrature,
};

const DPRKN6_B: [f64; 6] = [
    0.078_110_161_443_494_78,
    0.0,
    0.288_291_741_189_766_8,
    0.122_425_537_174_570_41,
    0.011_172_560_192_168_035,
    0.0,
];

const DPRKN6_B_PRIME: [f64; 6] = [
    0.078_110_161_443_494_78,
    0.0,
    0.388_843_478_705_982_6,
    0.371_320_757_928_842_3,
    0.111_725_601_921_680_35,
    0.05,
];

fn dprkn6_quadrature(f: [f64; 6], h: f64) -> (f64, f64) {
    let weigh = |w: &[f64; 6]| w.iter().zip(&f).map(|(w, f)| w * f).sum::<f64>();
    (h * weigh(&DPRKN6_B_PRIME), h * h * weigh(&DPRKN6_B))
}

/// Nyström's three-stage order-4 method (the one [`super::Rkn4`] hand-codes), as a tableau: the
/// located variant of `rkn4-contact` for the comparison of contact treatments.
pub const NYSTROM4: RknTableau<3> = RknTableau {
    names: ["rkn4", Method::Rkn4Contact.name(), "rkn4-located"],
    c: [0.0, 0.5, 1.0],
    a: [[0.0; 3], [0.125, 0.0, 0.0], [0.0, 0.5, 0.0]],
    b: [1.0 / 6.0, 1.0 / 3.0, 0.0],
    b_prime: [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    quadrature: super::rkn4::rkn4_quadrature,
};

/// How a step treats a contact that opens or closes inside it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactMode {
    /// Nothing special: the kink is left to the method's quadrature (order 2.5 on the chain).
    Plain,
    /// The bond's force integrated along its path ([`super::contact_event`]).
    Corrected,
    /// Steps end where a contact opens or closes.
    Located,
}

/// Located steps ignore a crossing this close to the step's start (as a fraction of the step):
/// it is the event the previous step ended on.
const SAME_EVENT: f64 = 1e-6;

/// Sub-steps one located step may be cut into before it gives up locating and takes the rest
/// whole: a guard against a cluster of events, never reached on the paper's scenes.
const MAX_SUB_STEPS: u32 = 256;

/// A Runge–Kutta–Nyström stepper with its scratch (allocated once).
#[derive(Debug, Clone)]
pub struct Rkn<const S: usize> {
    tableau: RknTableau<S>,
    mode: ContactMode,
    q_stage: Vec<f64>,
    a: [Vec<f64>; S],
    y_new: Vec<f64>,
    evals: u64,
    /// Located steps cut short at a contact event.
    cuts: u64,
    /// Whether the tableau's last stage is the force at the new state (FSAL: c = 1 and its row
    /// of `a` equal to `b`), so that the next step may start from it.
    fsal: bool,
    /// Whether the last stage's accelerations are those of the current state: the previous step
    /// was FSAL and no contact correction moved its end state.
    last_stage_current: bool,
    /// Whether they are, but for the few sites the previous step's corrections moved: the next
    /// step reuses them and evaluates those sites again
    /// ([`ContactEvents::patch_reused_stage`]).
    patch_first_stage: bool,
    /// Whether a corrected step's last stage may be patched: an FSAL tableau on a model whose
    /// couplings do not ramp (kept out of caution: a patched site's forces are taken at the
    /// step's start time). Decided once, the model being fixed.
    patchable: bool,
    contact: Option<ContactEvents<S>>,
    /// The harmonic resonators integrated exactly (`erkn6-contact`), if any.
    exact: Option<ExactResonators<S>>,
    /// The name when they are (the tableau's names otherwise).
    exact_name: Option<&'static str>,
}

impl<const S: usize> Rkn<S> {
    /// The method of `tableau` for states of `model`, treating contact events by `mode`.
    pub fn new(model: &Model, tableau: RknTableau<S>, mode: ContactMode) -> Self {
        const { assert!(S <= MAX_TERMS, "a stage sum takes at most MAX_TERMS terms") };
        let n = model.n_dof();
        let fsal = tableau.c[S - 1] == 1.0 && tableau.a[S - 1] == tableau.b;
        Self {
            tableau,
            mode,
            q_stage: vec![0.0; n],
            a: std::array::from_fn(|_| vec![0.0; n]),
            y_new: vec![0.0; 2 * n],
            evals: 0,
            cuts: 0,
            fsal,
            last_stage_current: false,
            patch_first_stage: false,
            patchable: fsal && !model.is_time_dependent(),
            contact: (mode != ContactMode::Plain)
                .then(|| ContactEvents::new(model, tableau.quadrature)),
            exact: None,
            exact_name: None,
        }
    }

    /// The same method with `model`'s harmonic resonators integrated exactly (the extended
    /// Nyström step, [`super::exact_resonator`]), under the name `name`. A model without one
    /// steps as the plain method.
    pub fn with_exact_resonators(mut self, model: &Model, name: &'static str) -> Self {
        let t = self.tableau;
        assert!(
            self.fsal,
            "{}: an exact resonator step needs an FSAL tableau",
            t.names[0]
        );
        let weights = NystromWeights {
            c: t.c,
            b: t.b,
            b_prime: t.b_prime,
        };
        self.exact = ExactResonators::of(model, weights);
        self.exact_name = Some(name);
        self
    }

    /// Makes the next step evaluate its first stage whole: for a caller that changed the state
    /// between steps (the `transport_estimate` example's shadow runs), which the reused forces
    /// of the last stage would not see.
    pub fn forget_last_stage(&mut self) {
        self.last_stage_current = false;
        self.patch_first_stage = false;
    }

    /// Steps cut short at a contact event (located mode), or bonds corrected (corrected mode).
    pub fn contact_events(&self) -> u64 {
        match self.mode {
            ContactMode::Located => self.cuts,
            _ => self.contact.as_ref().map_or(0, ContactEvents::events),
        }
    }

    crate::simd::dispatched! {
        /// One step of the tableau from `y` into `self.y_new` (uncorrected), recording the
        /// stage forces when contacts are tracked. Each stage position and the new state are
        /// summed in one pass per range ([`super::stage_sum`]), which vectorises: in its AVX2
        /// or AVX-512 copy where the CPU has one (`crate::simd`).
        fn raw_step[&mut self](model: &Model, t: f64, y: &[f64], h: f64, window: Window)
            => raw_step_body, raw_step_avx2, raw_step_avx512
    }

    #[inline(always)]
    fn raw_step_body(&mut self, model: &Model, t: f64, y: &[f64], h: f64, window: Window) {
        let n = model.n_dof();
        let ranges = window.dof_ranges(model);
        let (q, v) = y.split_at(n);
        let tab = self.tableau;
        if let Some(exact) = self.exact.as_mut() {
            exact.begin_step(h, (q, v), (window.lo, window.hi));
        }
        for i in 0..S {
            if i > 0 {
                for r in ranges.clone() {
                    let mut terms = Terms::new();
                    for j in 0..i {
                        terms.push(h * h * tab.a[i][j], &self.a[j][r.clone()]);
                    }
                    let base = Base::Plus(&q[r.clone()], tab.c[i] * h, &v[r.clone()]);
                    sum_into(&mut self.q_stage[r], base, &terms);
                }
                if let Some(exact) = &self.exact {
                    exact.shift_stage(i, self.q_stage.as_mut_slice());
                }
            }
            if i == 0 && (self.last_stage_current || self.patch_first_stage) {
                // The new state of the previous step is this one, bit for bit (c = 1 and the
                // last row of `a` is `b`, accumulated in the same order): its forces are known,
                // or known but at the sites its corrections moved.
                self.a.swap(0, S - 1);
                if let Some(c) = self.contact.as_mut() {
                    c.reuse_stage(S - 1, 0);
                }
                if let Some(exact) = self.exact.as_mut() {
                    exact.reuse_stage(S - 1, 0);
                }
                if self.patch_first_stage {
                    // Counted as the evaluation it stands for, as the lanes count it.
                    self.evals += 1;
                    if let Some(c) = self.contact.as_mut() {
                        let acc = self.a[0].as_mut_slice();
                        c.patch_reused_stage(model, (t, q, window), acc, self.exact.as_mut());
                    }
                }
                continue;
            }
            let qs: &[f64] = if i == 0 { q } else { &self.q_stage };
            self.evals += 1;
            stage_accelerations(
                model,
                self.contact.as_mut(),
                (qs, NYSTROM_VELOCITIES, &mut self.a[i]),
                (t + tab.c[i] * h, i),
                window,
            );
            if let Some(exact) = self.exact.as_mut() {
                exact.remove_springs(i, qs, self.a[i].as_mut_slice());
            }
        }
        let (new_q, new_v) = self.y_new.split_at_mut(n);
        for r in ranges {
            let nq = &mut new_q[r.clone()];
            if self.fsal {
                // An FSAL tableau's last stage position is the new position, computed by the
                // same operations in the same order: copy it.
                nq.copy_from_slice(&self.q_stage[r.clone()]);
            } else {
                let mut q_terms = Terms::new();
                for i in 0..S {
                    q_terms.push(h * h * tab.b[i], &self.a[i][r.clone()]);
                }
                sum_into(nq, Base::Plus(&q[r.clone()], h, &v[r.clone()]), &q_terms);
            }
            let mut v_terms = Terms::new();
            for i in 0..S {
                v_terms.push(h * tab.b_prime[i], &self.a[i][r.clone()]);
            }
            sum_into(&mut new_v[r.clone()], Base::Of(&v[r]), &v_terms);
        }
        if let Some(exact) = &self.exact {
            exact.shift_velocity(new_v);
        }
    }

    /// The located step: sub-steps that each end at the next contact event, or at `t + h`.
    fn located_step(&mut self, model: &Model, t: f64, y: &mut [f64], h: f64, window: Window) {
        self.last_stage_current = false;
        self.patch_first_stage = false;
        let mut done = 0.0;
        let mut cuts = 0;
        while done < h {
            let rest = h - done;
            self.raw_step(model, t + done, y, rest, window);
            let event = match self.contact.as_mut() {
                Some(c) if cuts < MAX_SUB_STEPS => {
                    let states = StepStates {
                        start: y,
                        end: &self.y_new,
                    };
                    c.first_event(model, states, rest, window, SAME_EVENT)
                }
                _ => None,
            };
            match event {
                Some(x) if x < 1.0 - SAME_EVENT => {
                    let short = x * rest;
                    self.raw_step(model, t + done, y, short, window);
                    copy_window(model, (y, &self.y_new), window);
                    done += short;
                    cuts += 1;
                }
                _ => {
                    copy_window(model, (y, &self.y_new), window);
                    done = h;
                }
            }
        }
        self.cuts += u64::from(cuts);
    }
}

impl<const S: usize> Stepper for Rkn<S> {
    fn name(&self) -> &'static str {
        self.exact_name
            .unwrap_or(self.tableau.names[self.mode as usize])
    }

    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        let StepSpan { t, h, window } = span;
        match self.mode {
            ContactMode::Located => self.located_step(model, t, y, h, window),
            ContactMode::Plain | ContactMode::Corrected => {
                self.raw_step(model, t, y, h, window);
                let mut y_new = std::mem::take(&mut self.y_new);
                let events = (self.contact.as_mut(), self.exact.as_ref());
                finish_step(events, model, (y, &mut y_new), h, window);
                self.y_new = y_new;
                let corrected = self
                    .contact
                    .as_ref()
                    .is_some_and(ContactEvents::corrected_last_step);
                self.last_stage_current = self.fsal && !corrected;
                self.patch_first_stage = self.patchable && corrected;
            }
        }
        StepOutcome::Accepted { h_next: h }
    }

    fn reach(&self) -> usize {
        S
    }

    fn rhs_evals(&self) -> u64 {
        self.evals
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order conditions of a Nyström method for q'' = f(q) up to order 6 that involve only
    /// the weights and nodes (the quadrature conditions), and the row-sum condition.
    #[test]
    fn dprkn6_meets_its_quadrature_and_row_sum_conditions() {
        let t = DPRKN6;
        for k in 0..=5 {
            let v: f64 = (0..6).map(|i| t.b_prime[i] * t.c[i].powi(k)).sum();
            assert!((v - 1.0 / f64::from(k + 1)).abs() < 1e-15, "b' c^{k}: {v}");
        }
        for k in 0..=4 {
            let p: f64 = (0..6).map(|i| t.b[i] * t.c[i].powi(k)).sum();
            let want = 1.0 / f64::from((k + 1) * (k + 2));
            assert!((p - want).abs() < 1e-15, "b c^{k}: {p}");
        }
        for i in 0..6 {
            let row: f64 = t.a[i].iter().sum();
            assert!((row - t.c[i] * t.c[i] / 2.0).abs() < 1e-15, "row {i}");
        }
    }

    /// On the harmonic oscillator q'' = -q the tableau converges at order 6 (a step error that
    /// shrinks 2^6 = 64-fold per halving, 50-fold asserted).
    #[test]
    fn dprkn6_has_order_six_on_a_smooth_problem() {
        let error = |n: u32| {
            let h = 1.0 / f64::from(n);
            let (mut q, mut v) = (1.0f64, 0.0f64);
            for _ in 0..n {
                let mut acc = [0.0; 6];
                for i in 0..6 {
                    let mut qi = q + DPRKN6.c[i] * h * v;
                    for (a_ij, acc_j) in DPRKN6.a[i][..i].iter().zip(&acc) {
                        qi += h * h * a_ij * acc_j;
                    }
                    acc[i] = -qi;
                }
                let dq: f64 = (0..6).map(|i| DPRKN6.b[i] * acc[i]).sum();
                let dv: f64 = (0..6).map(|i| DPRKN6.b_prime[i] * acc[i]).sum();
                q += h * v + h * h * dq;
                v += h * dv;
            }
            (q - 1f64.cos()).abs() + (v + 1f64.sin()).abs()
        };
        let (e1, e2) = (error(4), error(8));
        assert!(e1 / e2 > 50.0, "{e1:e} -> {e2:e}");
    }
}
