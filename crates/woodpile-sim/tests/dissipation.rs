//! Dissipation's known answers: a contact's coefficient of restitution, a damped resonator's
//! ring-down, a soft end absorbing a solitary wave, ground damping's momentum decay, D rising,
//! the ledger closing (with two damped soft ends too), `rk4-contact`'s order on a damped chain,
//! and the methods that refuse.
#![allow(clippy::unwrap_used)]

use woodpile_sim::energy::{total_momentum, Region};
use woodpile_sim::integrate::{Accuracy, Method, MethodChoice, Plan};
use woodpile_sim::model::{Boundary, End, Model, Resonator};
use woodpile_sim::observe::FractionSeries;
use woodpile_sim::simulation::{run_with_plan, simulate, Outcome, Scenario};
use woodpile_sim::testing::{fitted_order, fixed_dt, tolerance};
use woodpile_sim::{Damping, DashpotLaw, SimError};

fn damping(contact: f64, law: DashpotLaw, ground: f64, resonator: Vec<f64>) -> Damping {
    Damping::new(contact, law, ground, resonator).unwrap()
}

/// A scene of `model` struck at `site` with unit velocity, region `region`, run to `t_end`.
fn scene(
    model: Model,
    site: usize,
    region: (i64, i64),
    t_end: f64,
    accuracy: Accuracy,
) -> Scenario {
    let n = model.n_sites();
    let method = match accuracy.dt {
        Some(_) => MethodChoice::Named(Method::Rk4Contact),
        None => MethodChoice::Auto,
    };
    Scenario {
        model,
        impulse_site: site,
        impulse_velocity: 1.0,
        t_end,
        region: Region::new(region.0, region.1, n).unwrap(),
        method,
        accuracy,
        sample_every: 1.0,
    }
}

fn run(scenario: &Scenario) -> Outcome {
    simulate(scenario, &mut ()).unwrap()
}

/// The velocity a unit-mass bead rebounds with, relative to its partner, after striking an
/// equal bead at rest at relative speed 1 through a Hertz contact with a linear dashpot γ:
/// the relative coordinate c = u0 − u1 obeys c'' = −2 max(0, c^{3/2} + γ c') while c ≥ 0,
/// integrated here by classical RK4 at a step of 1e-5 until the force has vanished and the
/// beads part. An integration written for this test alone, sharing no code with the crate.
fn restitution_reference(gamma: f64) -> f64 {
    let force = |c: f64, rate: f64| match c >= 0.0 {
        true => (c.max(0.0).powf(1.5) + gamma * rate).max(0.0),
        false => 0.0,
    };
    let deriv = |(c, rate): (f64, f64)| (rate, -2.0 * force(c, rate));
    let (h, mut state) = (1e-5, (0.0, 1.0));
    loop {
        let k1 = deriv(state);
        let k2 = deriv((state.0 + 0.5 * h * k1.0, state.1 + 0.5 * h * k1.1));
        let k3 = deriv((state.0 + 0.5 * h * k2.0, state.1 + 0.5 * h * k2.1));
        let k4 = deriv((state.0 + h * k3.0, state.1 + h * k3.1));
        state.0 += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        state.1 += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        if state.0 < 0.0 && state.1 < 0.0 {
            return -state.1;
        }
    }
}

#[test]
fn a_linear_dashpot_gives_the_coefficient_of_restitution_of_a_tight_integration() {
    for gamma in [0.05, 0.3] {
        let model = Model::new(2, Boundary::Free, vec![])
            .unwrap()
            .with_damping(damping(gamma, DashpotLaw::Linear, 0.0, vec![]))
            .unwrap();
        let out = run(&scene(model, 0, (1, 1), 8.0, tolerance(1e-10)));
        let y = &out.final_state;
        let restitution = y[3] - y[2];
        let expected = restitution_reference(gamma);
        assert!(
            (restitution - expected).abs() < 1e-8,
            "gamma {gamma}: e = {restitution}, reference {expected}"
        );
        // The energy the collision lost is what D holds: 1 − e² of the relative motion's share.
        let lost = 0.5 * (1.0 - expected * expected) / 2.0 / out.e_initial;
        assert!((out.fractions.dissipated - lost).abs() < 1e-7);
        assert!(restitution < 1.0 && restitution > 0.0);
    }
}

#[test]
fn a_damped_resonator_rings_down_at_its_damped_frequency_and_rate() {
    // One site with its resonator, nothing else: the stretch x = u − v obeys
    // mu x'' + c x' + kappa x = 0, mu = eps / (1 + eps), from x = 0, x' = 1.
    let (eps, kappa, c): (f64, f64, f64) = (0.5, 2.0, 0.1);
    let mu = eps / (1.0 + eps);
    let omega = (kappa / mu).sqrt();
    let zeta = c / (2.0 * mu * omega);
    let damped = omega * (1.0 - zeta * zeta).sqrt();
    for t_end in [3.0, 7.5, 20.0] {
        let model = Model::new(
            1,
            Boundary::Free,
            vec![Resonator::constant(0, eps, kappa, 1)],
        )
        .unwrap()
        .with_damping(damping(0.0, DashpotLaw::Linear, 0.0, vec![c]))
        .unwrap();
        let out = run(&scene(model, 0, (0, 0), t_end, tolerance(1e-10)));
        let stretch = out.final_state[0] - out.final_state[1];
        let expected = (-zeta * omega * t_end).exp() * (damped * t_end).sin() / damped;
        assert!(
            (stretch - expected).abs() < 1e-8,
            "t = {t_end}: {stretch} vs {expected}"
        );
    }
}

