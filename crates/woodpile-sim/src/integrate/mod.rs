//! Time integration: steppers and the one driver that runs them.
//!
//! A method implements only [`Stepper::step`]. The [`drive`] function owns the time loop, the
//! sample grid, failure detection (non-finite state, energy drift, step underflow, step budget)
//! and the statistics. Observers see the state at the sample times only, between steps, so the
//! numerics never know who is watching.
//!
//! Methods (see [`Method`]): RK4 (the paper's), RK4 with exact contact events (`rk4-contact`,
//! [`contact_event`]), Nyström's three-stage order-4 method with the same events
//! (`rkn4-contact`), the sixth-order Nyström method RKN6 with them (`rkn6-contact`, `auto`'s;
//! [`Rkn`] steps any Nyström tableau), Störmer–Verlet and its symplectic compositions
//! of order 4 and 6, and the adaptive Dormand–Prince 8(5,3).
//!
//! Comparisons are written `!(x <= limit)` on purpose: a NaN must fail them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod active_sites;
mod bond_correction;
pub(crate) mod contact_event;
mod contact_scan;
mod dop853;
mod driver;
mod erkn_weights;
mod event_correction;
pub(crate) mod exact_resonator;
pub mod lanes;
mod method;
mod plan;
mod rk;
mod rk4_fused;
#[cfg(any(test, feature = "testing"))]
pub(crate) mod rk6_contact;
mod rkn;
mod rkn4;
mod split_losses;
mod stage_step;
mod stage_sum;
mod switches;
mod symplectic;

pub use active_sites::ActiveSites;
pub use dop853::{Dop853, Dop853Tableau, DOP853_TABLEAU};
pub use driver::{drive, intervals, END_ARRIVAL_SPEED};
pub use method::{Method, MethodChoice};
pub use plan::{
    Accuracy, Plan, AUTO_METHOD, BLOW_UP_DRIFT, DISSIPATIVE_AUTO_METHOD, DRIFT_PER_TOL,
    HARMONIC_AUTO_METHOD, LINEAR_LOSSES_AUTO_METHOD,
};
pub use rk::{ExplicitRk, Rk4, Tableau};
pub use rk4_fused::Rk4Fused;
pub use rkn::{ContactMode, Rkn, RknTableau, DPRKN6, NYSTROM4};
pub use rkn4::Rkn4;
pub use split_losses::SplitLosses;
pub use symplectic::{Composition, SymplecticStepper, VERLET, YOSHIDA4, YOSHIDA6};

use crate::model::{Model, Window};

/// What a step attempt did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepOutcome {
    /// The state was advanced by the requested `h`; `h_next` is the method's proposal.
    Accepted {
        /// Proposed next step.
        h_next: f64,
    },
    /// The state is unchanged; retry with `h_next`.
    Rejected {
        /// Proposed retry step.
        h_next: f64,
    },
}

/// One step's place: from time `t`, by `h`, on the sites of `window`.
#[derive(Debug, Clone, Copy)]
pub struct StepSpan {
    /// The time the step starts at.
    pub t: f64,
    /// Its size.
    pub h: f64,
    /// The sites it works on.
    pub window: Window,
}

/// One integration method. It advances the state; everything else belongs to [`drive`].
pub trait Stepper {
    /// Short name, as used in scene files ("rk4", "verlet", ...).
    fn name(&self) -> &'static str;

    /// Attempts a step `span` (of size `h` from time `t`) from `y`, updating `y` in place
    /// when accepted. Only the sites of `span.window` are worked on: the caller guarantees
    /// that every site outside it is at rest and stays so for the step (see
    /// [`Stepper::reach`]).
    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome;

    /// How many sites a disturbance can travel in one step, at most: one per force evaluation
    /// (a site at rest moves only once a neighbour has moved in an earlier stage).
    fn reach(&self) -> usize;

    /// Right-hand-side (force) evaluations so far.
    fn rhs_evals(&self) -> u64;

    /// An initial step for adaptive methods; fixed-step methods are never asked.
    fn initial_step(&mut self, _model: &Model, _t: f64, _y: &[f64], t_end: f64) -> f64 {
        t_end / 100.0
    }
}

/// Sees the state at every sample time (including t = 0 and t_end).
pub trait Observer {
    /// Called between steps at sample time `t` with state `y`.
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]);

    /// Forgets everything recorded: a run is being repeated (the `auto` verification ladder).
    fn reset(&mut self);

    /// Whether whoever asked for the run no longer wants it (Ctrl-C in a Python session, a
    /// sweep being stopped). Asked at every sample, so a run stops within one sample
    /// interval with [`SimError::Cancelled`](crate::SimError::Cancelled) instead of running to `t_end`.
    fn cancelled(&self) -> bool {
        false
    }
}

