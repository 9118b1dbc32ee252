//! Accuracy on the Hertzian chain itself, against tighter references computed here.
//!
//! The contact force [d]_+^{3/2} has a singular second derivative where a contact opens or
//! closes, so the velocity's local error on a step containing that instant is O(h^{5/2}) for any
//! method built on polynomials. Measured orders are therefore about 2.5 for RK4 and the order-4
//! and order-6 compositions, and 2 for Verlet, which is what these tests assert.
#![allow(clippy::unwrap_used)]

use woodpile_sim::energy::{energy_density, Fractions, Region};
use woodpile_sim::integrate::{
    drive, Accuracy, ContactMode, DriveConfig, ExplicitRk, Method, MethodChoice, Plan, Rk4, Rkn,
    Rkn4, StepControl, Stepper, SymplecticStepper, DPRKN6, VERLET,
};
use woodpile_sim::model::{Boundary, Model, Resonator};
use woodpile_sim::testing::fitted_order;
use woodpile_sim::SimError;

/// A short chain (sites -20..20), defect eps = 3 at 0, impulse at -8, t in [0, 40]: the wave
/// crosses the defect and splits, with every kind of contact event, in a test-sized run.
fn short_scene() -> (Model, Vec<f64>, Region) {
    let res = vec![Resonator::constant(20, 3.0, 1.0, 1)];
    let model = Model::new(41, Boundary::Fixed, res).unwrap();
    let mut y = model.rest_state();
    model.apply_impulse(&mut y, 12, 1.0).unwrap();
    (model, y, Region::new(19, 21, 41).unwrap())
}

const T_END: f64 = 40.0;

fn trapped(model: &Model, y: &[f64], region: Region) -> f64 {
    let mut e = vec![0.0; model.n_sites()];
    energy_density(model, T_END, y, &mut e);
    Fractions::from_density(&e, region).trapped
}

fn run(stepper: &mut dyn Stepper, control: StepControl) -> (f64, f64) {
    let (e, drift, _) = run_state(stepper, control);
    (e, drift)
}

fn run_state(stepper: &mut dyn Stepper, control: StepControl) -> (f64, f64, Vec<f64>) {
    let (model, mut y, region) = short_scene();
    let cfg = DriveConfig {
        t_end: T_END,
        sample_every: 1.0,
        control,
        max_steps: 10_000_000,
        energy_drift_limit: None,
        active_window: true,
    };
    let stats = drive(&model, stepper, &mut y, &cfg, &mut ()).unwrap();
    (trapped(&model, &y, region), stats.max_energy_drift, y)
}

/// The product's stepper for `method` (DOP853 at 1e-14), except plain `rk4`: the generic
/// tableau, so the fused stepper the product runs is checked against it.
fn stepper(method: Method, model: &Model) -> Box<dyn Stepper> {
    if method == Method::Rk4 {
        return Box::new(ExplicitRk::<Rk4>::new(model));
    }
    let plan = Plan {
        method,
        control: StepControl::Adaptive { h_min: 0.0 },
        rtol: 1e-14,
        atol: 1e-14,
        drift_limit: f64::INFINITY,
    };
    plan.stepper(model)
}

/// The tight reference: Yoshida-6 at dt = 5e-4 (its own error, judged by halving, is < 1e-11).
fn reference() -> f64 {
    let (model, ..) = short_scene();
    run(
        stepper(Method::Yoshida6, &model).as_mut(),
        StepControl::Fixed { dt: 5e-4 },
    )
    .0
}

/// The max-norm error at t_end of the short scene's state for (method, dt), against a Yoshida-6
/// run at dt = 5e-4 (made once).
fn state_error_against_tight_run() -> impl Fn(Method, f64) -> f64 {
    let (model, ..) = short_scene();
    let reference = run_state(
        stepper(Method::Yoshida6, &model).as_mut(),
        StepControl::Fixed { dt: 5e-4 },
    )
    .2;
    move |method, dt| {
        let y = run_state(stepper(method, &model).as_mut(), StepControl::Fixed { dt }).2;
        y.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    }
}

