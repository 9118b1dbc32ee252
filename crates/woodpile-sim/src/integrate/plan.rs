//! The plan that turns "method + tolerance (or dt)" into a concrete stepper and step control
//! for one model: the calibrated step, the resonance and stability caps, and `auto`'s first
//! plan.

use super::{
    drive, ContactMode, Dop853, DriveConfig, Method, MethodChoice, Observer, Rk4Fused, Rkn, Rkn4,
    SplitLosses, Stats, StepControl, Stepper, SymplecticStepper, DPRKN6, VERLET, YOSHIDA4,
    YOSHIDA6,
};
use crate::error::SimError;
use crate::model::Model;

/// What accuracy the caller asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accuracy {
    /// Target absolute accuracy of the energy fractions.
    pub tolerance: f64,
    /// Whether `tolerance` was given explicitly (then it also bounds the energy drift of
    /// fixed-step runs with an explicit `dt`).
    pub tolerance_explicit: bool,
    /// An explicit fixed step, for fixed-step methods.
    pub dt: Option<f64>,
}

/// Relative energy drift that stops a run whose accuracy was set by an explicit `dt` alone:
/// past this, nothing computed is worth reporting.
pub const BLOW_UP_DRIFT: f64 = 1e-3;

/// A resolved integration plan: which stepper, with which step control and tolerances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plan {
    /// The method.
    pub method: Method,
    /// Fixed dt, or adaptive.
    pub control: StepControl,
    /// Relative tolerance for the adaptive method.
    pub rtol: f64,
    /// Absolute tolerance for the adaptive method.
    pub atol: f64,
    /// Energy drift bound for conservative runs.
    pub drift_limit: f64,
}

/// Relative tolerance given to DOP853 per unit of requested fraction accuracy (measured: rtol
/// 1e-12 gives |dE_tr| ~ 1e-8 on the single-defect scene).
const DOP853_RTOL_PER_TOL: f64 = 1e-3;

/// Energy drift allowed per unit of requested fraction accuracy. Measured drift is 7 to 70 times
/// the fraction error for the fixed-step methods (the fractions are normalised by E(t), which
/// cancels most of a global energy error), so a drift beyond 100x means the run missed its target.
pub const DRIFT_PER_TOL: f64 = 100.0;

/// The method `auto` verifies by step halving: the sixth-order Nyström method with exact
/// contact events. On the sweeps' own scenes its errors at dt = 0.1 are 10 to 2000 times
/// smaller than `rk4-contact`'s (docs/performance.md, "Where the error comes from"), and over
/// the `auto_accuracy` survey it needs 2.6 to 2.8 times fewer force evaluations than
/// `rk4-contact` did at tolerances 1e-5 to 1e-7, with no scene missing its tolerance.
pub const AUTO_METHOD: Method = Method::Rkn6Contact;

/// The method `auto` verifies on a chain with a harmonic resonator ([`Model::is_harmonic`])
/// too fast for [`AUTO_METHOD`] at the tolerance's step ([`Plan::exact_step_pays`]): that
/// method with those resonators integrated exactly, so that their frequency no longer caps the
/// step (docs/methods.md, "Harmonic resonators integrated exactly").
pub const HARMONIC_AUTO_METHOD: Method = Method::Erkn6Contact;

/// The method `auto` verifies on a dissipative chain, whose dashpots make the forces depend
/// on velocities, which the Nyström methods cannot take: RK4 with exact contact events, each
/// event bond's force (spring, dashpot and clip) integrated along its path
/// (docs/methods.md, "Dissipation").
pub const DISSIPATIVE_AUTO_METHOD: Method = Method::Rk4Contact;

/// The method `auto` verifies on a dissipative chain whose losses all act on velocities alone
/// and linearly ([`Model::losses_are_linear`]: no contact dashpot): `rkn6-contact` between
/// their exact flows (docs/methods.md, "Linear losses split from the step").
pub const LINEAR_LOSSES_AUTO_METHOD: Method = Method::Rkn6Split;

