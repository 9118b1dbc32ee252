//! Error in E_tr against wall time for every method on one scene: the numbers quoted in the
//! README and the issue notes.
//!
//! ```text
//! cargo run --release -p woodpile-sim --example work_precision [eps]
//! ```
//!
//! Scene: the paper's standard chain (N = 100, fixed walls, n_S = -25, t = 150) with one linear
//! defect at 0, kappa = 1 (eps = 10 unless given). Reference: Yoshida-6 at dt = 2.5e-4,
//! cross-checked against RK4 at dt = 5e-4 (their difference is printed). Wall time is the best of
//! three runs on this machine.
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;

use woodpile_sim::integrate::{Accuracy, Method, MethodChoice};
use woodpile_sim::simulation::{simulate, Outcome};
use woodpile_sim::testing::{paper_scene, PaperDefect};

fn run(eps: f64, method: MethodChoice, accuracy: Accuracy) -> (Outcome, f64) {
    let scene = paper_scene(&[PaperDefect::linear(0, eps, 1.0)], method, accuracy);
    let mut best = f64::INFINITY;
    let mut outcome = None;
    for _ in 0..3 {
        let t0 = Instant::now();
        let out = simulate(&scene, &mut ()).unwrap();
        best = best.min(t0.elapsed().as_secs_f64());
        outcome = Some(out);
    }
    (outcome.unwrap(), best)
}

fn dt(dt: f64) -> Accuracy {
    Accuracy {
        tolerance: 1.0,
        tolerance_explicit: true,
        dt: Some(dt),
    }
}

fn tol(tol: f64) -> Accuracy {
    Accuracy {
        tolerance: tol,
        tolerance_explicit: true,
        dt: None,
    }
}

fn main() {
    let eps: f64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(10.0);
    let (reference, _) = run(eps, MethodChoice::Named(Method::Yoshida6), dt(2.5e-4));
    let (check, _) = run(eps, MethodChoice::Named(Method::Rk4), dt(5e-4));
    let e_ref = reference.fractions.trapped;
    println!("scene: one defect at 0, eps = {eps}, kappa = 1; reference E_tr = {e_ref:.12}");
    println!(
        "reference check: |yoshida6(2.5e-4) - rk4(5e-4)| = {:.1e}\n",
        (check.fractions.trapped - e_ref).abs()
    );
    println!(
        "| method | setting | abs error E_tr | energy drift | steps | force evals | wall ms |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut rows: Vec<(MethodChoice, Accuracy, String)> = Vec::new();
    // Every fixed-step method (DOP853, adaptive, is swept by tolerance below).
    for m in Method::ALL.into_iter().filter(|&m| m != Method::Dop853) {
        for h in [0.1, 0.05, 0.02, 0.01, 0.005] {
            rows.push((MethodChoice::Named(m), dt(h), format!("dt = {h}")));
        }
    }
    for t in [1e-6, 1e-8, 1e-10] {
        rows.push((
            MethodChoice::Named(Method::Dop853),
            tol(t),
            format!("tolerance = {t:.0e}"),
        ));
    }
    for t in [1e-6, 1e-7, 1e-8] {
        rows.push((MethodChoice::Auto, tol(t), format!("tolerance = {t:.0e}")));
    }
    for (choice, accuracy, setting) in rows {
        let (out, wall) = run(eps, choice, accuracy);
        let name = match choice {
            MethodChoice::Auto => format!(
                "auto ({} dt = {:.2e})",
                out.plan.method.name(),
                out.plan.dt().unwrap_or(0.0)
            ),
            MethodChoice::Named(m) => m.name().to_string(),
        };
        println!(
            "| {name} | {setting} | {:.1e} | {:.1e} | {} | {} | {:.1} |",
            (out.fractions.trapped - e_ref).abs(),
            out.stats.max_energy_drift,
            out.stats.steps,
            out.total_rhs_evals,
            wall * 1e3
        );
    }
}
