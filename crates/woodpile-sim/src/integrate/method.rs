//! Method names, and the plan that turns "method + tolerance (or dt)" into a concrete stepper
//! and step control for one model. `method = "auto"` lives here.

use super::{
    drive, ContactMode, Dop853, DriveConfig, Observer, Rk4Fused, Rkn, Rkn4, Stats, StepControl,
    Stepper, SymplecticStepper, DPRKN6, VERLET, YOSHIDA4, YOSHIDA6,
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
    /// Every method, in a stable order (the order of [`FACTS`]).
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

    const fn facts(self) -> &'static Facts {
        &FACTS[self as usize]
    }

    /// The name used in scene files. Const, so that each stepper takes its name from here.
    pub const fn name(self) -> &'static str {
        self.facts().name
    }

    /// Parses a scene-file name.
    pub fn from_name(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Classical order on smooth problems.
    pub fn order(self) -> u32 {
        self.facts().order
    }

    /// The order its errors in the energy fractions show on Hertzian chains (the calibrated
    /// error model's): what `auto`'s Richardson estimate divides by, 2^order - 1.
    pub fn observed_order(self) -> f64 {
        self.facts().error.order
    }

    /// Whether the method controls its own step.
    pub fn is_adaptive(self) -> bool {
        self.facts().adaptive
    }

    /// Whether the method may run a dissipative chain, whose forces depend on velocities.
    pub fn takes_velocity_forces(self) -> bool {
        self.facts().velocity_forces
    }

    /// The named methods that may run a dissipative chain.
    pub fn with_velocity_forces() -> impl Iterator<Item = Method> {
        Method::ALL
            .into_iter()
            .filter(|m| m.takes_velocity_forces())
    }

    /// Largest dt * omega for which the method is stable on the linear oscillator
    /// x'' = -omega^2 x (its stability interval on the imaginary axis for RK; HLW Section I.5 for
    /// compositions), used to keep fixed steps safe for stiff resonators.
    pub fn stability_limit(self) -> f64 {
        self.facts().stability_limit
    }
}

/// Everything known about one method, in one row: [`FACTS`].
struct Facts {
    name: &'static str,
    order: u32,
    adaptive: bool,
    /// Whether the method integrates y'' = f(t, y, y') (a Runge–Kutta method in first-order
    /// form), so that it may run a dissipative chain; the Nyström and symplectic methods
    /// assume forces of positions only.
    velocity_forces: bool,
    stability_limit: f64,
    error: ErrorModel,
}

/// Calibrated error model of a fixed-step method: error in the energy fractions of the paper's
/// linear scenes ~ `coef * dt^order`, measured against a reference run ten times finer on the
/// single, L = 2, separated and ramp scenes. The observed order is 2.5 for the methods that
/// integrate a contact's opening or closing with their ordinary quadrature, not the classical
/// one: there the force is (t - t*)_+^{3/2}, whose integral over a step is only accurate to
/// O(h^{5/2}). The contact-event methods integrate those steps along the contact's path and
/// show order 3 or so (docs/methods.md). The coefficient of `auto`'s method sets its first
/// step; the surveys (`make audit`, the `auto_accuracy` example) check the promise it serves.
struct ErrorModel {
    coef: f64,
    order: f64,
}

/// One row per method, in the order of [`Method::ALL`] (a test checks it).
const FACTS: [Facts; 8] = [
    Facts {
        name: "rk4",
        order: 4,
        adaptive: false,
        velocity_forces: true,
        stability_limit: 2.0 * std::f64::consts::SQRT_2,
        error: ErrorModel {
            coef: 1.5e-3,
            order: 2.5,
        },
    },
    Facts {
        name: "rk4-contact",
        order: 4,
        adaptive: false,
        velocity_forces: true,
        stability_limit: 2.0 * std::f64::consts::SQRT_2,
        error: ErrorModel {
            coef: 1.56e-2,
            order: 3.0,
        },
    },
    Facts {
        name: "rkn4-contact",
        order: 4,
        adaptive: false,
        velocity_forces: false,
        // The spectral radius of one step on the oscillator exceeds 1 past 2.5867 (computed).
        stability_limit: 2.586,
        // A third of rk4-contact's: its R and T errors on the standard scene are 3 to 4 times
        // smaller at every step from 0.02 to 0.1.
        error: ErrorModel {
            coef: 5.2e-3,
            order: 2.8,
        },
    },
    Facts {
        name: "rkn6-contact",
        order: 6,
        adaptive: false,
        velocity_forces: false,
        // DPRKN6 is not dissipative: on x'' = -ω² x one step grows the amplitude by 1.7e-8 at
        // ωh = 0.5 and 4e-6 at 1 (computed), so its bound is the growth it may accumulate, not
        // an edge.
        stability_limit: 1.0,
        // Order 6 between contact events; across them the fractions' errors fall about 7-fold
        // per halving from 0.2 to 0.1 (worst over 25 sweep scenes: 1.7e-6 to 2.3e-7, the
        // `error_split` example), so the Richardson estimate assumes order 3. The coefficient
        // puts the first step at 0.1 for tolerance 1e-6, where the worst measured error is
        // 2.3e-7, and 0.215 for 1e-5: a smaller first step costs more evaluations over the
        // surveys at 1e-5 and 1e-6, where the sweeps run, and a larger one more halvings.
        error: ErrorModel {
            coef: 1e-3,
            order: 3.0,
        },
    },
    Facts {
        name: "verlet",
        order: 2,
        adaptive: false,
        velocity_forces: false,
        stability_limit: 2.0,
        error: ErrorModel {
            coef: 1.5e-2,
            order: 2.0,
        },
    },
    Facts {
        name: "yoshida4",
        order: 4,
        adaptive: false,
        velocity_forces: false,
        stability_limit: 1.57,
        error: ErrorModel {
            coef: 1.0e-2,
            order: 2.5,
        },
    },
    Facts {
        name: "yoshida6",
        order: 6,
        adaptive: false,
        velocity_forces: false,
        stability_limit: 1.0,
        error: ErrorModel {
            coef: 3.0e-3,
            order: 2.5,
        },
    },
    Facts {
        name: "dop853",
        order: 8,
        adaptive: true,
        velocity_forces: true,
        stability_limit: 3.5,
        error: ErrorModel {
            coef: 1.0,
            order: 8.0,
        },
    },
];

