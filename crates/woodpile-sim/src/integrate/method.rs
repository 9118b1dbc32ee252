//! Method names, and the plan that turns "method + tolerance (or dt)" into a concrete stepper
//! and step control for one model. `method = "auto"` lives here.

use super::{
    drive, ContactMode, Dop853, DriveConfig, Observer, Rk4Fused, Rkn, Rkn4, Stats, StepControl,
    SymplecticStepper, DPRKN6, VERLET, YOSHIDA4, YOSHIDA6,
};
use crate::error::SimError;
use crate::model::Model;

/// A named integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Classical Runge–Kutta of order 4, fixed step (the paper's method).
    Rk4,
    /// RK4 whose step integrates each Hertz contact that opens or closes inside it along the
    /// contact's path (see `integrate::contact_event`): the kink no longer limits the order.
    Rk4Contact,
    /// Nyström's three-stage Runge–Kutta–Nyström method of order 4 with the same exact contact
    /// events (`integrate::rkn4`): three force evaluations per step where RK4 needs four.
    Rkn4Contact,
    /// Dormand, El-Mikkawy and Prince's six-stage Runge–Kutta–Nyström method of order 6
    /// (`integrate::rkn`) with the same exact contact events.
    Rkn6Contact,
    /// Störmer–Verlet, order 2, symplectic, fixed step.
    Verlet,
    /// Triple-jump composition of Verlet, order 4, symplectic, fixed step.
    Yoshida4,
    /// Seven-stage composition of Verlet, order 6, symplectic, fixed step.
    Yoshida6,
    /// Dormand–Prince 8(5,3), adaptive.
    Dop853,
}

impl Method {
    /// Every method, in a stable order.
    pub const ALL: [Method; 8] = [
        Method::Rk4,
        Method::Rk4Contact,
        Method::Rkn4Contact,
        Method::Rkn6Contact,
        Method::Verlet,
        Method::Yoshida4,
        Method::Yoshida6,
        Method::Dop853,
    ];

    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Rk4 => "rk4",
            Method::Rk4Contact => "rk4-contact",
            Method::Rkn4Contact => "rkn4-contact",
            Method::Rkn6Contact => "rkn6-contact",
            Method::Verlet => "verlet",
            Method::Yoshida4 => "yoshida4",
            Method::Yoshida6 => "yoshida6",
            Method::Dop853 => "dop853",
        }
    }

    /// Parses a scene-file name.
    pub fn from_name(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Classical order on smooth problems.
    pub fn order(self) -> u32 {
        match self {
            Method::Verlet => 2,
            Method::Rk4 | Method::Rk4Contact | Method::Rkn4Contact | Method::Yoshida4 => 4,
            Method::Yoshida6 | Method::Rkn6Contact => 6,
            Method::Dop853 => 8,
        }
    }

    /// The order its errors in the energy fractions show on Hertzian chains (the calibrated
    /// error model's): what `auto`'s Richardson estimate divides by, 2^order - 1.
    pub fn observed_order(self) -> f64 {
        error_model(self).order
    }

    /// Whether the method controls its own step.
    pub fn is_adaptive(self) -> bool {
        matches!(self, Method::Dop853)
    }

    /// Force evaluations per step (per accepted step for the adaptive method).
    pub fn evals_per_step(self) -> u32 {
        match self {
            Method::Rk4 | Method::Rk4Contact => 4,
            Method::Verlet => 1,
            Method::Yoshida4 | Method::Rkn4Contact => 3,
            Method::Rkn6Contact => 6,
            Method::Yoshida6 => 7,
            Method::Dop853 => 12,
        }
    }

    /// Largest dt * omega for which the method is stable on the linear oscillator
    /// x'' = -omega^2 x (its stability interval on the imaginary axis for RK; HLW Section I.5 for
    /// compositions), used to keep fixed steps safe for stiff resonators.
    pub fn stability_limit(self) -> f64 {
        match self {
            Method::Rk4 | Method::Rk4Contact => 2.0 * std::f64::consts::SQRT_2,
            // The spectral radius of one step on the oscillator exceeds 1 past 2.5867 (computed).
            Method::Rkn4Contact => 2.586,
            // Computed the same way for DPRKN6.
            Method::Rkn6Contact => RKN6_STABILITY_LIMIT,
            Method::Verlet => 2.0,
            Method::Yoshida4 => 1.57,
            Method::Yoshida6 => 1.0,
            Method::Dop853 => 3.5,
        }
    }
}