/// Measured convergence orders of the state (max-norm error at t_end against a Yoshida-6 run at
/// dt = 5e-4) on the chain: Verlet 2; RK4 and the compositions between 2 and 3, well below their
/// classical 4 and 6, because of the contact singularity. `rk4-contact`, which integrates each
/// opening or closing contact along its path, recovers order 3.3 (between 3 and 4.2 asserted),
/// `rkn4-contact`, the three-stage Nyström method with the same correction, measures 2.8 (slopes
/// 2.9, 2.7, 3.0): its errors are 2.4 times smaller than `rk4-contact`'s at dt = 0.08 and equal
/// at 0.01, with three force evaluations per step instead of four.
/// `rkn6-contact` (order 6 between contact events) measures 1.95: its errors are 200 times
/// smaller than `rk4-contact`'s at dt = 0.08 and 15 times at 0.01, where what is left is the
/// steps just after a contact closes, whose force (t - t*)^{3/2} no polynomial method
/// integrates at more than order 2.5 (next test).
/// A single scalar such as E_tr converges too irregularly (kink errors of either sign partly cancel) to fit a slope to.
#[test]
fn convergence_orders_on_the_hertz_chain() {
    let error = state_error_against_tight_run();
    let dts = [0.08, 0.04, 0.02, 0.01];
    for (method, lo, hi) in [
        (Method::Verlet, 1.8, 2.3),
        (Method::Rk4, 2.0, 3.2),
        (Method::Yoshida4, 2.0, 3.2),
        (Method::Yoshida6, 2.0, 3.2),
        (Method::Rk4Contact, 3.0, 4.2),
        (Method::Rkn4Contact, 2.6, 4.2),
        (Method::Rkn6Contact, 1.5, 3.5),
        (Method::Erkn6Contact, 1.5, 3.5),
    ] {
        let errs: Vec<f64> = dts.iter().map(|&dt| error(method, dt)).collect();
        let p = fitted_order(&dts, &errs);
        eprintln!("{}: measured order {p:.2} (errors {errs:?})", method.name());
        assert!(
            p > lo && p < hi,
            "{}: order {p:.2} outside [{lo}, {hi}]; errors {errs:?}",
            method.name()
        );
    }
}

/// Each refinement is worth its cost, at every step of the convergence test:
/// - the contact-event correction: `rk4-contact`'s state error is at least 5 times smaller
///   than plain RK4's;
/// - the sixth-order Nyström method with contact events (six force evaluations a step):
///   its error is at least 10 times smaller than `rk4-contact`'s (four a step), so it reaches
///   a given error at a step several times larger.
#[test]
fn each_refinement_beats_the_method_it_refines_at_every_step() {
    let error = state_error_against_tight_run();
    let refinements: [(Method, Method, f64, &[f64]); 2] = [
        (Method::Rk4Contact, Method::Rk4, 5.0, &[0.08, 0.04, 0.02]),
        (
            Method::Rkn6Contact,
            Method::Rk4Contact,
            10.0,
            &[0.08, 0.04, 0.02, 0.01],
        ),
    ];
    for (better, base, factor, steps) in refinements {
        for &dt in steps {
            let (ours, theirs) = (error(better, dt), error(base, dt));
            assert!(
                ours * factor < theirs,
                "dt = {dt}: {} {ours:.2e}, {} {theirs:.2e}",
                better.name(),
                base.name()
            );
        }
    }
}

/// Every method agrees with the tight reference at a tight setting, and DOP853 at tight
/// tolerance agrees with the composition reference (two independent methods).
#[test]
fn every_method_agrees_with_the_reference_at_tight_settings() {
    let reference = reference();
    let (model, ..) = short_scene();
    for method in Method::ALL {
        let control = if method.is_adaptive() {
            StepControl::Adaptive { h_min: 1e-13 }
        } else {
            StepControl::Fixed {
                dt: if method == Method::Verlet { 2e-4 } else { 2e-3 },
            }
        };
        let e = run(stepper(method, &model).as_mut(), control).0;
        let bound = if method == Method::Verlet { 1e-8 } else { 1e-9 };
        assert!(
            (e - reference).abs() < bound,
            "{}: {:.3e}",
            method.name(),
            (e - reference).abs()
        );
    }
}

/// Energy conservation with stated bounds at dt = 0.01 (max relative drift over the samples).
/// The symplectic methods' error is bounded, not secular: doubling the horizon leaves it alike.
#[test]
fn energy_is_conserved_within_stated_bounds() {
    let (model, ..) = short_scene();
    for (method, bound) in [
        (Method::Rk4, 1e-6),
        (Method::Verlet, 1e-4),
        (Method::Yoshida4, 1e-5),
        (Method::Yoshida6, 1e-6),
    ] {
        let (_, drift) = run(
            stepper(method, &model).as_mut(),
            StepControl::Fixed { dt: 0.01 },
        );
        assert!(
            drift < bound && drift > 0.0,
            "{}: drift {drift:.3e}",
            method.name()
        );
    }
    let (model, y0, _) = short_scene();
    let drift_until = |t_end: f64| {
        let mut y = y0.clone();
        let cfg = DriveConfig {
            t_end,
            sample_every: 1.0,
            control: StepControl::Fixed { dt: 0.02 },
            max_steps: 10_000_000,
            energy_drift_limit: None,
            active_window: true,
        };
        drive(
            &model,
            &mut SymplecticStepper::new(&model, VERLET),
            &mut y,
            &cfg,
            &mut (),
        )
        .unwrap()
        .max_energy_drift
    };
    let (short, long) = (drift_until(200.0), drift_until(400.0));
    assert!(
        long < 1.5 * short,
        "Verlet drift grows: {short:.3e} -> {long:.3e}"
    );
}

