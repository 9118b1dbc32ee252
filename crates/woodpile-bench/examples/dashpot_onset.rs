//! What a contact dashpot's events cost `rk4-contact`: the standard scene undamped and with a
//! contact dashpot of 0.05 of each law, at fixed steps, each share's error against the
//! independent reference (`woodpile_bench::independent`), the ledger's drift, the force
//! evaluations and the wall time (docs/methods.md, "The onset of a dashpot"). A D error far
//! above R's, T's and E_tr's, and equal to the drift, says the ledger's integration is what
//! misses, not the motion.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example dashpot_onset [-- DTS]
//! cargo run --release -p woodpile-bench --example dashpot_onset -- 0.0086206897,0.001
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]
use woodpile_bench::independent::reference;
use woodpile_bench::{standard_scene_with, standard_scene_with_dashpot};
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::fixed_dt;

fn main() {
    let dts: Vec<f64> = std::env::args().nth(1).map_or(
        // auto's rungs on the standard scene (150 / 8700 and its halvings), then 0.001.
        vec![
            0.0172413793,
            0.0086206897,
            0.0043103448,
            0.0021551724,
            0.001,
        ],
        |s| s.split(',').map(|t| t.parse().unwrap()).collect(),
    );
    let rows = [
        ("undamped", standard_scene_with("", "")),
        ("hertzian", standard_scene_with_dashpot("hertzian")),
        ("linear", standard_scene_with_dashpot("linear")),
    ];
    println!("| scene | dt | largest error | R | T | E_tr | D | drift | evaluations | ms |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (name, scene) in &rows {
        let exact = reference(scene, 1e-13).unwrap().fractions;
        for &dt in &dts {
            let rk4 = Scenario {
                method: MethodChoice::Named(Method::Rk4Contact),
                accuracy: fixed_dt(dt),
                ..scene.clone()
            };
            let t0 = std::time::Instant::now();
            let rk4 = simulate(&rk4, &mut ()).unwrap();
            let f = &rk4.fractions;
            println!(
                "| {name} | {dt} | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {} | {:.0} |",
                f.largest_difference(&exact),
                f.reflected - exact.reflected,
                f.transmitted - exact.transmitted,
                f.trapped - exact.trapped,
                f.dissipated - exact.dissipated,
                rk4.stats.max_energy_drift,
                rk4.total_rhs_evals,
                t0.elapsed().as_secs_f64() * 1e3
            );
        }
    }
}
