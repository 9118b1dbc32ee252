//! No more model than a scene needs: working only on the sites the wave has reached must give
//! the full model's result bit for bit, for every method and every kind of scene, and must
//! save work where part of the chain stays at rest.
#![allow(clippy::unwrap_used)]

use woodpile_sim::energy::Region;
use woodpile_sim::integrate::{
    drive, Dop853, DriveConfig, ExplicitRk, Rk4, Rk4Fused, Rkn4, StepControl, Stepper,
    SymplecticStepper, VERLET, YOSHIDA4, YOSHIDA6,
};
use woodpile_sim::model::{Boundary, Coupling, Model, Resonator};
use woodpile_sim::observe::FractionSeries;

fn linear(site: usize, eps: f64, kappa: f64) -> Resonator {
    Resonator::constant(site, eps, kappa, 1)
}

/// Scenes covering what the window must respect: walls, free ends, two defects, a nonlinear
/// coupling, a ramp, per-site masses, and a striker next to a wall.
fn scenes() -> Vec<(&'static str, Model, usize)> {
    let n = 81; // sites -40..40
    let ramp = Resonator {
        site: 40,
        eps: 10.0,
        coupling: Coupling::Ramp {
            k1: 0.0,
            k2: 2.5,
            t0: 10.0,
            tau: 0.1,
        },
        p: 1,
    };
    let nonlinear = Resonator {
        p: 7,
        ..linear(40, 0.3, 1.0)
    };
    let mut masses = vec![1.0; n];
    masses[40] = 0.9677;
    vec![
        (
            "one defect, fixed walls",
            Model::new(n, Boundary::Fixed, vec![linear(40, 10.0, 1.0)]).unwrap(),
            30,
        ),
        (
            "one defect, free ends",
            Model::new(n, Boundary::Free, vec![linear(40, 10.0, 1.0)]).unwrap(),
            30,
        ),
        (
            "two defects",
            Model::new(
                n,
                Boundary::Fixed,
                vec![linear(40, 0.67, 1.0), linear(50, 0.54, 1.0)],
            )
            .unwrap(),
            30,
        ),
        (
            "nonlinear p = 7",
            Model::new(n, Boundary::Fixed, vec![nonlinear]).unwrap(),
            30,
        ),
        (
            "ramp",
            Model::new(n, Boundary::Fixed, vec![ramp, linear(50, 10.0, 2.5)]).unwrap(),
            30,
        ),
        (
            "site masses",
            Model::with_masses(
                n,
                Boundary::Free,
                vec![linear(40, 1.03, 0.378)],
                Some(masses),
            )
            .unwrap(),
            30,
        ),
        (
            "striker at the wall",
            Model::new(n, Boundary::Fixed, vec![linear(40, 10.0, 1.0)]).unwrap(),
            0,
        ),
    ]
}

fn steppers(model: &Model) -> Vec<(Box<dyn Stepper>, StepControl)> {
    let fixed = StepControl::Fixed { dt: 0.05 };
    vec![
        (Box::new(ExplicitRk::<Rk4>::new(model)), fixed),
        (Box::new(SymplecticStepper::new(model, VERLET)), fixed),
        (Box::new(SymplecticStepper::new(model, YOSHIDA4)), fixed),
        (Box::new(SymplecticStepper::new(model, YOSHIDA6)), fixed),
        (
            Box::new(Dop853::new(model, 1e-9, 1e-9)),
            StepControl::Adaptive { h_min: 1e-12 },
        ),
        (Box::new(Rk4Fused::new(model)), fixed),
        (Box::new(Rk4Fused::with_contact_events(model)), fixed),
        (Box::new(Rkn4::new(model)), fixed),
        (Box::new(Rkn4::with_contact_events(model)), fixed),
    ]
}

