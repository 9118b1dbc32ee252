//! `method = "auto"` on one scene of each of the paper's kinds, against a tight reference
//! (`rk4-contact` at dt = 0.002, which agrees with RK4 at 0.001 and Yoshida-6 at 5e-4 to about
//! 1e-10): the step auto accepted, its Richardson estimate, the true error (largest over R, T
//! and E_tr), whether it met the tolerance, the force evaluations of the whole verification
//! ladder, and the wall time.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example auto_accuracy [-- TOLERANCE]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::model::Coupling;
use woodpile_sim::run::simulate;
use woodpile_sim::testing::{fixed_dt, paper_scene, tolerance, PaperDefect};
fn pd(site: i64, eps: f64, p: u32) -> PaperDefect {
    PaperDefect {
        site,
        eps,
        coupling: Coupling::Constant(1.0),
        p,
    }
}
fn main() {
    let tol: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e-6);
    let scenes: Vec<(&str, Vec<PaperDefect>)> = vec![
        ("standard eps=10", vec![pd(0, 10.0, 1)]),
        ("F4 L=2 eps=0.5", (0..=2).map(|s| pd(s, 0.5, 1)).collect()),
        ("F5 L=9 eps=30", (0..=9).map(|s| pd(s, 30.0, 1)).collect()),
        ("F7 fine (0.1,0.1)", vec![pd(0, 0.1, 1), pd(20, 0.1, 1)]),
        ("F7 fine (0.67,0.54)", vec![pd(0, 0.67, 1), pd(20, 0.54, 1)]),
        ("F7 coarse (13,100)", vec![pd(0, 13.0, 1), pd(20, 100.0, 1)]),
        ("F6 p=3 eps=0.16", vec![pd(0, 0.16, 3)]),
        ("F6 p=19 eps=0.01", vec![pd(0, 0.01, 19)]),
    ];
    let (mut tot_ms, mut tot_ev) = (0.0, 0u64);
    for (name, d) in scenes {
        let r = simulate(
            &paper_scene(&d, MethodChoice::Named(Method::Rk4Contact), fixed_dt(0.002)),
            &mut (),
        )
        .unwrap()
        .fractions;
        let s = paper_scene(&d, MethodChoice::Auto, tolerance(tol));
        let t0 = Instant::now();
        let o = simulate(&s, &mut ()).unwrap();
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        let f = o.fractions;
        let err = (f.reflected - r.reflected)
            .abs()
            .max((f.transmitted - r.transmitted).abs())
            .max((f.trapped - r.trapped).abs());
        tot_ms += ms;
        tot_ev += o.total_rhs_evals;
        println!(
            "{name:22} dt={:.4} est={:.1e} err={err:.1e} {} evals={} {ms:.1} ms",
            o.plan.dt().unwrap_or(0.0),
            o.error_estimate.unwrap_or(0.0),
            if err <= tol { "ok  " } else { "MISS" },
            o.total_rhs_evals
        );
    }
    println!("total {tot_ms:.1} ms, {tot_ev} evals");
}
