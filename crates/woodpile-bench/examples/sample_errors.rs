//! Each scene of the paper sample at tolerance 1e-6 against the bench's reference
//! (`rk4-contact` at `reference_dt`) and a reference at half that step: which scenes are
//! furthest from it, and whether the reference itself is converged there.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example sample_errors -- PER_SWEEP SEED [TOLERANCE]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::paper::paper_sample;
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{reference_dt, reference_fractions, tolerance};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let per_sweep: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(34);
    let seed: u64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(2026);
    let tol: f64 = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(1e-6);
    let scenes = paper_sample("pipeline", per_sweep, seed).unwrap();
    let mut rows = Vec::new();
    for (name, scene) in &scenes {
        let dt = reference_dt(&scene.model);
        let reference = reference_fractions(scene, dt).unwrap();
        let finer = reference_fractions(scene, dt / 2.0).unwrap();
        let run = Scenario {
            accuracy: tolerance(tol),
            ..scene.clone()
        };
        let out = simulate(&run, &mut ()).unwrap();
        let error = out.fractions.largest_difference(&reference);
        let reference_error = reference.largest_difference(&finer);
        rows.push((
            error,
            reference_error,
            name.clone(),
            out.error_estimate,
            out.plan.method.name(),
        ));
    }
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!("| scene | error | reference's own | auto's estimate | method |");
    for (error, reference_error, name, estimate, method) in rows.iter().take(8) {
        println!("| {name} | {error:.2e} | {reference_error:.2e} | {estimate:?} | {method} |");
    }
}
