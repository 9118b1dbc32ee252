//! `method = "auto"` on random scenes far from the paper's: chains of 81 to 239 sites, fixed or
//! free ends, one to three resonators (p = 1, 3, 5 or 7; eps from 0.03 to 100, kappa from 0.3
//! to 5, a fifth of them switched on by a tanh ramp), impact velocities from 0.2 to 3, end
//! times from 60 to 200. Each against `rk4-contact` at dt = 0.001 (0.00025 with a nonlinear
//! resonator). Prints one line per scene, MISS where the error exceeds the tolerance, then the
//! count and the force evaluations.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example auto_wide [-- SCENES [TOLERANCE]]
//! ```
//!
//! With `WIDE_SCENE=K` in the environment it instead prints scene K's fractions by
//! `rk4-contact`, `rkn6-contact` and DOP853 at several settings: how a miss is examined.
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::on_two_cores;
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{
    fixed_dt, random_scene, reference_dt, reference_fractions, tolerance, Lcg, SceneRanges,
};

/// This survey's ranges (the module doc).
const WIDE: SceneRanges = SceneRanges {
    half: (40, 80.0),
    defects: 3.0,
    site: (0, 30.0),
    p: &[1, 1, 1, 3, 5, 7],
    kappa: (0.3, 5.0),
    eps: (0.03, 100.0),
    impulse_back: 25.0,
    velocity: (0.2, 3.0),
    log_velocity: true,
    t_end: (60.0, 140.0),
};

/// One line for `scene`, whether it missed, and its force evaluations.
fn check(k: usize, scene: &Scenario, tol: f64) -> (String, bool, u64) {
    let reference = reference_fractions(scene, reference_dt(&scene.model)).unwrap();
    let out = simulate(scene, &mut ()).unwrap();
    let error = out.fractions.largest_difference(&reference);
    let resonators: Vec<String> = scene
        .model
        .resonators()
        .iter()
        .map(|r| format!("(eps {:.3}, p {}, {:?})", r.eps, r.p, r.coupling))
        .collect();
    let line = format!(
        "{k:3} {} error {error:.1e} estimate {:.1e} dt {:.4} evals {} {:?} ends, {}",
        if error > tol { "MISS" } else { "ok  " },
        out.error_estimate.unwrap_or(0.0),
        out.plan.dt().unwrap_or(0.0),
        out.total_rhs_evals,
        scene.model.boundary(),
        resonators.join(" ")
    );
    (line, error > tol, out.total_rhs_evals)
}

/// Scene `scene`'s fractions by the reference method at finer steps, by `auto`'s method over
/// its ladder's steps, and by DOP853: whether a miss is `auto`'s or its reference's.
fn examine(scene: &Scenario) {
    let settings = [
        ("rk4-contact", Some(0.001)),
        ("rk4-contact", Some(0.0005)),
        ("rk4-contact", Some(0.00025)),
        ("rkn6-contact", Some(0.1)),
        ("rkn6-contact", Some(0.05)),
        ("rkn6-contact", Some(0.025)),
        ("rkn6-contact", Some(0.0125)),
        ("rkn6-contact", Some(0.001)),
        ("rkn4-contact", Some(0.001)),
        ("dop853", None),
    ];
    for (name, dt) in settings {
        let accuracy = dt.map_or(tolerance(1e-10), fixed_dt);
        let method = MethodChoice::Named(Method::from_name(name).unwrap());
        let o = simulate(
            &Scenario {
                method,
                accuracy,
                ..scene.clone()
            },
            &mut (),
        )
        .unwrap();
        println!("{name} {dt:?}: {:?}", o.fractions);
    }
}

fn main() {
    let n: usize = std::env::args().nth(1).map_or(60, |s| s.parse().unwrap());
    let tol: f64 = std::env::args().nth(2).map_or(1e-6, |s| s.parse().unwrap());
    let mut rng = Lcg(777);
    let indexed: Vec<(usize, Scenario)> = (0..n)
        .map(|k| (k, random_scene(&mut rng, &WIDE, tol)))
        .collect();
    if let Ok(k) = std::env::var("WIDE_SCENE") {
        examine(&indexed[k.parse::<usize>().unwrap()].1);
        return;
    }
    let results: Vec<(String, bool, u64)> =
        on_two_cores(&indexed, |(k, scene)| check(*k, scene, tol));
    for (line, _, _) in &results {
        println!("{line}");
    }
    let missed = results.iter().filter(|(_, m, _)| *m).count();
    let evals: u64 = results.iter().map(|(_, _, e)| e).sum();
    println!("tol={tol:.0e}: {n} scenes, {missed} missed, {evals} evals");
}
