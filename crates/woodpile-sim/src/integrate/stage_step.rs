//! What every step of a fixed-step method shares with the contact events: a stage's force
//! evaluation (recording its bond forces when events are kept), the scratch of the hand-written
//! steppers, and the end of a step (correct, then copy the new state back over the window).

use super::event_correction::{ContactEvents, Quadrature};
use super::exact_resonator::ExactResonators;
use crate::damped_force::BondRecord;
use crate::dofs::StepStatesMut;
use crate::model::{Model, Window};

/// What the hand-written fixed-step steppers ([`super::Rk4Fused`], [`super::Rkn4`], and the
/// measured `crate::testing::Rk6Contact`) keep
/// beside their stage derivatives: the position of the next force evaluation, the new state
/// being assembled, the evaluations spent, and, for the `-contact` variant, each stage's bond
/// forces. One constructor serves a method and its `-contact` variant.
#[derive(Debug, Clone)]
pub(crate) struct FixedStepScratch<const S: usize> {
    pub q_stage: Vec<f64>,
    pub y_new: Vec<f64>,
    pub evals: u64,
    pub contact: Option<ContactEvents<S>>,
    /// The plain method's name and its `-contact` variant's.
    names: [&'static str; 2],
}

impl<const S: usize> FixedStepScratch<S> {
    /// Scratch for states of `model`; contact events are kept when `quadrature` (the method's
    /// quadrature of a bond force) is given.
    pub fn new(model: &Model, names: [&'static str; 2], quadrature: Option<Quadrature<S>>) -> Self {
        let n = model.n_dof();
        Self {
            q_stage: vec![0.0; n],
            y_new: vec![0.0; model.state_len()],
            evals: 0,
            contact: quadrature.map(|q| ContactEvents::new(model, q)),
            names,
        }
    }

    /// The method's name: the `-contact` one when contact events are kept.
    pub fn name(&self) -> &'static str {
        self.names[usize::from(self.contact.is_some())]
    }
}

/// The velocities a Nyström method passes to [`stage_accelerations`]: none, since its forces
/// depend on positions only. [`super::Plan::choose`] never gives such a method a dissipative
/// model, the one kind that would read them.
pub(crate) const NYSTROM_VELOCITIES: &[f64] = &[];

/// Stage `stage`'s accelerations `acc` at positions `q` (and velocities `v`, which only a
/// dissipative model reads), recording every bond force into `contact` when a contact-event
/// method keeps them. Returns the stage's dissipated power (0 for a conservative chain).
/// Inlined into each method's stage loop, as it was before the dissipative branch existed.
#[inline(always)]
pub(crate) fn stage_accelerations<const S: usize>(
    model: &Model,
    contact: Option<&mut ContactEvents<S>>,
    (q, v, acc): (&[f64], &[f64], &mut [f64]),
    (t, stage): (f64, usize),
    window: Window,
) -> f64 {
    if model.is_dissipative() {
        return damped_accelerations(model, (contact, stage), (q, v, acc), t, window);
    }
    match contact {
        None => model.accelerations_in(t, q, acc, window),
        Some(c) => model.accelerations_recording(t, q, acc, window, &mut c.stage_force[stage]),
    }
    0.0
}

/// [`stage_accelerations`] of a dissipative chain, recording into the stage's bond record.
/// Kept out of line: the conservative methods' stage loops inline [`stage_accelerations`],
/// and should not carry this path's code.
#[inline(never)]
#[cold]
fn damped_accelerations<const S: usize>(
    model: &Model,
    (contact, stage): (Option<&mut ContactEvents<S>>, usize),
    (q, v, acc): (&[f64], &[f64], &mut [f64]),
    t: f64,
    window: Window,
) -> f64 {
    let record = contact.map(|c| BondRecord {
        force: &mut c.stage_force[stage],
        power: &mut c.stage_power[stage],
    });
    model.damped_recording(t, (q, v), acc, window, record)
}

/// Ends a step of a method that can correct contact events: corrects `y_new` (the new state,
/// `[q, q']`) if `contact` events are kept (along the fast modes of `exact` resonators too),
/// then copies it into `y` over `window`.
pub(crate) fn finish_step<const S: usize>(
    (contact, exact): (Option<&mut ContactEvents<S>>, Option<&ExactResonators<S>>),
    model: &Model,
    (y, y_new): (&mut [f64], &mut [f64]),
    h: f64,
    window: Window,
) {
    if let Some(contact) = contact {
        let states = StepStatesMut {
            start: y,
            end: y_new,
        };
        contact.correct(model, states, h, (window, exact));
    }
    copy_window(model, (y, y_new), window);
}

/// Copies the new state `y_new` into `y` over `window` (states `[q, q']`).
pub(crate) fn copy_window(model: &Model, (y, y_new): (&mut [f64], &[f64]), window: Window) {
    let n = model.n_dof();
    let (new_q, new_v) = y_new.split_at(n);
    let (q, v) = y.split_at_mut(n);
    for r in window.dof_ranges(model) {
        q[r.clone()].copy_from_slice(&new_q[r.clone()]);
        v[r.clone()].copy_from_slice(&new_v[r]);
    }
    if model.is_dissipative() {
        v[n] = new_v[n];
    }
}
