//! The known scene's noisy trace as CSV (t in s, rod, velocity in m/s, 6 significant
//! digits): the measured trace the pipeline's calibration figure fits.
//!
//! `cargo run --release -p woodpile-calibrate --example synthetic_trace -- 1 > pipeline/experiment/trace_synthetic.csv`
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::path::Path;

fn main() {
    let seed: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1);
    let table: toml::Table = toml::from_str(woodpile_calibrate::testing::SCENE).unwrap();
    let truth = woodpile_scene::from_table(table, Path::new("truth.toml")).unwrap();
    let trace = woodpile_calibrate::testing::trace(&truth, seed);
    println!("# woodpile_calibrate::testing's scene (gamma = 1800 N s/m^1.5, Q = 30) with 5% noise, seed {seed}");
    println!("t,rod,velocity");
    for ((t, rod), v) in trace.t.iter().zip(&trace.rod).zip(&trace.velocity) {
        println!("{t:e},{rod},{v:.6e}");
    }
}