/// The method a scene asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodChoice {
    /// Let [`Plan::choose`] pick.
    Auto,
    /// Use this method.
    Named(Method),
}

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

/// Calibrated error model of a fixed-step method: error in the energy fractions of the paper's
/// linear scenes ~ `coef * dt^order`. Measured against RK4 at dt = 0.001 on the single, L = 2,
/// separated and ramp scenes (`cargo run --release -p woodpile-sim --example calibrate`). The
/// observed order is 2.5 for every method, not the classical one: where a contact opens or closes
/// the force is (t - t*)_+^{3/2}, whose integral over a step is only accurate to O(h^{5/2}).
/// `rk4-contact` integrates those steps exactly and shows order 3 to 3.5; its coefficient puts
/// `auto`'s first step at 0.04 for tolerance 1e-6, where the first Richardson pair passes on
/// most of the paper's scenes (`cargo run --release -p woodpile-bench --example auto_accuracy`).
struct ErrorModel {
    coef: f64,
    order: f64,
}

fn error_model(method: Method) -> ErrorModel {
    match method {
        Method::Rk4Contact => ErrorModel {
            coef: 1.56e-2,
            order: 3.0,
        },
        // A third of rk4-contact's: its R and T errors on the standard scene are 3 to 4 times
        // smaller at every step from 0.02 to 0.1.
        Method::Rkn4Contact => ErrorModel {
            coef: 5.2e-3,
            order: 2.8,
        },
        // Order 6 between contact events; across them the fractions' errors fall about 7-fold
        // per halving from 0.2 to 0.1 (worst over 25 sweep scenes: 1.7e-6 to 2.3e-7, the
        // `error_split` example), so the Richardson estimate assumes order 3. The coefficient
        // puts the first step at 0.1 for tolerance 1e-6, where the worst measured error is
        // 2.3e-7, and 0.215 for 1e-5; 5e-4 and 2e-3 were tried and cost more evaluations
        // over the `auto_accuracy` and `auto_wide` surveys at 1e-5 and 1e-6, where the sweeps run.
        Method::Rkn6Contact => ErrorModel {
            coef: 1e-3,
            order: 3.0,
        },
        Method::Verlet => ErrorModel {
            coef: 1.5e-2,
            order: 2.0,
        },
        Method::Rk4 => ErrorModel {
            coef: 1.5e-3,
            order: 2.5,
        },
        Method::Yoshida4 => ErrorModel {
            coef: 1.0e-2,
            order: 2.5,
        },
        Method::Yoshida6 => ErrorModel {
            coef: 3.0e-3,
            order: 2.5,
        },
        Method::Dop853 => ErrorModel {
            coef: 1.0,
            order: 8.0,
        },
    }
}

/// DPRKN6 is not dissipative: on x'' = -ω² x one step grows the amplitude by 1.7e-8 at ωh = 0.5
/// and 4e-6 at 1 (computed), so its bound is the growth it may accumulate, not an edge.
const RKN6_STABILITY_LIMIT: f64 = 1.0;

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

/// Largest omega * dt `auto` and tolerance-driven fixed steps accept for the fastest linear
/// resonator: keeps its phase accurate, not merely stable.
const MAX_OMEGA_DT: f64 = 0.5;

