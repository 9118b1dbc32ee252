//! The paper sample's scenes run by `simulate` alone, pass after pass, on one thread: a steady
//! load to profile a scene's time under (`perf record`), without the references and baselines
//! `woodpile-bench` also runs. Prints the mean time of a pass.
//!
//! ```sh
//! cargo run --release -p woodpile-bench --example sample_passes -- 1e-6 20 20
//! perf record target/release/examples/sample_passes 1e-6 20 20
//! ```
//!
//! Arguments: the tolerance every scene runs at, the scenes drawn from each of the paper's
//! sweeps (seed 2026, as `woodpile-bench --paper N`), and the passes.

#![allow(clippy::print_stdout)]

use std::time::Instant;

use woodpile_bench::paper::paper_sample;
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::tolerance;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |i: usize, default: f64| {
        args.get(i)
            .map_or(Ok(default), |a| a.parse::<f64>())
            .unwrap_or_else(|_| {
                eprintln!("usage: sample_passes [TOLERANCE] [PER_SWEEP] [PASSES]");
                std::process::exit(2)
            })
    };
    let (tol, per_sweep, passes) = (number(0, 1e-6), number(1, 20.0), number(2, 20.0));
    let scenes: Vec<Scenario> = paper_sample("pipeline", per_sweep as usize, 2026)
        .unwrap_or_else(|e| {
            eprintln!("sample_passes: {e}");
            std::process::exit(1)
        })
        .into_iter()
        .map(|(_, s)| Scenario {
            accuracy: tolerance(tol),
            ..s
        })
        .collect();
    let t0 = Instant::now();
    for _ in 0..passes as usize {
        for scene in &scenes {
            if let Err(e) = simulate(scene, &mut ()) {
                eprintln!("sample_passes: {e}");
                std::process::exit(1)
            }
        }
    }
    let ms = t0.elapsed().as_secs_f64() * 1e3 / passes;
    println!(
        "{} scenes at tolerance {tol:e}: {ms:.1} ms a pass",
        scenes.len()
    );
}
