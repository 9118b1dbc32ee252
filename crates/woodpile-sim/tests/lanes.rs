//! Scenes in lanes: four runs stepped together must each equal their scene's scalar run bit
//! for bit (fractions, final state, statistics, samples, and failures), whatever the lanes
//! differ in: resonator masses and couplings, impulses, windows, wall bounces, a lane that
//! blows up.
#![allow(clippy::unwrap_used)]

use woodpile_sim::energy::Region;
use woodpile_sim::integrate::lanes::{drive_lanes, shares_a_chain, LANES};
use woodpile_sim::integrate::{
    drive, DriveConfig, Method, MethodChoice, Observer, Plan, StepControl, BLOW_UP_DRIFT,
};
use woodpile_sim::model::{Boundary, End, Model, Resonator};
use woodpile_sim::observe::FractionSeries;
use woodpile_sim::simulation::{auto_first_step, Scenario};
use woodpile_sim::testing::{
    by_lanes_and_alone, fixed_dt, lane_neighbours, paper_scene, tolerance, PaperDefect,
    THIRD_RUN_POINTS,
};
use woodpile_sim::SimError;

/// F7's chain (defects at 0 and 20) with the resonator masses `eps`, at tolerance 1e-5.
fn f7_scene((eps1, eps2): (f64, f64)) -> Scenario {
    let defects = [
        PaperDefect::linear(0, eps1, 1.0),
        PaperDefect::linear(20, eps2, 1.0),
    ];
    paper_scene(&defects, MethodChoice::Auto, tolerance(1e-5))
}

/// Each scene's outcome and recorded samples, by `simulate_batch` and by `simulate` alone.
fn batched_and_alone(scenes: &[Scenario]) {
    for (k, (lanes, alone)) in by_lanes_and_alone(scenes).into_iter().enumerate() {
        assert_eq!(lanes.0, alone.0, "scene {k}: outcome");
        assert_eq!(lanes.1, alone.1, "scene {k}: samples");
    }
}

/// The method and first step `auto` plans for each of `scenes`.
fn first_steps(scenes: &[Scenario]) -> Vec<(Method, f64)> {
    let plan = |s: &Scenario| Plan::choose(&s.model, s.method, s.accuracy).unwrap();
    scenes
        .iter()
        .map(|s| (plan(s).method, auto_first_step(s, &plan(s))))
        .collect()
}

/// The first four of `scenes` plan `method` at one first step, as a lane group must.
fn assert_first_group_plans_alike(scenes: &[Scenario], method: Method) {
    let first = first_steps(&scenes[..LANES]);
    assert!(
        first.iter().all(|&f| f == (method, first[0].1)),
        "{first:?}"
    );
}

/// Eight F7 fine points (light resonators, run by `erkn6-contact`) in two lane groups, each
/// equal to its scalar `auto` run: the exact pair steps and their fast-mode corrections per
/// lane.
#[test]
fn light_resonators_in_lanes_equal_their_scalar_runs() {
    let eps = [
        (0.1, 0.3),
        (0.3, 0.3),
        (0.72, 0.62),
        (1.0, 0.2),
        (0.5, 0.9),
        (0.15, 0.15),
        (0.8, 0.4),
        (0.25, 1.0),
    ];
    let scenes: Vec<Scenario> = eps.iter().map(|&e| f7_scene(e)).collect();
    assert_first_group_plans_alike(&scenes, Method::Erkn6Contact);
    batched_and_alone(&scenes);
}

/// Ladders that need a later rung wait for three others at its step, across the batch's
/// groups of four, and make that rung's run in lanes: eight F7 fine points in two first-pair
/// groups, five of which need a third run, each equal to its scalar `auto` run.
#[test]
fn later_rungs_pooled_across_groups_equal_their_scalar_runs() {
    let scenes: Vec<Scenario> = THIRD_RUN_POINTS.into_iter().map(f7_scene).collect();
    let first = first_steps(&scenes);
    let mut later_rungs = 0;
    for (k, (lanes, alone)) in by_lanes_and_alone(&scenes).into_iter().enumerate() {
        assert_eq!(lanes.0, alone.0, "scene {k}: outcome");
        assert_eq!(lanes.1, alone.1, "scene {k}: samples");
        if alone.0.unwrap().stats.max_step < 0.75 * first[k].1 {
            later_rungs += 1;
        }
    }
    assert_eq!(later_rungs, 5, "the scenes that needed a third run");
}