/// The energy a chain keeps after a solitary wave has met a soft end of dashpot `c`.
fn kept_after_a_soft_end(c: f64) -> f64 {
    let right = End::Soft {
        spring: 0.0,
        damping: c,
    };
    let model = Model::new(81, Boundary::ends(End::Free, right), vec![]).unwrap();
    let out = run(&scene(model, 5, (40, 40), 150.0, tolerance(1e-7)));
    1.0 - out.fractions.dissipated
}

#[test]
fn a_soft_end_absorbs_most_as_its_dashpot_approaches_the_chains_impedance() {
    let kept: Vec<f64> = [0.03, 0.1, 0.3, 1.0, 5.0, 100.0]
        .into_iter()
        .map(kept_after_a_soft_end)
        .collect();
    // Falling as the dashpot grows towards the chain's impedance, then rising again as a stiff
    // dashpot turns into a wall.
    assert!(kept[0] > kept[1] && kept[1] > kept[2], "{kept:?}");
    assert!(
        kept[2] < kept[3] && kept[3] < kept[4] && kept[4] < kept[5],
        "{kept:?}"
    );
    assert!(kept[2] < 0.02, "{kept:?}");
    assert!(kept[5] > 0.9, "{kept:?}");
}

#[test]
fn ground_damping_makes_a_free_chains_momentum_decay_exponentially() {
    let (g, mass) = (0.05, 2.0);
    let model = Model::with_masses(20, Boundary::Free, vec![], Some(vec![mass; 20]))
        .unwrap()
        .with_damping(damping(0.2, DashpotLaw::Hertzian, g, vec![]))
        .unwrap();
    for t_end in [10.0, 40.0] {
        let out = run(&scene(model.clone(), 3, (10, 10), t_end, tolerance(1e-9)));
        let momentum = total_momentum(&model, &out.final_state);
        let expected = mass * (-g * t_end / mass).exp();
        assert!(
            (momentum / expected - 1.0).abs() < 1e-8,
            "t = {t_end}: {momentum} vs {expected}"
        );
    }
}

/// A chain with every kind of dissipation: Hertzian or linear contact dashpots, ground
/// damping, a damped resonator and a soft end with spring and dashpot.
fn damped_chain(law: DashpotLaw) -> Model {
    let right = End::Soft {
        spring: 0.05,
        damping: 0.5,
    };
    Model::new(
        41,
        Boundary::ends(End::Free, right),
        vec![Resonator::constant(20, 0.5, 1.0, 1)],
    )
    .unwrap()
    .with_damping(damping(0.1, law, 0.001, vec![0.05]))
    .unwrap()
}

#[test]
fn d_rises_and_the_ledger_closes_at_a_tight_tolerance() {
    for law in [DashpotLaw::Linear, DashpotLaw::Hertzian] {
        let scenario = scene(damped_chain(law), 2, (19, 21), 60.0, tolerance(1e-10));
        let mut series = FractionSeries::new(&scenario.model, scenario.region);
        let out = simulate(&scenario, &mut series).unwrap();
        let f = out.fractions;
        assert!((f.sum() - 1.0).abs() <= 1e-9, "{law:?}: {}", f.sum() - 1.0);
        assert!(out.stats.max_energy_drift <= 1e-9, "{law:?}");
        assert!(f.dissipated > 0.5, "{law:?}: D = {}", f.dissipated);
        assert!(
            series.dissipated.windows(2).all(|w| w[1] >= w[0]),
            "{law:?}"
        );
        // Every sample's shares sum to one as well.
        for k in 0..series.t.len() {
            let sum = series.reflected[k]
                + series.transmitted[k]
                + series.trapped[k]
                + series.dissipated[k];
            assert!((sum - 1.0).abs() <= 1e-9, "{law:?} at t = {}", series.t[k]);
        }
    }
}

/// `rk4-contact` on a chain with every kind of damping, against itself at a far finer step:
/// order about 2.2 with a linear contact dashpot and 1.75 with a Hertzian one, and within
/// 1.5e-9 at dt = 0.005. Without the correction of contacts that open inside their dashpot's
/// clip (`ContactEvents::add_crossings`) the errors at that step were 22 (linear) and 1.2
/// times larger: 8.3e-9 and 1.65e-9 (docs/methods.md, "The onset of a dashpot").
#[test]
fn rk4_contact_converges_on_a_damped_chain() {
    for (law, least_order) in [(DashpotLaw::Linear, 2.1), (DashpotLaw::Hertzian, 1.6)] {
        let at = |dt: f64| run(&scene(damped_chain(law), 2, (19, 21), 40.0, fixed_dt(dt)));
        let reference = at(0.000125).fractions;
        let dts = [0.02, 0.01, 0.005, 0.0025];
        let errors: Vec<f64> = dts
            .iter()
            .map(|&dt| at(dt).fractions.largest_difference(&reference))
            .collect();
        let order = fitted_order(&dts, &errors);
        assert!(
            order > least_order,
            "{law:?}: order {order}, errors {errors:?}"
        );
        assert!(errors[2] < 1.5e-9, "{law:?}: {errors:?}");
    }
}

