//! `rkn6-split` at fixed steps on the standard scene's smooth-loss rows: the linear losses
//! (ground damping, resonator dashpots) integrated exactly half a step before and half after
//! the conservative `rkn6-contact` step (`woodpile_sim::integrate::SplitLosses`).
//!
//! For each row it prints, per fixed step, the run's error against the independent reference,
//! its wall time, and the error's fall per halving, next to what `auto` pays.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example damped_split
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;
use woodpile_bench::independent::reference;
use woodpile_bench::standard_scene_with;
use woodpile_sim::energy::Fractions;
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::fixed_dt;

/// `scene` by `rkn6-split` at step `dt`: its fractions and wall time in ms.
fn split_run(scene: &Scenario, dt: f64) -> (Fractions, f64) {
    let split = Scenario {
        method: MethodChoice::Named(Method::Rkn6Split),
        accuracy: fixed_dt(dt),
        ..scene.clone()
    };
    let clock = Instant::now();
    let out = simulate(&split, &mut ()).unwrap();
    (out.fractions, clock.elapsed().as_secs_f64() * 1e3)
}

fn main() {
    let undamped = standard_scene_with("", "");
    let clock = Instant::now();
    simulate(&undamped, &mut ()).unwrap();
    let undamped_ms = clock.elapsed().as_secs_f64() * 1e3;
    println!("undamped, auto at 1e-8: {undamped_ms:.1} ms\n");
    let rows = [
        (
            "resonator quality_factor = 300",
            standard_scene_with("quality_factor = 300.0", ""),
        ),
        (
            "[damping] ground = 0.001",
            standard_scene_with("", "[damping]\nground = 0.001"),
        ),
        (
            "[damping] ground = 0.01",
            standard_scene_with("", "[damping]\nground = 0.01"),
        ),
    ];
    for (name, scene) in &rows {
        let exact = reference(scene, 1e-13).unwrap().fractions;
        let clock = Instant::now();
        let auto = simulate(scene, &mut ()).unwrap();
        let auto_ms = clock.elapsed().as_secs_f64() * 1e3;
        println!(
            "{name}: auto ({}) {auto_ms:.1} ms, {:.1}x, error {:.1e}",
            auto.plan.method.name(),
            auto_ms / undamped_ms,
            auto.fractions.largest_difference(&exact)
        );
        println!("| dt | error | fall per halving | ms | against undamped auto |");
        println!("|---|---|---|---|---|");
        let mut previous: Option<f64> = None;
        for dt in [0.04, 0.02, 0.01, 0.005, 0.0025] {
            let (f, ms) = split_run(scene, dt);
            let error = f.largest_difference(&exact);
            let fall = previous.map_or(String::from("–"), |p| format!("{:.1}", p / error));
            println!(
                "| {dt} | {error:.1e} | {fall} | {ms:.1} | {:.1}x |",
                ms / undamped_ms
            );
            previous = Some(error);
        }
        println!();
    }
}
