//! Exact answers: the linear host–resonator oscillator and the two-bead Hertz collision.
//! Convergence orders on the smooth oscillator are the classical ones; on the Hertzian chain they
//! are not (see `chain_accuracy.rs`).
#![allow(clippy::unwrap_used)]

use woodpile_sim::energy::{total_energy, total_momentum};
use woodpile_sim::integrate::{
    drive, ContactMode, Dop853, DriveConfig, ExplicitRk, Rk4, Rkn, Rkn4, StepControl, StepSpan,
    Stepper, SymplecticStepper, DPRKN6, VERLET, YOSHIDA4, YOSHIDA6,
};
use woodpile_sim::model::{Model, Window};
use woodpile_sim::testing::{fitted_order, linear_oscillator, two_bead_collision};

fn fixed(t_end: f64, dt: f64) -> DriveConfig {
    DriveConfig {
        t_end,
        sample_every: t_end,
        control: StepControl::Fixed { dt },
        max_steps: 10_000_000,
        energy_drift_limit: None,
        active_window: true,
    }
}

fn fixed_steppers(model: &Model) -> Vec<(Box<dyn Stepper>, f64)> {
    vec![
        (Box::new(ExplicitRk::<Rk4>::new(model)), 4.0),
        (Box::new(Rkn4::new(model)), 4.0),
        (Box::new(Rkn::new(model, DPRKN6, ContactMode::Plain)), 6.0),
        (
            Box::new(Rkn::new(model, DPRKN6, ContactMode::Corrected)),
            6.0,
        ),
        (Box::new(SymplecticStepper::new(model, VERLET)), 2.0),
        (Box::new(SymplecticStepper::new(model, YOSHIDA4)), 4.0),
        (Box::new(SymplecticStepper::new(model, YOSHIDA6)), 6.0),
    ]
}

/// The relative coordinate v - u of a host–resonator pair oscillates as x0 cos(omega t),
/// omega^2 = kappa (1 + 1/eps): each fixed-step method converges to it at its classical order.
#[test]
fn linear_oscillator_convergence_orders_are_classical() {
    let (model, y0, omega) = linear_oscillator(0.5, 2.0, 0.1);
    let t_end = 10.0;
    let exact = 0.1 * (omega * t_end).cos();
    let n = fixed_steppers(&model).len();
    for i in 0..n {
        let dts = [0.1, 0.05, 0.025, 0.0125];
        let mut errs = Vec::new();
        let mut name = "";
        for &dt in &dts {
            let mut stepper = fixed_steppers(&model).swap_remove(i).0;
            let mut y = y0.clone();
            drive(&model, stepper.as_mut(), &mut y, &fixed(t_end, dt), &mut ()).unwrap();
            errs.push((y[1] - y[0] - exact).abs().max(1e-300));
            name = stepper.name();
        }
        let order = fixed_steppers(&model)[i].1;
        let p = fitted_order(&dts, &errs);
        assert!(
            (p - order).abs() < 0.3,
            "{name}: measured order {p:.2}, classical {order}; errors {errs:?}"
        );
    }
}

/// DOP853 reaches the oscillator's exact solution to about its tolerance.
#[test]
fn dop853_meets_its_tolerance_on_the_oscillator() {
    let (model, y0, omega) = linear_oscillator(0.5, 2.0, 0.1);
    let t_end = 10.0;
    let exact = 0.1 * (omega * t_end).cos();
    for rtol in [1e-6, 1e-9, 1e-12] {
        let mut y = y0.clone();
        let cfg = DriveConfig {
            control: StepControl::Adaptive { h_min: 1e-12 },
            ..fixed(t_end, 1.0)
        };
        let stats = drive(
            &model,
            &mut Dop853::new(&model, rtol, rtol),
            &mut y,
            &cfg,
            &mut (),
        )
        .unwrap();
        let err = (y[1] - y[0] - exact).abs();
        assert!(err < 100.0 * rtol, "rtol {rtol}: error {err:.3e}");
        assert!(stats.steps > 0);
    }
}

/// The resonator's linear frequency: the simulated period of u - v matches 2 pi / omega.
#[test]
fn resonator_linear_frequency() {
    let (model, mut y, omega) = linear_oscillator(10.0, 1.0, 0.1);
    let dt = 1e-3;
    let mut stepper = SymplecticStepper::new(&model, YOSHIDA4);
    let mut crossings = Vec::new();
    let mut t = 0.0;
    let mut prev = y[0] - y[1];
    while crossings.len() < 5 {
        stepper.step(
            &model,
            &mut y,
            StepSpan {
                t,
                h: dt,
                window: Window::full(&model),
            },
        );
        t += dt;
        let x = y[0] - y[1];
        if prev.signum() != x.signum() {
            crossings.push(t - dt * x / (x - prev)); // linear interpolation of the zero
        }
        prev = x;
    }
    let period = (crossings[4] - crossings[0]) / 2.0;
    let expected = 2.0 * std::f64::consts::PI / omega;
    assert!(
        (period / expected - 1.0).abs() < 1e-6,
        "period {period} vs {expected}"
    );
}

/// Two equal free beads: the Hertz collision exchanges their velocities exactly, conserving
/// energy and momentum.
#[test]
fn two_bead_collision_swaps_velocities() {
    let (model, y0) = two_bead_collision();
    let e0 = total_energy(&model, 0.0, &y0);
    let p0 = total_momentum(&model, &y0);
    for (mut stepper, _) in fixed_steppers(&model) {
        let mut y = y0.clone();
        drive(
            &model,
            stepper.as_mut(),
            &mut y,
            &fixed(20.0, 0.001),
            &mut (),
        )
        .unwrap();
        let name = stepper.name();
        assert!(y[2].abs() < 1e-6, "{name}: first bead keeps {}", y[2]);
        assert!(
            (y[3] - 1.0).abs() < 1e-6,
            "{name}: second bead gets {}",
            y[3]
        );
        let de = (total_energy(&model, 20.0, &y) - e0).abs();
        eprintln!("{name}: energy error after the collision {de:.2e}");
        assert!(de < 1e-8, "{name}: energy error {de:.3e}");
        assert!(
            (total_momentum(&model, &y) - p0).abs() < 1e-12,
            "{name}: momentum"
        );
    }
}
