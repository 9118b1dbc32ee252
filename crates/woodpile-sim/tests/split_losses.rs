//! `rkn6-split`: losses that act on velocities alone (ground damping, resonator dashpots, soft
//! ends' dashpots) integrated exactly around the conservative `rkn6-contact` step. Its order,
//! `auto`'s choice of it and its promise, its refusals, and its identity with `rkn6-contact`
//! where nothing is lost.
#![allow(clippy::unwrap_used)]

use woodpile_sim::energy::Region;
use woodpile_sim::integrate::{Accuracy, Method, MethodChoice, Plan};
use woodpile_sim::model::{Boundary, End, Model, Resonator};
use woodpile_sim::simulation::{simulate, Outcome, Scenario};
use woodpile_sim::testing::{fitted_order, fixed_dt, tolerance};
use woodpile_sim::{Damping, DashpotLaw, SimError};

/// 41 sites struck at site 2, a resonator (ε = 0.5) with a dashpot at site 20, ground damping
/// and a soft right end whose dashpot is `soft`; a contact dashpot `contact`.
fn chain(soft: f64, contact: f64) -> Model {
    let right = End::Soft {
        spring: 0.05,
        damping: soft,
    };
    Model::new(
        41,
        Boundary::ends(End::Free, right),
        vec![Resonator::constant(20, 0.5, 1.0, 1)],
    )
    .unwrap()
    .with_damping(Damping::new(contact, DashpotLaw::Linear, 0.002, vec![0.05]).unwrap())
    .unwrap()
}

fn scene(model: Model, method: MethodChoice, accuracy: Accuracy) -> Scenario {
    Scenario {
        model,
        impulse_site: 2,
        impulse_velocity: 1.0,
        t_end: 40.0,
        region: Region::new(19, 21, 41).unwrap(),
        method,
        accuracy,
        sample_every: 1.0,
    }
}

fn run(model: Model, method: Method, dt: f64) -> Outcome {
    simulate(
        &scene(model, MethodChoice::Named(method), fixed_dt(dt)),
        &mut (),
    )
    .unwrap()
}

/// `rk4-contact` at a step 40 times below the split's finest: shares no step with it.
fn reference(model: Model) -> Outcome {
    run(model, Method::Rk4Contact, 0.00025)
}

#[test]
fn the_split_converges_at_order_two_and_keeps_the_ledger() {
    let model = chain(0.3, 0.0);
    let reference = reference(model.clone()).fractions;
    let dts = [0.04, 0.02, 0.01];
    let runs: Vec<Outcome> = dts
        .iter()
        .map(|&dt| run(model.clone(), Method::Rkn6Split, dt))
        .collect();
    let errors: Vec<f64> = runs
        .iter()
        .map(|o| o.fractions.largest_difference(&reference))
        .collect();
    let order = fitted_order(&dts, &errors);
    assert!(
        (1.7..2.6).contains(&order),
        "order {order}, errors {errors:?}"
    );
    assert!(errors[2] < 1e-7, "{errors:?}");
    let finest = &runs[2].fractions;
    assert!(finest.dissipated > 0.05, "D = {}", finest.dissipated);
    assert!(
        (finest.sum() - 1.0).abs() < 1e-8,
        "ledger {}",
        finest.sum() - 1.0
    );
}

/// Two dashpots on one host do not commute: the second half-step must undo the first's order,
/// or the method falls to order 1 (3.3, 2.9, 2.6 times per halving in a model of one host).
#[test]
fn two_damped_resonators_on_one_host_keep_order_two() {
    let model = Model::new(
        41,
        Boundary::Fixed,
        vec![
            Resonator::constant(20, 0.5, 1.0, 1),
            Resonator::constant(20, 0.3, 2.0, 1),
        ],
    )
    .unwrap()
    .with_damping(Damping::new(0.0, DashpotLaw::Linear, 0.0, vec![0.2, 0.3]).unwrap())
    .unwrap();
    // The state, not the shares: the order-1 term rotates velocities and barely moves energy.
    let reference = reference(model.clone()).final_state;
    let dts = [0.02, 0.01, 0.005, 0.0025];
    let errors: Vec<f64> = dts
        .iter()
        .map(|&dt| {
            let state = run(model.clone(), Method::Rkn6Split, dt).final_state;
            state
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .collect();
    // Order 2 to the finest step: the order-1 term shows there as a fall below 3.5.
    for pair in errors.windows(2) {
        let fall = pair[0] / pair[1];
        assert!((3.5..4.6).contains(&fall), "falls {errors:?}");
    }
}

#[test]
fn auto_splits_slow_linear_losses_and_meets_its_tolerance() {
    let model = chain(0.3, 0.0);
    let reference = reference(model.clone()).fractions;
    for tol in [1e-6, 1e-8] {
        let out = simulate(
            &scene(model.clone(), MethodChoice::Auto, tolerance(tol)),
            &mut (),
        )
        .unwrap();
        assert_eq!(out.plan.method, Method::Rkn6Split);
        let error = out.fractions.largest_difference(&reference);
        assert!(error <= tol, "at {tol}: error {error}");
    }
}

#[test]
fn auto_keeps_rk4_contact_for_a_contact_dashpot_or_fast_losses() {
    let choose = |model: &Model| {
        Plan::choose(model, MethodChoice::Auto, tolerance(1e-6))
            .unwrap()
            .method
    };
    assert_eq!(choose(&chain(0.3, 0.0)), Method::Rkn6Split);
    assert_eq!(choose(&chain(0.3, 0.01)), Method::Rk4Contact);
    // A soft end's dashpot of 5 on a unit mass damps at rate 5, beyond what is split.
    assert_eq!(choose(&chain(5.0, 0.0)), Method::Rk4Contact);
}

#[test]
fn the_split_by_name_refuses_a_contact_dashpot() {
    let plan = Plan::choose(
        &chain(0.3, 0.01),
        MethodChoice::Named(Method::Rkn6Split),
        fixed_dt(0.01),
    );
    assert!(
        matches!(&plan, Err(SimError::BadRun(why)) if why.contains("contact dashpot")),
        "{plan:?}"
    );
}

#[test]
fn without_losses_the_split_is_rkn6_contact_bit_for_bit() {
    let model = Model::new(
        41,
        Boundary::Fixed,
        vec![Resonator::constant(20, 0.5, 1.0, 1)],
    )
    .unwrap();
    let split = run(model.clone(), Method::Rkn6Split, 0.02);
    let plain = run(model, Method::Rkn6Contact, 0.02);
    assert_eq!(split.fractions, plain.fractions);
    assert_eq!(split.final_state, plain.final_state);
}