/// The method a scene asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodChoice {
    /// Let [`Plan::choose`] pick.
    Auto,
    /// Use this method.
    Named(Method),
}

impl MethodChoice {
    /// `"auto"` and every method, under the names scene and stage files give them: the one
    /// table a method's name is read from.
    pub fn options() -> Vec<(&'static str, MethodChoice)> {
        std::iter::once(("auto", MethodChoice::Auto))
            .chain(Method::ALL.map(|m| (m.name(), MethodChoice::Named(m))))
            .collect()
    }

    /// The choice called `name` (`"auto"` or a method's name).
    pub fn from_name(name: &str) -> Option<MethodChoice> {
        MethodChoice::options()
            .into_iter()
            .find(|(n, _)| *n == name)
            .map(|(_, c)| c)
    }
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

/// The method `auto` verifies on a dissipative chain, whose dashpots make the forces depend
/// on velocities, which the Nyström methods cannot take: RK4 with exact contact events, each
/// event bond's force (spring, dashpot and clip) integrated along its path
/// (docs/methods.md, "Dissipation").
pub const DISSIPATIVE_AUTO_METHOD: Method = Method::Rk4Contact;

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
            MethodChoice::Auto if model.is_dissipative() => DISSIPATIVE_AUTO_METHOD,
            MethodChoice::Auto => AUTO_METHOD,
        };
        if model.is_dissipative() && !method.takes_velocity_forces() {
            return Err(SimError::VelocityForces {
                method: method.name(),
                methods: Method::with_velocity_forces()
                    .map(Method::name)
                    .collect::<Vec<_>>()
                    .join(", "),
            });
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
        let em = &method.facts().error;
        (tol / em.coef).powf(1.0 / em.order).min(0.25)
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
    pub fn resolving_dt(model: &Model, energy: f64) -> f64 {
        let omega = model
            .max_resonator_omega(energy)
            .max(model.max_contact_omega(energy))
            .max(model.max_dissipation_rate(energy));
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
            max_steps: super::MAX_STEPS,
            energy_drift_limit: Some(self.drift_limit),
            active_window,
        };
        // One dynamic call a step picks the stepper; its loops inside are static.
        drive(model, &mut *self.stepper(model), y, &cfg, observer)
    }

    /// The stepper of the plan's method for `model`: the one place a method becomes code.
    pub fn stepper(&self, model: &Model) -> Box<dyn Stepper> {
        match self.method {
            Method::Rk4 => Box::new(Rk4Fused::new(model)),
            Method::Rk4Contact => Box::new(Rk4Fused::with_contact_events(model)),
            Method::Rkn4Contact => Box::new(Rkn4::with_contact_events(model)),
            Method::Rkn6Contact => Box::new(Rkn::new(model, DPRKN6, ContactMode::Corrected)),
            Method::Verlet => Box::new(SymplecticStepper::new(model, VERLET)),
            Method::Yoshida4 => Box::new(SymplecticStepper::new(model, YOSHIDA4)),
            Method::Yoshida6 => Box::new(SymplecticStepper::new(model, YOSHIDA6)),
            Method::Dop853 => Box::new(Dop853::new(model, self.rtol, self.atol)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every method's row of facts, its name in scene files, and the stepper a plan builds for
    /// it, which reports the same name: one table of names, checked for all eight.
    #[test]
    fn every_method_has_its_own_row_of_facts() {
        let names = [
            "rk4",
            "rk4-contact",
            "rkn4-contact",
            "rkn6-contact",
            "verlet",
            "yoshida4",
            "yoshida6",
            "dop853",
        ];
        assert_eq!(Method::ALL.len(), names.len());
        let model = Model::new(21, crate::Boundary::Fixed, Vec::new()).unwrap();
        for (method, name) in Method::ALL.into_iter().zip(names) {
            assert_eq!(method.name(), name);
            let accuracy = Accuracy {
                tolerance: 1e-6,
                tolerance_explicit: true,
                dt: (!method.is_adaptive()).then_some(0.1),
            };
            let plan = Plan::choose(&model, MethodChoice::Named(method), accuracy).unwrap();
            assert_eq!(plan.stepper(&model).name(), name, "{method:?}'s stepper");
        }
        for method in Method::ALL {
            assert_eq!(Method::from_name(method.name()), Some(method));
            assert_eq!(method.is_adaptive(), method == Method::Dop853);
        }
        assert_eq!(AUTO_METHOD.observed_order(), 3.0);
    }
}
