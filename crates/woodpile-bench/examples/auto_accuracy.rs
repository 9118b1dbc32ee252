//! `method = "auto"` against a tight reference, on one scene of each of the paper's kinds or,
//! with `--survey N`, on N scenes of each sweep kind drawn from the stage files' grids
//! (`woodpile_stages::sampling`, run from the repository's root): the step auto accepted, its Richardson estimate, the true error
//! (largest over R, T and E_tr), whether it met the tolerance, the force evaluations of the whole
//! verification ladder, and the wall time. The reference is `rk4-contact` at dt = 0.001
//! (0.00025 for nonlinear resonators), which agrees with RK4 at 0.001 and Yoshida-6 at 5e-4 to
//! about 1e-10 on the linear scenes.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example auto_accuracy [-- TOL...] [--survey N]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;
use woodpile_bench::on_two_cores;
use woodpile_pipeline::Pipeline;
use woodpile_sim::integrate::MethodChoice;
use woodpile_sim::simulation::simulate;
use woodpile_sim::simulation::Scenario;
use woodpile_sim::testing::{
    paper_scene, reference_dt, reference_fractions, tolerance, PaperDefect,
};
use woodpile_stages::sampling::sampled_sweep_scenes;
use woodpile_stages::KINDS;

fn hand_picked() -> Vec<(String, Scenario)> {
    let pd = |site, eps, p| PaperDefect::with_exponent(site, eps, 1.0, p);
    vec![
        ("standard eps=10".into(), vec![pd(0, 10.0, 1)]),
        (
            "F4 L=2 eps=0.5".into(),
            (0..=2).map(|s| pd(s, 0.5, 1)).collect(),
        ),
        (
            "F5 L=9 eps=30".into(),
            (0..=9).map(|s| pd(s, 30.0, 1)).collect(),
        ),
        (
            "F7 fine (0.1,0.1)".into(),
            vec![pd(0, 0.1, 1), pd(20, 0.1, 1)],
        ),
        (
            "F7 fine (0.67,0.54)".into(),
            vec![pd(0, 0.67, 1), pd(20, 0.54, 1)],
        ),
        (
            "F7 coarse (13,100)".into(),
            vec![pd(0, 13.0, 1), pd(20, 100.0, 1)],
        ),
        ("F6 p=3 eps=0.16".into(), vec![pd(0, 0.16, 3)]),
        ("F6 p=19 eps=0.01".into(), vec![pd(0, 0.01, 19)]),
    ]
    .into_iter()
    .map(|(name, d)| (name, paper_scene(&d, MethodChoice::Auto, tolerance(1e-6))))
    .collect()
}

/// One auto run against the reference.
struct Verdict {
    line: String,
    missed: bool,
    error_per_tol: f64,
    evals: u64,
    ms: f64,
}

/// One scene at every tolerance.
fn survey_scene(name: &str, scenario: &Scenario, tols: &[f64]) -> Vec<Verdict> {
    // Sampled every time unit, as auto was calibrated (the step tiles each sample interval).
    let scene = |tol| Scenario {
        method: MethodChoice::Auto,
        accuracy: tolerance(tol),
        sample_every: 1.0,
        ..scenario.clone()
    };
    let first = scene(tols[0]);
    let reference = reference_fractions(&first, reference_dt(&first.model)).unwrap();
    tols.iter()
        .map(|&tol| {
            let t0 = Instant::now();
            let o = simulate(&scene(tol), &mut ()).unwrap();
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            let err = o.fractions.largest_difference(&reference);
            let line = format!(
                "tol={tol:.0e} {name:24} dt={:.4} est={:.1e} err={err:.1e} {} evals={} {ms:.1} ms",
                o.plan.dt().unwrap_or(0.0),
                o.error_estimate.unwrap_or(0.0),
                if err <= tol { "ok  " } else { "MISS" },
                o.total_rhs_evals
            );
            Verdict {
                line,
                missed: err > tol,
                error_per_tol: err / tol,
                evals: o.total_rhs_evals,
                ms,
            }
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let survey = args
        .iter()
        .position(|a| a == "--survey")
        .map(|i| args[i + 1].parse::<usize>().unwrap());
    let mut tols: Vec<f64> = args
        .iter()
        .enumerate()
        .filter(|(i, a)| *a != "--survey" && (*i == 0 || args[i - 1] != "--survey"))
        .map(|(_, a)| a.parse().unwrap())
        .collect();
    if tols.is_empty() {
        tols.push(1e-6);
    }
    let scenes = match survey {
        Some(n) => {
            sampled_sweep_scenes(&Pipeline::load("pipeline".as_ref(), KINDS).unwrap(), n).unwrap()
        }
        None => hand_picked(),
    };
    let results: Vec<Vec<Verdict>> =
        on_two_cores(&scenes, |(name, d)| survey_scene(name, d, &tols));
    for (k, tol) in tols.iter().enumerate() {
        let (mut misses, mut worst, mut evals, mut ms) = (0, 0.0f64, 0u64, 0.0);
        for r in &results {
            let v = &r[k];
            println!("{}", v.line);
            misses += usize::from(v.missed);
            worst = worst.max(v.error_per_tol);
            evals += v.evals;
            ms += v.ms;
        }
        println!(
            "tol={tol:.0e}: {} scenes, {misses} missed, worst error {worst:.2} x tol, {evals} evals, {ms:.0} ms\n",
            results.len()
        );
    }
}