impl Plan {
    /// Resolves `choice` and `accuracy` for `model`. For [`MethodChoice::Auto`] this is the
    /// first (finest) plan of the verification ladder run by [`crate::run::simulate`].
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
            MethodChoice::Auto => AUTO_METHOD,
        };
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
        let omega = model.max_linear_omega();
        let resolved = if omega > 0.0 {
            MAX_OMEGA_DT / omega
        } else {
            f64::INFINITY
        };
        let stable = if omega > 0.0 {
            0.9 * method.stability_limit() / omega
        } else {
            f64::INFINITY
        };
        Self::tolerance_dt(method, tol).min(resolved).min(stable)
    }

    /// The fixed step the calibrated error model predicts for `tol` with `method`, before any
    /// resonator caps it (never above 0.25). For an adaptive method, its step scale.
    pub fn tolerance_dt(method: Method, tol: f64) -> f64 {
        let em = error_model(method);
        (tol / em.coef).powf(1.0 / em.order).min(0.25)
    }

    /// The largest step that keeps every resonator of `model` resolved (omega * dt at most
    /// 0.5) in a motion of total energy `energy`, at the stiffest moment the energy allows
    /// ([`Model::max_resonator_omega`]). For linear resonators [`Plan::dt_for`] already
    /// applies this cap; for nonlinear ones (p > 1) it is what keeps `auto`'s verification
    /// pair out of the regime where both runs miss the resonator's stiff moments by the same
    /// amount and agree (p = 19, eps = 0.09 at tolerance 1e-5: both runs off by 3e-5, their
    /// difference 2.6e-6).
    pub fn resolving_dt(model: &Model, energy: f64) -> f64 {
        let omega = model.max_resonator_omega(energy);
        if omega > 0.0 {
            MAX_OMEGA_DT / omega
        } else {
            f64::INFINITY
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
    pub fn run<O: Observer + ?Sized>(
        &self,
        model: &Model,
        y: &mut [f64],
        t_end: f64,
        sample_every: f64,
        observer: &mut O,
    ) -> Result<Stats, SimError> {
        self.run_model(model, y, (t_end, sample_every), observer, true)
    }

    /// [`Plan::run`], choosing whether to skip the sites at rest (`active_window`) or to work
    /// on the full chain. Both give the same bits; the full model is for tests and benchmarks.
    pub fn run_model<O: Observer + ?Sized>(
        &self,
        model: &Model,
        y: &mut [f64],
        (t_end, sample_every): (f64, f64),
        observer: &mut O,
        active_window: bool,
    ) -> Result<Stats, SimError> {
        let cfg = DriveConfig {
            t_end,
            sample_every,
            control: self.control,
            max_steps: crate::budget::MAX_STEPS,
            energy_drift_limit: Some(self.drift_limit),
            active_window,
        };
        match self.method {
            Method::Rk4 => drive(model, &mut Rk4Fused::new(model), y, &cfg, observer),
            Method::Rk4Contact => drive(
                model,
                &mut Rk4Fused::with_contact_events(model),
                y,
                &cfg,
                observer,
            ),
            Method::Rkn4Contact => drive(
                model,
                &mut Rkn4::with_contact_events(model),
                y,
                &cfg,
                observer,
            ),
            Method::Rkn6Contact => drive(
                model,
                &mut Rkn::new(model, DPRKN6, ContactMode::Corrected),
                y,
                &cfg,
                observer,
            ),
            Method::Verlet => drive(
                model,
                &mut SymplecticStepper::new(model, VERLET),
                y,
                &cfg,
                observer,
            ),
            Method::Yoshida4 => drive(
                model,
                &mut SymplecticStepper::new(model, YOSHIDA4),
                y,
                &cfg,
                observer,
            ),
            Method::Yoshida6 => drive(
                model,
                &mut SymplecticStepper::new(model, YOSHIDA6),
                y,
                &cfg,
                observer,
            ),
            Method::Dop853 => drive(
                model,
                &mut Dop853::new(model, self.rtol, self.atol),
                y,
                &cfg,
                observer,
            ),
        }
    }
}