fn run(
    model: &Model,
    striker: usize,
    index: usize,
    active_window: bool,
) -> (Vec<f64>, FractionSeries, u64) {
    let mut y = model.rest_state();
    model.apply_impulse(&mut y, striker, 1.0).unwrap();
    let (mut stepper, control) = steppers(model).swap_remove(index);
    let cfg = DriveConfig {
        t_end: 60.0,
        sample_every: 2.0,
        control,
        max_steps: 10_000_000,
        energy_drift_limit: None,
        active_window,
    };
    let region = Region::new(39, 51, model.n_sites()).unwrap();
    let mut series = FractionSeries::new(model, region);
    let stats = drive(model, stepper.as_mut(), &mut y, &cfg, &mut series).unwrap();
    (y, series, stats.steps)
}

#[test]
fn the_active_window_changes_no_bit_of_the_result() {
    for (scene, model, striker) in scenes() {
        for index in 0..7 {
            let (y_window, series_window, steps_window) = run(&model, striker, index, true);
            let (y_full, series_full, steps_full) = run(&model, striker, index, false);
            let name = steppers(&model)[index].0.name();
            assert_eq!(
                steps_window, steps_full,
                "{scene}, {name}: step counts differ"
            );
            let first_difference = y_window
                .iter()
                .zip(&y_full)
                .position(|(a, b)| a.to_bits() != b.to_bits());
            assert_eq!(
                first_difference, None,
                "{scene}, {name}: final states differ"
            );
            assert_eq!(
                series_window, series_full,
                "{scene}, {name}: fraction series differ"
            );
        }
    }
}

/// The fused RK4 (the one `rk4` and `auto` run) is the tableau RK4 in another loop order: the
/// same bits.
#[test]
fn fused_rk4_is_the_tableau_rk4_bit_for_bit() {
    for (scene, model, striker) in scenes() {
        let (y_tableau, series_tableau, _) = run(&model, striker, 0, true);
        let (y_fused, series_fused, _) = run(&model, striker, 5, true);
        let first_difference = y_tableau
            .iter()
            .zip(&y_fused)
            .position(|(a, b)| a.to_bits() != b.to_bits());
        assert_eq!(first_difference, None, "{scene}: final states differ");
        assert_eq!(
            series_tableau, series_fused,
            "{scene}: fraction series differ"
        );
    }
}

/// Chain length only as large as the fractions can feel: while the wave has not reached the
/// walls of the shorter chain, a chain three times as long gives the same fraction series, bit
/// for bit, for exactly the same work (site-steps), and that work is well under the full
/// chain's. So a scene may be given a generous length at no cost.
#[test]
fn a_longer_chain_costs_nothing_until_the_wave_reaches_its_ends() {
    let run = |half: usize| {
        let n = 2 * half + 1;
        let model = Model::new(n, Boundary::Fixed, vec![linear(half, 10.0, 1.0)]).unwrap();
        let mut y = model.rest_state();
        model.apply_impulse(&mut y, half - 25, 1.0).unwrap();
        let cfg = DriveConfig {
            t_end: 50.0,
            sample_every: 1.0,
            control: StepControl::Fixed { dt: 0.05 },
            max_steps: 10_000_000,
            energy_drift_limit: None,
            active_window: true,
        };
        let region = Region::new(half as i64 - 1, half as i64 + 1, n).unwrap();
        let mut series = FractionSeries::new(&model, region);
        let mut stepper = Rk4Fused::with_contact_events(&model);
        let stats = drive(&model, &mut stepper, &mut y, &cfg, &mut series).unwrap();
        (series, stats)
    };
    let (short, short_stats) = run(100);
    let (long, long_stats) = run(300);
    for (name, a, b) in [
        ("t", &short.t, &long.t),
        ("R", &short.reflected, &long.reflected),
        ("T", &short.transmitted, &long.transmitted),
        ("E_tr", &short.trapped, &long.trapped),
        ("E", &short.energy, &long.energy),
    ] {
        assert_eq!(a, b, "{name} differs between the 201- and 601-site chains");
    }
    assert_eq!(short_stats.site_steps, long_stats.site_steps);
    let full_chain = 201 * short_stats.steps;
    assert!(
        2 * short_stats.site_steps < full_chain,
        "the window worked on {} of {full_chain} site-steps",
        short_stats.site_steps
    );
}