#[test]
fn auto_meets_its_tolerance_on_damped_chains() {
    for law in [DashpotLaw::Linear, DashpotLaw::Hertzian] {
        let reference = run(&scene(
            damped_chain(law),
            2,
            (19, 21),
            40.0,
            fixed_dt(0.0005),
        ));
        for tol in [1e-6, 1e-8] {
            let out = run(&scene(damped_chain(law), 2, (19, 21), 40.0, tolerance(tol)));
            assert_eq!(out.plan.method, Method::Rk4Contact);
            let error = out.fractions.largest_difference(&reference.fractions);
            assert!(error <= tol, "{law:?} at {tol}: error {error}");
        }
    }
}

#[test]
fn methods_for_position_forces_refuse_a_damped_chain() {
    let model = damped_chain(DashpotLaw::Linear);
    for method in Method::ALL {
        let plan = Plan::choose(&model, MethodChoice::Named(method), fixed_dt(0.01));
        match (method.takes_velocity_forces(), method) {
            // It takes linear losses only, and this chain has a contact dashpot.
            (true, Method::Rkn6Split) => assert!(
                matches!(&plan, Err(SimError::BadRun(why)) if why.contains("contact dashpot")),
                "{plan:?}"
            ),
            (true, _) => assert!(plan.is_ok(), "{method:?}"),
            (false, _) => assert!(
                matches!(plan, Err(SimError::VelocityForces { .. })),
                "{method:?}"
            ),
        }
    }
    let names: Vec<&str> = Method::with_velocity_forces().map(Method::name).collect();
    assert_eq!(names, ["rk4", "rk4-contact", "dop853", "rkn6-split"]);
}

#[test]
fn zero_damping_and_a_spring_only_end_keep_the_conservative_path() {
    let none = Model::new(30, Boundary::Fixed, vec![])
        .unwrap()
        .with_damping(damping(0.0, DashpotLaw::Hertzian, 0.0, vec![]))
        .unwrap();
    assert!(!none.is_dissipative());
    let plain = Model::new(30, Boundary::Fixed, vec![]).unwrap();
    let a = run(&scene(none, 3, (14, 16), 30.0, tolerance(1e-7)));
    let b = run(&scene(plain, 3, (14, 16), 30.0, tolerance(1e-7)));
    assert_eq!(a.fractions, b.fractions);
    assert_eq!(a.plan.method, Method::Rkn6Contact);
    // A single site on a spring-only soft end oscillates at sqrt(k / m), conserving energy.
    let (k, m): (f64, f64) = (0.7, 2.0);
    let spring = End::Soft {
        spring: k,
        damping: 0.0,
    };
    let model =
        Model::with_masses(1, Boundary::ends(End::Free, spring), vec![], Some(vec![m])).unwrap();
    assert!(!model.is_dissipative());
    let omega = (k / m).sqrt();
    let out = run_with_plan(
        &scene(model.clone(), 0, (0, 0), 9.0, tolerance(1e-10)),
        &Plan::choose(
            &model,
            MethodChoice::Named(Method::Dop853),
            tolerance(1e-10),
        )
        .unwrap(),
        &mut (),
        true,
    )
    .unwrap();
    let expected = (omega * 9.0).sin() / omega;
    assert!((out.final_state[0] - expected).abs() < 1e-9);
}

/// Both ends soft, each with a dashpot: the power of both enters D (the force kernel sums the
/// soft ends' power apart from the bonds'), so the ledger closes, and the chain with both
/// dashpots has lost more than the same chain with the left one alone.
#[test]
fn two_damped_soft_ends_both_enter_the_ledger() {
    let soft = |damping| End::Soft {
        spring: 0.05,
        damping,
    };
    let dissipated = |right: f64| {
        let model = Model::new(21, Boundary::ends(soft(0.4), soft(right)), vec![]).unwrap();
        let scenario = scene(model, 1, (9, 11), 80.0, tolerance(1e-10));
        let out = run(&scenario);
        let f = out.fractions;
        assert!(
            (f.sum() - 1.0).abs() <= 1e-9,
            "right {right}: {}",
            f.sum() - 1.0
        );
        assert!(out.stats.max_energy_drift <= 1e-9, "right {right}");
        f.dissipated
    };
    let (left_only, both) = (dissipated(0.0), dissipated(0.4));
    assert!(left_only > 0.0, "D = {left_only}");
    assert!(
        both > left_only + 0.05,
        "both {both}, left alone {left_only}"
    );
}
