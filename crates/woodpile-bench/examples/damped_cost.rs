//! What a damped chain costs against the same chain undamped: the standard scene at
//! tolerance 1e-8 with one kind of loss at a time, `auto`'s wall time (median of five, one
//! thread) and its ratio to the undamped run, and each run's error against the independent
//! reference (`woodpile_bench::independent`). Then one lever for the damped rows: the
//! simulator's DOP853, a higher-order method for y'' = f(t, y, y') without located events,
//! at the tolerances given, with its error and time.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example damped_cost [-- DOP853_TOLERANCES]
//! cargo run --release -p woodpile-bench --example damped_cost -- 1e-8,1e-10,1e-12
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;
use woodpile_bench::independent::reference;
use woodpile_bench::{standard_scene_with, standard_scene_with_dashpot};
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::simulation::{simulate, Outcome, Scenario};
use woodpile_sim::testing::tolerance;
use woodpile_sim::SimError;

/// The median wall time of five runs, in ms, and the last run's outcome, or why the run
/// failed.
fn timed(scene: &Scenario) -> Result<(f64, Outcome), SimError> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..5 {
        let clock = Instant::now();
        last = Some(simulate(scene, &mut ())?);
        times.push(clock.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok((times[2], last.unwrap()))
}

fn main() {
    let dop_tolerances: Vec<f64> = std::env::args().nth(1).map_or(vec![1e-8, 1e-10], |s| {
        s.split(',').map(|t| t.parse().unwrap()).collect()
    });
    let rows = [
        ("undamped", standard_scene_with("", "")),
        (
            "resonator quality_factor = 300",
            standard_scene_with("quality_factor = 300.0", ""),
        ),
        (
            "[damping] ground = 0.001",
            standard_scene_with("", "[damping]\nground = 0.001"),
        ),
        (
            "[damping] contact = 0.05, hertzian",
            standard_scene_with_dashpot("hertzian"),
        ),
        (
            "[damping] contact = 0.05, linear",
            standard_scene_with_dashpot("linear"),
        ),
    ];
    println!("| scene | method | ms (median of 5) | against undamped | evaluations | error against the independent reference |");
    println!("|---|---|---|---|---|---|");
    let mut undamped_ms = f64::NAN;
    for (name, scene) in &rows {
        let exact = reference(scene, 1e-13).unwrap().fractions;
        let (ms, out) = timed(scene).unwrap();
        if undamped_ms.is_nan() {
            undamped_ms = ms;
        }
        println!(
            "| {name} | {} | {ms:.1} | {:.1}x | {} | {:.1e} |",
            out.plan.method.name(),
            ms / undamped_ms,
            out.total_rhs_evals,
            out.fractions.largest_difference(&exact)
        );
        for &tol in &dop_tolerances {
            let dop = Scenario {
                method: MethodChoice::Named(Method::Dop853),
                accuracy: tolerance(tol),
                ..scene.clone()
            };
            let Ok((ms, out)) = timed(&dop).map_err(|e| {
                println!("| … by dop853 at tolerance {tol:.0e} | failed: {e} | | | | |")
            }) else {
                continue;
            };
            println!(
                "| … by dop853 at tolerance {tol:.0e} | dop853 | {ms:.1} | {:.1}x | {} | {:.1e} |",
                ms / undamped_ms,
                out.total_rhs_evals,
                out.fractions.largest_difference(&exact)
            );
        }
    }
}
