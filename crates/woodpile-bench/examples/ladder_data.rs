//! Raw data for designing `auto`'s verification ladder: the fractions of sampled sweep scenes
//! (`woodpile_stages::sampling`, run from the repository's root) at a geometric ladder of fixed steps (ratio 0.85) for
//! `rk4-contact` and `rkn4-contact`, with the reference (`rk4-contact` at dt = 0.001). CSV on
//! stdout, the label quoted.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example ladder_data [-- PER_KIND] > ladder.csv
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::on_two_cores;
use woodpile_pipeline::Pipeline;
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::simulation::simulate;
use woodpile_sim::simulation::Scenario;
use woodpile_sim::testing::fixed_dt;
use woodpile_stages::sampling::sampled_sweep_scenes;
use woodpile_stages::KINDS;

fn scene_rows(i: usize, label: &str, scenario: &Scenario) -> Vec<String> {
    let nonlinear = scenario.model.resonators().iter().any(|r| r.p > 1);
    let mut runs = vec![(Method::Rk4Contact, 0.001, "ref")];
    let mut dt = 0.25;
    while dt >= if nonlinear { 0.0015 } else { 0.004 } {
        runs.push((Method::Rk4Contact, dt, "rk4c"));
        runs.push((Method::Rkn4Contact, dt, "rkn4c"));
        dt *= 0.85;
    }
    runs.into_iter()
        .map(|(m, dt, name)| {
            match simulate(
                &Scenario {
                    method: MethodChoice::Named(m),
                    accuracy: fixed_dt(dt),
                    ..scenario.clone()
                },
                &mut (),
            ) {
                Ok(o) => {
                    let f = o.fractions;
                    format!(
                        "{i},\"{label}\",{name},{},{:.17e},{:.17e},{:.17e},{}",
                        o.plan.dt().unwrap(),
                        f.reflected,
                        f.transmitted,
                        f.trapped,
                        o.total_rhs_evals
                    )
                }
                Err(_) => format!("{i},\"{label}\",{name},{dt},nan,nan,nan,0"),
            }
        })
        .collect()
}

fn main() {
    let per_kind = std::env::args().nth(1).map_or(10, |s| s.parse().unwrap());
    let pipeline = Pipeline::load("pipeline".as_ref(), KINDS).unwrap();
    let scenes = sampled_sweep_scenes(&pipeline, per_kind).unwrap();
    println!("scene,label,method,dt,R,T,E_tr,evals");
    let indexed: Vec<(usize, &(String, Scenario))> = scenes.iter().enumerate().collect();
    let rows: Vec<String> =
        on_two_cores(&indexed, |(i, (label, d))| scene_rows(*i, label, d)).concat();
    for row in rows {
        println!("{row}");
    }
}