impl Observer for () {
    fn observe(&mut self, _: &Model, _: f64, _: &[f64]) {}
    fn reset(&mut self) {}
}

/// An observer its caller may stop: `inner` records, and the run is cancelled once `stop`
/// says so (Ctrl-C in Python, a sweep being stopped).
pub struct Stoppable<'a, O> {
    /// What records the run.
    pub inner: O,
    /// Asked at every sample whether the run is still wanted.
    pub stop: &'a dyn Fn() -> bool,
}

impl<O: Observer> Observer for Stoppable<'_, O> {
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]) {
        self.inner.observe(model, t, y);
    }
    fn reset(&mut self) {
        self.inner.reset();
    }
    fn cancelled(&self) -> bool {
        (self.stop)() || self.inner.cancelled()
    }
}

/// An observer that may not be there: a run that records only when asked.
impl<A: Observer> Observer for Option<A> {
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]) {
        if let Some(inner) = self {
            inner.observe(model, t, y);
        }
    }
    fn reset(&mut self) {
        if let Some(inner) = self {
            inner.reset();
        }
    }
    fn cancelled(&self) -> bool {
        self.as_ref().is_some_and(Observer::cancelled)
    }
}

impl<A: Observer, B: Observer> Observer for (A, B) {
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]) {
        self.0.observe(model, t, y);
        self.1.observe(model, t, y);
    }
    fn reset(&mut self) {
        self.0.reset();
        self.1.reset();
    }
    fn cancelled(&self) -> bool {
        self.0.cancelled() || self.1.cancelled()
    }
}

/// Records nothing but passes on whether `O` wants the run stopped: the observer of runs
/// whose samples nobody keeps (`auto`'s verification runs), which must stop all the same.
pub struct CancelOnly<'a, O: ?Sized>(pub &'a O);

impl<O: Observer + ?Sized> Observer for CancelOnly<'_, O> {
    fn observe(&mut self, _: &Model, _: f64, _: &[f64]) {}
    fn reset(&mut self) {}
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

/// How step sizes are chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepControl {
    /// Equal steps no longer than `dt`, tiling each sample interval exactly.
    Fixed {
        /// Largest step.
        dt: f64,
    },
    /// The stepper's own error control; the driver only enforces `h_min`.
    Adaptive {
        /// Steps below this are a [`SimError::StepUnderflow`](crate::SimError::StepUnderflow).
        h_min: f64,
    },
}

/// Most steps (accepted plus rejected) one run may take: about a minute of one core on the
/// paper's chain. [`drive`] enforces it (as `DriveConfig::max_steps`, which plans set to it);
/// `simulation::budget::check` refuses a run that would exceed it before it starts.
pub const MAX_STEPS: u64 = 50_000_000;

/// Everything the driver needs besides the model, stepper and state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveConfig {
    /// Integrate over [0, t_end].
    pub t_end: f64,
    /// Observers and checks run every `sample_every` (and at t_end).
    pub sample_every: f64,
    /// Step-size policy.
    pub control: StepControl,
    /// Budget of accepted plus rejected steps.
    pub max_steps: u64,
    /// Largest allowed relative energy drift |E(t) - E(0)|/E(0), checked at samples when the
    /// model conserves energy; `None` disables the check.
    pub energy_drift_limit: Option<f64>,
    /// Work only on the sites the wave has reached ([`ActiveSites`]). The result is bitwise the
    /// same either way (tested); `false` is the full model, for that test and for benchmarks.
    pub active_window: bool,
}

/// What a run cost and how well it kept its invariants.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// The longest accepted step. A fixed step `dt` is what each sample interval is cut into
    /// equal steps of at most: with `sample_every = 1` and `dt = 0.8` every step is 0.5, and
    /// this says so.
    pub max_step: f64,
    /// Rejected step attempts (adaptive methods).
    pub rejected: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Largest relative energy drift seen at the samples, of the ledger E + D for a
    /// dissipative chain (0 when the coupling depends on time).
    pub max_energy_drift: f64,
    /// Sites worked on, summed over step attempts: the window's width each time. The full
    /// model's count is `n_sites × attempts`; the ratio is what the active window saves, as a
    /// machine-independent number.
    pub site_steps: u64,
    /// The first sample time at which a chain end that was at rest at t = 0 moves at more
    /// than [`END_ARRIVAL_SPEED`] of the impact's speed: when the wave reached a wall or a
    /// free end. `None`: it never did (the paper's scenes end before it does).
    pub end_reached_at: Option<f64>,
}