/// Nine F7 points (two groups of four in lanes, the ninth alone), some passing their first
/// pair and some needing a third run, each equal to its scalar `auto` run.
#[test]
fn sweep_points_in_lanes_equal_their_scalar_runs() {
    let eps = [
        (3.0, 5.0),
        (3.0, 6.0),
        (40.0, 7.0),
        (100.0, 100.0),
        (12.0, 3.5),
        (20.0, 20.0),
        (8.0, 60.0),
        (4.5, 4.0),
        (9.0, 9.0),
    ];
    let scenes: Vec<Scenario> = eps.iter().map(|&e| f7_scene(e)).collect();
    let models: Vec<&Model> = scenes.iter().map(|s| &s.model).collect();
    assert!(shares_a_chain(&models[..LANES].try_into().unwrap()));
    // The first group takes lanes: one method and one first step.
    assert_first_group_plans_alike(&scenes, Method::Rkn6Contact);
    batched_and_alone(&scenes);
}

/// A short walled chain whose lanes start their waves at different sites and bounce them off
/// both walls many times, so that their windows differ and the walls' contacts open and close.
#[test]
fn lanes_with_other_impulses_and_wall_bounces_equal_their_scalar_runs() {
    let scene = |site: usize, velocity: f64, eps: f64| {
        let resonators = vec![Resonator::constant(7, eps, 2.0, 1)];
        let model = Model::new(15, Boundary::Fixed, resonators).unwrap();
        Scenario {
            region: Region::new(6, 8, 15).unwrap(),
            model,
            impulse_site: site,
            impulse_velocity: velocity,
            t_end: 120.0,
            method: MethodChoice::Auto,
            accuracy: tolerance(1e-6),
            sample_every: 7.0,
        }
    };
    let scenes = [
        scene(0, 1.0, 5.0),
        scene(3, -1.0, 8.0),
        scene(14, -1.0, 30.0),
        scene(10, 1.0, 12.0),
    ];
    batched_and_alone(&scenes);
    // Light resonators (`erkn6-contact`) on a longer chain, whose host some lanes' windows
    // reach late and others hold from the start.
    let long = |site: usize, velocity: f64, eps: f64| {
        let resonators = vec![Resonator::constant(30, eps, 1.0, 1)];
        Scenario {
            model: Model::new(41, Boundary::Fixed, resonators).unwrap(),
            region: Region::new(29, 31, 41).unwrap(),
            ..scene(site, velocity, eps)
        }
    };
    let light = [
        long(0, 1.0, 0.05),
        long(5, -1.0, 0.08),
        long(40, -1.0, 0.06),
        long(33, 1.0, 0.1),
    ];
    let first = first_steps(&light);
    assert!(
        first
            .iter()
            .all(|&f| f == (Method::Erkn6Contact, first[0].1)),
        "{first:?}"
    );
    batched_and_alone(&light);
}

/// Scenes that cannot share lanes (other resonator sites, a named method) run alone, with the
/// same results.
#[test]
fn scenes_that_cannot_share_lanes_run_alone() {
    let mut scenes: Vec<Scenario> = (0..4).map(|k| f7_scene((3.0 + k as f64, 5.0))).collect();
    scenes[2] = paper_scene(
        &[PaperDefect::linear(5, 4.0, 1.0)],
        MethodChoice::Auto,
        tolerance(1e-5),
    );
    let models: Vec<&Model> = scenes.iter().map(|s| &s.model).collect();
    assert!(!shares_a_chain(&models[..].try_into().unwrap()));
    batched_and_alone(&scenes);
    let mut named = scenes.clone();
    named[2] = f7_scene((9.0, 9.0));
    named[1].method = MethodChoice::Named(Method::Rkn6Contact);
    named[1].accuracy = fixed_dt(0.1);
    batched_and_alone(&named);
}

