//! How often the 95% intervals of a calibration hold the true values: a known scene's trace
//! with 5% noise, fitted for its contact dashpot γ and its defect's quality factor Q, over
//! `N` noise seeds (docs/calibration.md).
//!
//! `cargo run --release -p woodpile-calibrate --example coverage -- 20`
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::path::Path;

use woodpile_calibrate::calibrate;

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20);
    let scene: toml::Table = toml::from_str(woodpile_calibrate::testing::SCENE).unwrap();
    let truth = woodpile_scene::from_table(scene.clone(), Path::new("truth.toml")).unwrap();
    let parameters = woodpile_calibrate::testing::parameters();
    let truths = [
        woodpile_calibrate::testing::GAMMA,
        woodpile_calibrate::testing::Q,
    ];
    let mut held = [0, 0];
    println!("| seed | γ (N·s/m) ± 1.96 se | Q ± 1.96 se | rms (mm/s) | verified | simulations |");
    println!("|---|---|---|---|---|---|");
    for seed in 1..=seeds {
        let trace = woodpile_calibrate::testing::trace(&truth, seed);
        let fit = calibrate(
            &scene,
            Path::new("scene.toml"),
            &trace,
            &parameters,
            &|| false,
        )
        .unwrap();
        for (k, e) in fit.estimates.iter().enumerate() {
            held[k] += usize::from(e.low <= truths[k] && truths[k] <= e.high);
        }
        let [g, q] = [&fit.estimates[0], &fit.estimates[1]];
        println!(
            "| {seed} | {:.4} ± {:.4} | {:.2} ± {:.2} | {:.3} | {} | {} |",
            g.value,
            1.96 * g.std_error,
            q.value,
            1.96 * q.std_error,
            fit.rms * 1e3,
            fit.verification.passed,
            fit.simulations
        );
    }
    println!(
        "\nγ = {} held in {}/{seeds}, Q = {} held in {}/{seeds}",
        truths[0], held[0], truths[1], held[1]
    );
}