/// The fastest linear loss ([`Model::linear_loss_rate`], 1/time) that `auto` splits from the
/// step. Splitting errs by the losses' failure to commute with the forces, which grows with
/// their rate: a soft end's dashpot of 100 on a unit mass (a near wall) estimated 2.8e-6 at
/// dt = 0.002 and could not reach a tolerance of 1e-7, where `rk4-contact` does. The chain's
/// own contacts vibrate at rates about 1.
pub const SPLIT_MAX_LOSS_RATE: f64 = 0.5;

/// Largest omega * dt `auto` and tolerance-driven fixed steps accept for the fastest linear
/// resonator: keeps its phase accurate, not merely stable.
const MAX_OMEGA_DT: f64 = 0.5;

/// Largest omega * dt for a harmonic resonator that the method integrates exactly
/// ([`Method::integrates_harmonic_exactly`]): its free vibration is exact at any step, but the
/// contact forces its host feels are sampled at the stages, and a coarse run at twice this
/// step must stay clear of omega * dt = 2 pi, where those samples alias (a p = 1, eps = 0.05,
/// kappa = 10 scene drifts by 2e-4 there and is within 2e-6 at 6.0 and 1.2e-7 at pi).
const MAX_HARMONIC_OMEGA_DT: f64 = 2.0;

impl Plan {
    /// Resolves `choice` and `accuracy` for `model`. For [`MethodChoice::Auto`] this is the
    /// first (finest) plan of the verification ladder run by [`crate::simulation::simulate`].
    pub fn choose(
        model: &Model,
        choice: MethodChoice,
        accuracy: Accuracy,
    ) -> Result<Plan, SimError> {
        let tol = accuracy.tolerance;
        if !(tol.is_finite() && tol > 0.0) {
            return Err(SimError::BadRun(format!(
                "tolerance must be finite and > 0, got {tol}"
            )));
        }
        if let Some(dt) = accuracy.dt {
            if !(dt.is_finite() && dt > 0.0) {
                return Err(SimError::BadRun(format!(
                    "dt must be finite and > 0, got {dt}"
                )));
            }
        }
        let method = match choice {
            MethodChoice::Named(m) => m,
            MethodChoice::Auto if Self::splits_losses(model) => LINEAR_LOSSES_AUTO_METHOD,
            MethodChoice::Auto if model.is_dissipative() => DISSIPATIVE_AUTO_METHOD,
            MethodChoice::Auto if Self::exact_step_pays(model, tol) => HARMONIC_AUTO_METHOD,
            MethodChoice::Auto => AUTO_METHOD,
        };
        if model.is_dissipative() && !method.takes_velocity_forces() {
            return Err(SimError::VelocityForces {
                method: method.name(),
                methods: Self::methods_for_losses(model),
            });
        }
        if method == Method::Rkn6Split && !model.losses_are_linear() {
            return Err(SimError::BadRun(format!(
                "method {} integrates only losses that act on velocities alone (ground damping, resonator dashpots, soft ends); a contact dashpot needs one of {}",
                method.name(),
                Self::methods_for_losses(model)
            )));
        }
        let tolerance_drift = (DRIFT_PER_TOL * tol).max(1e-12);
        if method.is_adaptive() {
            let rtol = (tol * DOP853_RTOL_PER_TOL).max(1e-14);
            return Ok(Plan {
                method,
                control: StepControl::Adaptive { h_min: 1e-12 },
                rtol,
                atol: rtol,
                drift_limit: tolerance_drift,
            });
        }
        let (dt, drift_limit) = match accuracy.dt {
            Some(dt) => {
                let limit = if accuracy.tolerance_explicit {
                    tolerance_drift
                } else {
                    BLOW_UP_DRIFT
                };
                (dt, limit)
            }
            None => (Self::dt_for(model, method, tol), tolerance_drift),
        };
        Ok(Plan {
            method,
            control: StepControl::Fixed { dt },
            rtol: 0.0,
            atol: 0.0,
            drift_limit,
        })
    }

    /// The fixed step predicted to reach `tol` with `method` on `model`: the calibrated error
    /// model, capped so that the fastest linear resonator is resolved and never above 0.25.
    pub fn dt_for(model: &Model, method: Method, tol: f64) -> f64 {
        let exact = method.integrates_harmonic_exactly();
        let omega = model.max_linear_omega(exact);
        let resolved = step_within(MAX_OMEGA_DT, omega).min(Self::harmonic_dt(model, method));
        let stable = step_within(0.9 * method.stability_limit(), omega);
        Self::tolerance_dt(method, tol).min(resolved).min(stable)
    }

