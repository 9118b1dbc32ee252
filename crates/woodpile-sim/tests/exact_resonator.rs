//! Harmonic resonators integrated exactly (`erkn6-contact`): the free pair at steps no
//! ordinary method survives, light resonators on the paper's chain against a tighter
//! reference, and `auto`'s use of them.
#![allow(clippy::unwrap_used)]

use woodpile_sim::integrate::{drive, DriveConfig, Method, MethodChoice, Plan, StepControl};
use woodpile_sim::simulation::simulate;
use woodpile_sim::testing::{
    fitted_order, fixed_dt, linear_oscillator, paper_scene, tolerance, PaperDefect,
};

/// The free host–resonator pair (ε = 0.2, κ = 3, so ω = 4.24) run by `method` at step `dt` to
/// t = 10: the error of the stretch v − u against x0 cos(ω t).
fn free_pair_error(method: Method, dt: f64) -> f64 {
    let (model, mut y, omega) = linear_oscillator(0.2, 3.0, 0.1);
    let plan = Plan::choose(&model, MethodChoice::Named(method), fixed_dt(dt)).unwrap();
    let t_end = 10.0;
    let cfg = DriveConfig {
        t_end,
        sample_every: t_end,
        control: StepControl::Fixed { dt },
        max_steps: 1_000_000,
        energy_drift_limit: None,
        active_window: true,
    };
    drive(&model, plan.stepper(&model).as_mut(), &mut y, &cfg, &mut ()).unwrap();
    (y[1] - y[0] - 0.1 * (omega * t_end).cos()).abs()
}

/// The pair alone is a linear oscillator, which the extended step integrates exactly: at
/// ω dt = 0.42, 1.06 and 2.12 its stretch is right to rounding, where DPRKN6's own step is
/// 1e-9, 1e-6 and 0.1 of the amplitude off.
#[test]
fn a_free_pair_vibrates_exactly_at_any_step() {
    for dt in [0.1, 0.25, 0.5] {
        let exact = free_pair_error(Method::Erkn6Contact, dt);
        let plain = free_pair_error(Method::Rkn6Contact, dt);
        assert!(exact < 1e-14, "dt = {dt}: erkn6 off by {exact:e}");
        assert!(
            plain > 1e4 * exact.max(1e-16),
            "dt = {dt}: rkn6 off by only {plain:e}"
        );
    }
}

/// The largest error of R, T and E_tr at t = 150 on F7's chain with two light resonators
/// (ε = 0.3 at 0 and 20, ω = 2.08) for `method` at `dt`, against `rkn6-contact` at 0.005.
fn light_pair_errors(method: Method, dts: &[f64]) -> Vec<f64> {
    let defects = [
        PaperDefect::linear(0, 0.3, 1.0),
        PaperDefect::linear(20, 0.3, 1.0),
    ];
    let scene = |method, dt| paper_scene(&defects, MethodChoice::Named(method), fixed_dt(dt));
    let reference = simulate(&scene(Method::Rkn6Contact, 0.005), &mut ())
        .unwrap()
        .fractions;
    dts.iter()
        .map(|&dt| {
            let out = simulate(&scene(method, dt), &mut ()).unwrap();
            out.fractions.largest_difference(&reference)
        })
        .collect()
}

/// On F7's light resonators the extended step converges (order above 3 from dt = 0.43 to 0.11;
/// measured 4.4) and its coarse run, where `auto`'s first pair starts, is at least 4 times
/// closer than `rkn6-contact`'s (measured 8).
#[test]
fn light_resonators_converge_and_beat_the_plain_step_where_auto_starts() {
    let dts = [0.43, 0.215, 0.108];
    let exact = light_pair_errors(Method::Erkn6Contact, &dts);
    let plain = light_pair_errors(Method::Rkn6Contact, &dts[..1]);
    let order = fitted_order(&dts, &exact);
    assert!(order > 3.0, "order {order:.2}; errors {exact:?}");
    assert!(
        4.0 * exact[0] < plain[0],
        "dt = 0.43: erkn6 {:.1e}, rkn6 {:.1e}",
        exact[0],
        plain[0]
    );
}

/// `auto` takes the extended step where a harmonic resonator is too fast for the plain one at
/// the tolerance's step, and the plain one otherwise: F7's light pair at 1e-5 is accepted from
/// its first pair at the calibrated step (0.215, no longer capped by ω dt ≤ 0.5) and is within
/// the tolerance of a tight run; a heavy resonator, or a nonlinear one, keeps `rkn6-contact`.
#[test]
fn auto_integrates_harmonic_resonators_exactly() {
    let defects = [
        PaperDefect::linear(0, 0.3, 1.0),
        PaperDefect::linear(20, 0.3, 1.0),
    ];
    let scene = paper_scene(&defects, MethodChoice::Auto, tolerance(1e-5));
    let out = simulate(&scene, &mut ()).unwrap();
    assert_eq!(out.plan.method, Method::Erkn6Contact);
    assert!(out.plan.dt().unwrap() > 0.2, "dt {:?}", out.plan.dt());
    let tight = paper_scene(
        &defects,
        MethodChoice::Named(Method::Rkn6Contact),
        fixed_dt(0.005),
    );
    let reference = simulate(&tight, &mut ()).unwrap().fractions;
    assert!(out.fractions.largest_difference(&reference) <= 1e-5);

    for defect in [
        PaperDefect::with_exponent(0, 0.3, 1.0, 3),
        PaperDefect::linear(0, 10.0, 1.0),
    ] {
        let plain = paper_scene(&[defect], MethodChoice::Auto, tolerance(1e-5));
        let plan = Plan::choose(&plain.model, plain.method, plain.accuracy).unwrap();
        assert_eq!(plan.method, Method::Rkn6Contact, "{defect:?}");
    }
}
