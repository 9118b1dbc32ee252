//! The methods: their names and everything known about each, in one table ([`FACTS`]), and
//! what a scene asks for (`auto` or a named method). The plan that runs one is `super::plan`.

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
    /// `rkn6-contact` with every harmonic resonator (linear, constant κ, alone on its host)
    /// integrated exactly: the extended Nyström step of `integrate::exact_resonator`, whose
    /// accuracy does not depend on the resonator's frequency. `auto`'s method on a chain with
    /// such a resonator.
    Erkn6Contact,
    /// Störmer–Verlet, order 2, symplectic, fixed step.
    Verlet,
    /// Triple-jump composition of Verlet, order 4, symplectic, fixed step.
    Yoshida4,
    /// Seven-stage composition of Verlet, order 6, symplectic, fixed step.
    Yoshida6,
    /// Dormand–Prince 8(5,3), adaptive.
    Dop853,
    /// `rkn6-contact` on the chain without its losses, between two exact half-step flows of
    /// losses that act on velocities alone and linearly (`integrate::split_losses`): order 2.
    /// `auto`'s method on a chain with such losses and no contact dashpot.
    Rkn6Split,
}

impl Method {
    /// Every method, in a stable order (the order of [`FACTS`]).
    pub const ALL: [Method; 10] = [
        Method::Rk4,
        Method::Rk4Contact,
        Method::Rkn4Contact,
        Method::Rkn6Contact,
        Method::Erkn6Contact,
        Method::Verlet,
        Method::Yoshida4,
        Method::Yoshida6,
        Method::Dop853,
        Method::Rkn6Split,
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

    /// Whether the method integrates harmonic resonators exactly ([`crate::Model::is_harmonic`]),
    /// so that their frequency caps none of its steps.
    pub fn integrates_harmonic_exactly(self) -> bool {
        self == Method::Erkn6Contact
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

/// The error model of DPRKN6 with exact contact events (`rkn6-contact`, `erkn6-contact`).
/// Order 6 between contact events; across them the fractions' errors fall about 7-fold per
/// halving from 0.2 to 0.1 (worst over 25 sweep scenes: 1.7e-6 to 2.3e-7, the `error_split`
/// example), so the Richardson estimate assumes order 3. The coefficient puts the first step
/// at 0.1 for tolerance 1e-6, where the worst measured error is 2.3e-7, and 0.215 for 1e-5: a
/// smaller first step costs more evaluations over the surveys at 1e-5 and 1e-6, where the
/// sweeps run, and a larger one more halvings.
const RKN6_ERROR: ErrorModel = ErrorModel {
    coef: 1e-3,
    order: 3.0,
};

/// One row per method, in the order of [`Method::ALL`] (a test checks it).
const FACTS: [Facts; 10] = [
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
        error: RKN6_ERROR,
    },
    Facts {
        name: "erkn6-contact",
        order: 6,
        adaptive: false,
        velocity_forces: false,
        // Its harmonic resonators are exact at any step; this bounds the others (nonlinear or
        // ramped), which it integrates as `rkn6-contact` does.
        stability_limit: 1.0,
        // As `rkn6-contact`'s, which it is wherever no harmonic resonator vibrates.
        error: RKN6_ERROR,
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
    Facts {
        name: "rkn6-split",
        order: 2,
        adaptive: false,
        // Only for the linear losses it integrates exactly; `Plan::choose` refuses it a
        // contact dashpot.
        velocity_forces: true,
        stability_limit: 1.0,
        // The splitting's order 2, with a coefficient that puts the first step at 0.01 for
        // tolerance 1e-8: on the standard scene with Q = 300 its error is 8.9e-10 there and
        // falls 4 times per halving (docs/performance.md, "Damped chains"). Never above
        // `rkn6-contact`'s step ([`Method::calibrated_dt`]).
        error: ErrorModel {
            coef: 1e-4,
            order: 2.0,
        },
    },
];

/// The method a scene asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodChoice {
    /// Let [`Plan::choose`](super::Plan::choose) pick.
    Auto,
    /// Use this method.
    Named(Method),
}

impl Method {
    /// The fixed step the calibrated error model predicts for `tol`, before any resonator
    /// caps it (never above 0.25).
    pub(super) fn calibrated_dt(self, tol: f64) -> f64 {
        let em = &self.facts().error;
        let dt = (tol / em.coef).powf(1.0 / em.order).min(0.25);
        match self {
            // Where the losses are light the conservative step's own error sets the step.
            Method::Rkn6Split => dt.min(Method::Rkn6Contact.calibrated_dt(tol)),
            _ => dt,
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Accuracy, Plan, AUTO_METHOD};
    use crate::model::Model;

    /// Every method's row of facts, its name in scene files, and the stepper a plan builds for
    /// it, which reports the same name: one table of names, checked for all nine.
    #[test]
    fn every_method_has_its_own_row_of_facts() {
        let names = [
            "rk4",
            "rk4-contact",
            "rkn4-contact",
            "rkn6-contact",
            "erkn6-contact",
            "verlet",
            "yoshida4",
            "yoshida6",
            "dop853",
            "rkn6-split",
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