    /// The named methods that can run `model`'s losses, listed for a refusal: those for
    /// velocity-dependent forces, `rkn6-split` only where the losses are linear.
    fn methods_for_losses(model: &Model) -> String {
        Method::with_velocity_forces()
            .filter(|&m| m != Method::Rkn6Split || model.losses_are_linear())
            .map(Method::name)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Whether `auto` integrates `model`'s losses apart from its conservative step
    /// ([`LINEAR_LOSSES_AUTO_METHOD`]): a dissipative chain with no contact dashpot whose
    /// losses are slower than [`SPLIT_MAX_LOSS_RATE`].
    fn splits_losses(model: &Model) -> bool {
        model.is_dissipative()
            && model.losses_are_linear()
            && model.linear_loss_rate() <= SPLIT_MAX_LOSS_RATE
    }

    /// Whether `auto` should integrate `model`'s harmonic resonators exactly at tolerance `tol`:
    /// when the coarse run of its first pair, at twice the tolerance's step, would take the
    /// fastest of them past ω dt = [`MAX_OMEGA_DT`], beyond which DPRKN6 does not resolve it.
    /// Below that the plain step is as accurate and cheaper: the exact one spends about 8% more
    /// instructions a step on a chain of 100 sites with two heavy resonators (callgrind), for
    /// nothing. So the paper's heavy resonators keep `rkn6-contact` and its numbers.
    fn exact_step_pays(model: &Model, tol: f64) -> bool {
        2.0 * Self::tolerance_dt(AUTO_METHOD, tol) * model.max_harmonic_omega() > MAX_OMEGA_DT
    }

    /// The fixed step the calibrated error model predicts for `tol` with `method`, before any
    /// resonator caps it (never above 0.25). For an adaptive method, its step scale.
    pub fn tolerance_dt(method: Method, tol: f64) -> f64 {
        method.calibrated_dt(tol)
    }

    /// The largest step that keeps every resonator of `model` resolved (omega * dt at most
    /// 0.5) in a motion of total energy `energy`, at the stiffest moment the energy allows
    /// ([`Model::max_resonator_omega`]). For linear resonators [`Plan::dt_for`] already
    /// applies this cap; for nonlinear ones (p > 1) it is what keeps `auto`'s verification
    /// pair out of the regime where both runs miss the resonator's stiff moments by the same
    /// amount and agree (p = 19, eps = 0.09 at tolerance 1e-5: both runs off by 3e-5, their
    /// difference 2.6e-6).
    ///
    /// A chain under a [`crate::ContactLaw`] is held to the same bound on its stiffest
    /// contact ([`Model::max_contact_omega`]); the paper's chain has none and is not capped.
    pub fn resolving_dt(model: &Model, method: Method, energy: f64) -> f64 {
        let omega = model
            .max_resonator_omega(energy, method.integrates_harmonic_exactly())
            .max(model.max_contact_omega(energy))
            .max(model.max_dissipation_rate(energy));
        step_within(MAX_OMEGA_DT, omega).min(Self::harmonic_dt(model, method))
    }

    /// The step resonator `j` of `model` allows `method` in a motion of total energy `energy`:
    /// what [`Plan::resolving_dt`] takes the smallest of, resonator by resonator (to say which
    /// one set a step).
    pub fn resonator_dt(model: &Model, method: Method, j: usize, energy: f64) -> f64 {
        let r = &model.resonators()[j];
        let omega = r.omega_within(model.site_mass(r.site), energy);
        let cap = match method.integrates_harmonic_exactly() && model.is_harmonic(j) {
            true => MAX_HARMONIC_OMEGA_DT,
            false => MAX_OMEGA_DT,
        };
        step_within(cap, omega)
    }

    /// The step the stiffest contact of `model` allows in a motion of total energy `energy`
    /// (infinite for the paper's chain, [`Model::max_contact_omega`]).
    pub fn contact_dt(model: &Model, energy: f64) -> f64 {
        step_within(MAX_OMEGA_DT, model.max_contact_omega(energy))
    }

    /// The step the fastest dashpot or soft end of `model` allows in a motion of total
    /// energy `energy` (infinite without them, [`Model::max_dissipation_rate`]).
    pub fn dissipation_dt(model: &Model, energy: f64) -> f64 {
        step_within(MAX_OMEGA_DT, model.max_dissipation_rate(energy))
    }

    /// The cap a method that integrates harmonic resonators exactly keeps on them
    /// ([`MAX_HARMONIC_OMEGA_DT`]); none for other methods, which resolve them by
    /// [`MAX_OMEGA_DT`].
    fn harmonic_dt(model: &Model, method: Method) -> f64 {
        match method.integrates_harmonic_exactly() {
            true => step_within(MAX_HARMONIC_OMEGA_DT, model.max_harmonic_omega()),
            false => f64::INFINITY,
        }
    }

    /// The same plan with a fixed step `dt` (for the verification ladder).
    pub fn with_dt(&self, dt: f64) -> Plan {
        Plan {
            control: StepControl::Fixed { dt },
            ..*self
        }
    }

    /// The fixed step, if any.
    pub fn dt(&self) -> Option<f64> {
        match self.control {
            StepControl::Fixed { dt } => Some(dt),
            StepControl::Adaptive { .. } => None,
        }
    }

    /// Runs the plan: builds the stepper for `model` and drives `y` to `t_end`, working only on
    /// the sites the wave has reached.
    pub fn integrate<O: Observer + ?Sized>(
        &self,
        model: &Model,
        y: &mut [f64],
        t_end: f64,
        sample_every: f64,
        observer: &mut O,
    ) -> Result<Stats, SimError> {
        self.integrate_model(model, y, (t_end, sample_every), observer, true)
    }

    /// [`Plan::integrate`], choosing whether to skip the sites at rest (`active_window`) or to work
    /// on the full chain. Both give the same bits; the full model is for tests and benchmarks.
    pub fn integrate_model<O: Observer + ?Sized>(
        &self,
        model: &Model,
        y: &mut [f64],
        (t_end, sample_every): (f64, f64),
        observer: &mut O,
        active_window: bool,
    ) -> Result<Stats, SimError> {
        let cfg = self.drive_config((t_end, sample_every), active_window);
        // One dynamic call a step picks the stepper; its loops inside are static.
        drive(model, &mut *self.stepper(model), y, &cfg, observer)
    }

    /// What the driver is told of this plan for a run to `t_end`, sampled every
    /// `sample_every`.
    pub fn drive_config(
        &self,
        (t_end, sample_every): (f64, f64),
        active_window: bool,
    ) -> DriveConfig {
        DriveConfig {
            t_end,
            sample_every,
            control: self.control,
            max_steps: super::MAX_STEPS,
            energy_drift_limit: Some(self.drift_limit),
            active_window,
        }
    }

    /// The stepper of the plan's method for `model`: the one place a method becomes code.
    pub fn stepper(&self, model: &Model) -> Box<dyn Stepper> {
        match self.method {
            Method::Rk4 => Box::new(Rk4Fused::new(model)),
            Method::Rk4Contact => Box::new(Rk4Fused::with_contact_events(model)),
            Method::Rkn4Contact => Box::new(Rkn4::with_contact_events(model)),
            Method::Rkn6Contact => Box::new(Rkn::new(model, DPRKN6, ContactMode::Corrected)),
            Method::Erkn6Contact => Box::new(
                Rkn::new(model, DPRKN6, ContactMode::Corrected)
                    .with_exact_resonators(model, Method::Erkn6Contact.name()),
            ),
            Method::Verlet => Box::new(SymplecticStepper::new(model, VERLET)),
            Method::Yoshida4 => Box::new(SymplecticStepper::new(model, YOSHIDA4)),
            Method::Yoshida6 => Box::new(SymplecticStepper::new(model, YOSHIDA6)),
            Method::Dop853 => Box::new(Dop853::new(model, self.rtol, self.atol)),
            Method::Rkn6Split => Box::new(SplitLosses::new(model)),
        }
    }
}

/// The largest step that keeps ω dt within `limit` for a frequency `omega` (none for 0).
fn step_within(limit: f64, omega: f64) -> f64 {
    if omega > 0.0 {
        limit / omega
    } else {
        f64::INFINITY
    }
}