/// One lane too stiff for the step blows up and stops; the others run on, and every lane's
/// result, failure included, is its scalar run's.
#[test]
fn a_lane_that_blows_up_stops_alone() {
    let stiff = [
        PaperDefect::linear(0, 0.01, 50.0),
        PaperDefect::linear(20, 5.0, 1.0),
    ];
    let mut scenes: Vec<Scenario> = (0..4).map(|k| f7_scene((3.0 + k as f64, 5.0))).collect();
    scenes[1] = paper_scene(&stiff, MethodChoice::Auto, tolerance(1e-5));
    let plan = Plan::choose(&scenes[0].model, MethodChoice::Auto, tolerance(1e-5))
        .unwrap()
        .with_dt(0.3);
    let cfg = DriveConfig {
        t_end: 150.0,
        sample_every: 10.0,
        control: StepControl::Fixed { dt: 0.3 },
        max_steps: 1_000_000,
        energy_drift_limit: Some(BLOW_UP_DRIFT),
        active_window: true,
    };
    let start = |s: &Scenario| {
        let mut y = s.model.rest_state();
        s.model
            .apply_impulse(&mut y, s.impulse_site, s.impulse_velocity)
            .unwrap();
        y
    };
    let mut ys: [Vec<f64>; LANES] = std::array::from_fn(|l| start(&scenes[l]));
    let mut recorders: [FractionSeries; LANES] =
        std::array::from_fn(|l| FractionSeries::new(&scenes[l].model, scenes[l].region));
    let models: [&Model; LANES] = std::array::from_fn(|l| &scenes[l].model);
    let observers = recorders.each_mut().map(|o| o as &mut dyn Observer);
    let results = drive_lanes(Method::Rkn6Contact, models, &mut ys, &cfg, observers).unwrap();
    for l in 0..LANES {
        let mut y = start(&scenes[l]);
        let mut alone = FractionSeries::new(&scenes[l].model, scenes[l].region);
        let model = &scenes[l].model;
        let expected = drive(
            model,
            plan.stepper(model).as_mut(),
            &mut y,
            &cfg,
            &mut alone,
        );
        assert_eq!(results[l], expected, "lane {l}");
        if expected.is_ok() {
            assert_eq!(ys[l], y, "lane {l}: final state");
            assert_eq!(recorders[l], alone, "lane {l}: samples");
        }
    }
    assert!(
        matches!(
            results[1],
            Err(SimError::NonFinite { .. } | SimError::EnergyDrift { .. })
        ),
        "the stiff lane must fail: {:?}",
        results[1]
    );
    assert!(results.iter().filter(|r| r.is_ok()).count() == 3);
}

/// Whether four scenes take lanes together: one method and first step, one chain.
fn take_lanes(scenes: &[Scenario]) -> bool {
    let first = first_steps(scenes);
    let models: Vec<&Model> = scenes.iter().map(|s| &s.model).collect();
    let auto = scenes.iter().all(|s| s.method == MethodChoice::Auto);
    auto && first.iter().all(|&f| f == first[0]) && shares_a_chain(&models[..].try_into().unwrap())
}

/// The experiment's chain in lanes (the chain audit's scenes at tolerance 1e-5 to t = 60: an
/// exponent from 1 to 3,
/// alternating masses and contact coefficients, precompression or a striker), each lane a
/// neighbouring point, each equal to its scalar run.
#[test]
fn the_experiments_chain_in_lanes_equals_its_scalar_runs() {
    let mut rng = woodpile_sim::testing::Lcg(2026);
    let mut batched = 0;
    for k in 0..24 {
        // At the sweeps' tolerance and over a shorter run, to keep the test quick.
        let base = Scenario {
            accuracy: tolerance(1e-5),
            t_end: 60.0,
            sample_every: 5.0,
            ..woodpile_sim::testing::chain_audit_scene(&mut rng)
        };
        let scenes = lane_neighbours(&base, k);
        batched += usize::from(take_lanes(&scenes));
        batched_and_alone(&scenes);
    }
    assert!(batched >= 6, "only {batched} of 24 groups took lanes");
}

/// Soft ends (springs without dashpots) and a heavy striker's mass per lane, in lanes.
#[test]
fn soft_ends_and_site_masses_in_lanes_equal_their_scalar_runs() {
    let scene = |striker: f64, eps: f64| {
        let soft = End::Soft {
            spring: 0.05,
            damping: 0.0,
        };
        let mut masses = vec![1.0; 30];
        masses[0] = striker;
        let resonators = vec![Resonator::constant(15, eps, 1.0, 1)];
        let model =
            Model::with_masses(30, Boundary::ends(soft, soft), resonators, Some(masses)).unwrap();
        Scenario {
            region: Region::new(14, 16, 30).unwrap(),
            model,
            impulse_site: 0,
            impulse_velocity: 1.0,
            t_end: 80.0,
            method: MethodChoice::Auto,
            accuracy: tolerance(1e-6),
            sample_every: 4.0,
        }
    };
    let scenes = [
        scene(1.0, 5.0),
        scene(1.0, 6.0),
        scene(1.0, 7.0),
        scene(1.0, 8.0),
    ];
    assert!(take_lanes(&scenes));
    batched_and_alone(&scenes);
}
