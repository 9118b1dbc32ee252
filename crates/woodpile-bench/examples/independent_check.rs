//! The damped audit's scenes run by the independent reference (`woodpile_bench::independent`)
//! at two tolerances and by the simulator's `rk4-contact` at the audit's old reference step:
//! how far apart the two references are, and what the independent one costs.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example independent_check [-- SCENES [SEED]]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;
use woodpile_bench::independent::reference;
use woodpile_bench::on_two_cores;
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{damped_audit_scene, fixed_dt, Lcg, AUDIT_REFERENCE_DT};

const FINE: f64 = 1e-13;
const COARSE: f64 = 1e-12;

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(10, |s| s.parse().unwrap());
    let seed: u64 = args.next().map_or(2026, |s| s.parse().unwrap());
    let mut rng = Lcg(seed);
    let scenes: Vec<(usize, Scenario)> =
        (0..n).map(|k| (k, damped_audit_scene(&mut rng))).collect();
    let lines = on_two_cores(&scenes, |(k, scene)| {
        let clock = Instant::now();
        let fine = reference(scene, FINE);
        let seconds = clock.elapsed().as_secs_f64();
        let coarse = reference(scene, COARSE);
        let rk4 = simulate(
            &Scenario {
                method: MethodChoice::Named(Method::Rk4Contact),
                accuracy: fixed_dt(AUDIT_REFERENCE_DT),
                ..scene.clone()
            },
            &mut (),
        )
        .map(|o| o.fractions);
        let rk4_seconds = clock.elapsed().as_secs_f64() - seconds;
        match (fine, coarse) {
            (Ok(f), Ok(c)) => format!(
                "{k:3} n {:3} | own bound {:.1e} | against rk4-contact {:.1e} | ledger {:.1e} | {:.2} s ({:.2} s for both rk4 and the coarse), {} steps, {} switches, {} evals",
                scene.model.n_sites(),
                f.fractions.largest_difference(&c.fractions),
                rk4.as_ref().map_or(f64::NAN, |r| f.fractions.largest_difference(r)),
                f.ledger_drift,
                seconds,
                rk4_seconds,
                f.counts.steps,
                f.counts.switches,
                f.counts.evals
            ),
            (Err(e), _) | (_, Err(e)) => format!("{k:3} failed: {e}"),
        }
    });
    for line in lines {
        println!("{line}");
    }
}
