//! Whether a higher-order method with the same contact events helps a damped chain: the
//! standard scene undamped and with a contact dashpot of each law, integrated at fixed steps by
//! `rk4-contact` and by Butcher's RK6 with the same events and switch location
//! (`woodpile_sim::testing::Rk6Contact`), each run's error against the independent reference
//! (`woodpile_bench::independent`) and its force evaluations (docs/methods.md, "A higher-order
//! method with the same events"). Each scene's line first gives the reference's own bound:
//! how far it moves between rtol 1e-13 and 1e-12.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example damped_order [-- DTS]
//! cargo run --release -p woodpile-bench --example damped_order -- 0.016,0.008,0.004,0.002,0.001
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::independent::reference;
use woodpile_bench::{standard_scene_with, standard_scene_with_dashpot};
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{fixed_dt, run_fixed_step, Rk6Contact};

fn main() {
    let dts: Vec<f64> = std::env::args()
        .nth(1)
        .map_or(vec![0.016, 0.008, 0.004, 0.002, 0.001], |s| {
            s.split(',').map(|t| t.parse().unwrap()).collect()
        });
    let rows = [
        ("undamped", standard_scene_with("", "")),
        (
            "contact = 0.05, hertzian",
            standard_scene_with_dashpot("hertzian"),
        ),
        (
            "contact = 0.05, linear",
            standard_scene_with_dashpot("linear"),
        ),
    ];
    println!("| scene | dt | `rk4-contact` error | evaluations | RK6 with the same events: error | evaluations |");
    println!("|---|---|---|---|---|---|");
    for (name, scene) in &rows {
        let exact = reference(scene, 1e-13).unwrap().fractions;
        let looser = reference(scene, 1e-12).unwrap().fractions;
        println!(
            "| {name} | reference's bound | {:.1e} | | | |",
            looser.largest_difference(&exact)
        );
        for &dt in &dts {
            let rk4 = Scenario {
                method: MethodChoice::Named(Method::Rk4Contact),
                accuracy: fixed_dt(dt),
                ..scene.clone()
            };
            let rk4 = simulate(&rk4, &mut ()).unwrap();
            let mut stepper = Rk6Contact::new(&scene.model);
            let (rk6, rk6_evals) = run_fixed_step(scene, &mut stepper, dt).unwrap();
            println!(
                "| {name} | {dt} | {:.1e} | {} | {:.1e} | {rk6_evals} |",
                rk4.fractions.largest_difference(&exact),
                rk4.total_rhs_evals,
                rk6.largest_difference(&exact),
            );
        }
    }
}
