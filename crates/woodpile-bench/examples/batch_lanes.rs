//! Scenes in lanes against scenes alone: F7 coarse scenes (the same chain and resonator sites,
//! their own ε1 and ε2) run by `rkn6-contact` at one fixed step, four at a time in the lanes
//! of an AVX2 register (`woodpile_sim::integrate::lanes::drive_lanes`, the path the sweeps
//! take), and one after another by the scalar stepper (itself vectorised along the chain).
//! Every lane's final state must equal its scalar run's bit for bit: checked on every batch.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example batch_lanes [-- BATCHES [DT]]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;
use woodpile_bench::drive_fixed;
use woodpile_pipeline::Pipeline;
use woodpile_sim::integrate::lanes::{drive_lanes, LANES};
use woodpile_sim::integrate::{DriveConfig, Method, MethodChoice, Observer, Plan, StepControl};
use woodpile_sim::simulation::Scenario;
use woodpile_sim::Model;
use woodpile_stages::sampling::sampled_sweep_scenes;
use woodpile_stages::KINDS;

/// Best of `passes` wall times of `work`, in ms.
fn best_ms(passes: usize, mut work: impl FnMut()) -> f64 {
    (0..passes)
        .map(|_| {
            let t0 = Instant::now();
            work();
            t0.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

/// The four scenes of `batch` run in lanes at `dt`: their final states.
fn in_lanes(batch: &[Scenario], dt: f64) -> [Vec<f64>; LANES] {
    let mut ys: [Vec<f64>; LANES] = std::array::from_fn(|l| {
        let s = &batch[l];
        let mut y = s.model.rest_state();
        s.model
            .apply_impulse(&mut y, s.impulse_site, s.impulse_velocity)
            .unwrap();
        y
    });
    let cfg = DriveConfig {
        t_end: batch[0].t_end,
        sample_every: batch[0].t_end,
        control: StepControl::Fixed { dt },
        max_steps: 100_000_000,
        energy_drift_limit: None,
        active_window: true,
    };
    let models: [&Model; LANES] = std::array::from_fn(|l| &batch[l].model);
    let mut nobody = [(); LANES];
    let observers = nobody.each_mut().map(|o| o as &mut dyn Observer);
    let results =
        drive_lanes(Method::Rkn6Contact, models, &mut ys, &cfg, observers).expect("one chain");
    for r in results {
        r.unwrap();
    }
    ys
}

/// One scene run alone by `rkn6-contact` at `dt`: its final state.
fn alone(scene: &Scenario, dt: f64) -> Vec<f64> {
    let method = MethodChoice::Named(Method::Rkn6Contact);
    let plan = Plan::choose(&scene.model, method, scene.accuracy)
        .unwrap()
        .with_dt(dt);
    let mut stepper = plan.stepper(&scene.model);
    drive_fixed(scene, stepper.as_mut(), (dt, scene.t_end), None)
        .unwrap()
        .0
}

fn main() {
    let mut args = std::env::args().skip(1);
    let batches: usize = args.next().map_or(8, |a| a.parse().unwrap());
    let dt: f64 = args.next().map_or(0.05, |a| a.parse().unwrap());
    let pipeline = Pipeline::load("pipeline".as_ref(), KINDS).unwrap();
    let scenes: Vec<Scenario> = sampled_sweep_scenes(&pipeline, LANES * batches)
        .unwrap()
        .into_iter()
        .filter(|(name, _)| name.starts_with("F7 coarse"))
        .map(|(_, s)| s)
        .collect();
    let batches: Vec<&[Scenario]> = scenes.chunks_exact(LANES).collect();
    println!(
        "{} batches of {LANES} F7 coarse scenes, rkn6-contact at dt = {dt}, one thread, best of 5\n",
        batches.len()
    );
    let (mut alone_ms, mut lanes_ms) = (0.0, 0.0);
    for batch in &batches {
        let mut batched = None;
        lanes_ms += best_ms(5, || batched = Some(in_lanes(batch, dt)));
        let mut single = Vec::new();
        alone_ms += best_ms(5, || single = batch.iter().map(|s| alone(s, dt)).collect());
        for (l, (b, s)) in batched.unwrap().iter().zip(&single).enumerate() {
            assert!(b == s, "lane {l} differs from its scalar run");
        }
    }
    let n = scenes.len() as f64;
    println!("| path | ms per scene | alone / this |");
    println!("|---|---|---|");
    for (label, ms) in [
        ("rkn6-contact, one scene at a time", alone_ms),
        ("rkn6-contact, four scenes in the lanes", lanes_ms),
    ] {
        println!("| {label} | {:.3} | {:.2} |", ms / n, alone_ms / ms);
    }
    println!("\nEvery lane's final state equals its scalar run's, bit for bit.");
}