/// Failures are errors, never numbers: a step far beyond stability is reported with its time.
#[test]
fn blow_up_is_an_error() {
    let res = vec![Resonator::constant(20, 1e-3, 1.0, 1)];
    let model = Model::new(41, Boundary::Fixed, res).unwrap();
    let mut y = model.rest_state();
    model.apply_impulse(&mut y, 12, 1.0).unwrap();
    let cfg = DriveConfig {
        t_end: T_END,
        sample_every: 1.0,
        control: StepControl::Fixed { dt: 0.5 },
        max_steps: 1_000_000,
        energy_drift_limit: Some(1e-3),
        active_window: true,
    };
    let err = drive(
        &model,
        &mut ExplicitRk::<Rk4>::new(&model),
        &mut y,
        &cfg,
        &mut (),
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            SimError::NonFinite { .. } | SimError::EnergyDrift { .. }
        ),
        "{err:?}"
    );
}

/// The plan never hands a fixed-step method a step beyond its linear stability bound.
#[test]
fn tolerance_driven_steps_respect_the_stability_bound() {
    for eps in [1e-4, 1e-2, 1.0] {
        let res = vec![Resonator::constant(0, eps, 1.0, 1)];
        let model = Model::new(3, Boundary::Fixed, res).unwrap();
        for method in [
            Method::Rk4,
            Method::Verlet,
            Method::Yoshida4,
            Method::Yoshida6,
        ] {
            let acc = Accuracy {
                tolerance: 1e-3,
                tolerance_explicit: true,
                dt: None,
            };
            let plan = Plan::choose(&model, MethodChoice::Named(method), acc).unwrap();
            let dt = plan.dt().unwrap();
            assert!(
                dt * model.max_linear_omega(false) < method.stability_limit(),
                "{} eps {eps}: dt {dt}",
                method.name()
            );
        }
    }
}

/// Free ends conserve momentum along the whole chain run.
#[test]
fn free_chain_conserves_momentum() {
    let res = vec![Resonator::constant(20, 3.0, 1.0, 3)];
    let model = Model::new(41, Boundary::Free, res).unwrap();
    let mut y = model.rest_state();
    model.apply_impulse(&mut y, 12, 1.0).unwrap();
    let p0 = woodpile_sim::energy::total_momentum(&model, &y);
    let cfg = DriveConfig {
        t_end: 60.0,
        sample_every: 1.0,
        control: StepControl::Fixed { dt: 0.01 },
        max_steps: 1_000_000,
        energy_drift_limit: Some(1e-5),
        active_window: true,
    };
    drive(
        &model,
        &mut ExplicitRk::<Rk4>::new(&model),
        &mut y,
        &cfg,
        &mut (),
    )
    .unwrap();
    assert!((woodpile_sim::energy::total_momentum(&model, &y) - p0).abs() < 1e-12);
}

/// The tableau stepper with Nyström's tableau is the hand-written `rkn4-contact` (the same
/// arithmetic in another order: equal to 1e-12), so the comparison of contact treatments in
/// `error_split` compares treatments, not implementations.
#[test]
fn the_tableau_stepper_reproduces_rkn4_contact() {
    use woodpile_sim::integrate::NYSTROM4;
    let (model, ..) = short_scene();
    let control = StepControl::Fixed { dt: 0.05 };
    let hand = run_state(&mut Rkn4::with_contact_events(&model), control).2;
    let tableau = run_state(
        &mut Rkn::new(&model, NYSTROM4, ContactMode::Corrected),
        control,
    )
    .2;
    let largest = hand
        .iter()
        .zip(&tableau)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(largest < 1e-12, "{largest:e}");
}

/// Located steps end where contacts open or close: on the chain a step of 0.05 is cut short
/// many times, and the result still converges to the reference.
#[test]
fn located_steps_cut_at_contact_events_and_converge() {
    let (model, ..) = short_scene();
    let reference = run_state(
        stepper(Method::Yoshida6, &model).as_mut(),
        StepControl::Fixed { dt: 5e-4 },
    )
    .2;
    let mut located = Rkn::new(&model, DPRKN6, ContactMode::Located);
    let y = run_state(&mut located, StepControl::Fixed { dt: 0.02 }).2;
    let largest = y
        .iter()
        .zip(&reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        located.contact_events() > 100,
        "{} cuts",
        located.contact_events()
    );
    assert!(largest < 1e-6, "{largest:e}");
}
