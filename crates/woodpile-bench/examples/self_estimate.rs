//! A run that judges itself, measured before it is trusted: can the fine run's own energy
//! drift stand in for the coarse run of `auto`'s pair? The drift is the one error a run of a
//! conservative chain measures of itself at no cost (every local error's effect on the energy,
//! which needs no transport: the energy is conserved), so it is the cheapest estimate there is
//! of the kind the issue asks to try (one fed by the run's own local and event errors).
//!
//! On the audit's random scenes (`testing::audit_scene`) at each tolerance, `rkn6-contact` runs
//! at `auto`'s first step; its error is taken against the independent reference
//! (`rk4-contact` at dt = 2.5e-4), and set beside its energy drift and the Richardson
//! estimate of the pair `auto` makes. A drift estimate `C · drift` needs a constant C: it is
//! calibrated on the first seed's scenes as the least C for which C · drift bounds every run's
//! error there as `auto` holds its estimates to (the error times the acceptance threshold over
//! the tolerance), then judged on the second seed's: first rungs accepted (C · drift at most
//! `auto`'s acceptance threshold), misses (accepted, error above the tolerance), and the force
//! evaluations of the two ladders to their second rung (a refused first rung costs a run at
//! dt / 2). With `paper` in place of the second seed, the scenes judged are about SCENES,
//! drawn evenly from the five sweep stage files.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example self_estimate [-- SCENES [SEED SEED|paper [TOLERANCES]]]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::{at_fixed_step, auto_first_step_at, on_two_cores};
use woodpile_pipeline::Pipeline;
use woodpile_sim::integrate::Method;
use woodpile_sim::simulation::{accepted_estimate, Scenario};
use woodpile_sim::testing::{audit_scene, Lcg, AUDIT_REFERENCE_DT};
use woodpile_stages::sampling::sampled_sweep_scenes;
use woodpile_stages::KINDS;

/// One first rung: (tolerance, the run's error, its energy drift, the pair's Richardson
/// estimate, the largest estimate accepted, evaluations of the runs at dt and 2 dt).
type Row = (f64, f64, f64, f64, f64, [u64; 2]);

/// The first rung of `auto`'s ladder on `scene` at each of `tolerances`.
fn measure(scene: &Scenario, tolerances: &[f64]) -> Vec<Row> {
    if scene.model.is_time_dependent() {
        return Vec::new(); // A ramped coupling: no conserved energy, no drift to judge by.
    }
    let Some(reference) = at_fixed_step(scene, Method::Rk4Contact, AUDIT_REFERENCE_DT) else {
        return Vec::new();
    };
    let q = Method::Rkn6Contact.observed_order();
    let mut rows = Vec::new();
    for &tol in tolerances {
        let Some(dt) = auto_first_step_at(scene, tol) else {
            continue;
        };
        let (Some(fine), Some(coarse)) = (
            at_fixed_step(scene, Method::Rkn6Contact, dt),
            at_fixed_step(scene, Method::Rkn6Contact, 2.0 * dt),
        ) else {
            continue;
        };
        rows.push((
            tol,
            fine.fractions.largest_difference(&reference.fractions),
            fine.stats.max_energy_drift,
            fine.fractions.largest_difference(&coarse.fractions) / (2f64.powf(q) - 1.0),
            accepted_estimate(&scene.model, tol),
            [fine.stats.rhs_evals, coarse.stats.rhs_evals],
        ));
    }
    rows
}

/// The rows of `n` audit scenes drawn with `seed`, or of about `n` from the sweep stage
/// files for `paper` (those without a ramped coupling).
fn rows_of(n: usize, seed: &str, tolerances: &[f64]) -> Vec<Row> {
    let scenes: Vec<Scenario> = if seed == "paper" {
        let pipeline = Pipeline::load("pipeline".as_ref(), KINDS).unwrap();
        let sampled = sampled_sweep_scenes(&pipeline, n.div_ceil(5)).unwrap();
        sampled.into_iter().map(|(_, s)| s).collect()
    } else {
        let mut rng = Lcg(seed.parse().unwrap());
        (0..n).map(|_| audit_scene(&mut rng)).collect()
    };
    let n = scenes.len();
    let ramped = scenes
        .iter()
        .filter(|s| s.model.is_time_dependent())
        .count();
    println!("seed {seed}: {ramped} of {n} scenes have a ramped coupling and are left out");
    on_two_cores(&scenes, |s| measure(s, tolerances))
        .into_iter()
        .flatten()
        .collect()
}

/// The value below which a share `p` of `values` lies.
fn quantile(values: &mut [f64], p: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    values[((values.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(100, |s| s.parse().unwrap());
    let calibration = args.next().unwrap_or_else(|| "2026".into());
    let test = args.next().unwrap_or_else(|| "7".into());
    let tolerances: Vec<f64> = args.next().map_or(vec![1e-5, 1e-6, 1e-7], |s| {
        s.split(',').map(|t| t.parse().unwrap()).collect()
    });
    let calibrating = rows_of(n, &calibration, &tolerances);
    let judged = rows_of(n, &test, &tolerances);
    let ratio = |r: &Row| r.1 / r.2.max(f64::MIN_POSITIVE);
    println!("\nThe run at auto's first step, its error against its energy drift\n");
    println!("| seed | tolerance | runs | error / drift: 10% | median | 90% | largest | error / Richardson estimate: largest |");
    println!("|---|---|---|---|---|---|---|---|");
    for (seed, rows) in [(&calibration, &calibrating), (&test, &judged)] {
        for &tol in &tolerances {
            let at: Vec<&Row> = rows.iter().filter(|r| r.0 == tol).collect();
            let mut ratios: Vec<f64> = at.iter().map(|r| ratio(r)).collect();
            if ratios.is_empty() {
                continue;
            }
            let worst_richardson = at.iter().map(|r| r.1 / r.3).fold(0.0, f64::max);
            println!(
                "| {seed} | {tol:.0e} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {worst_richardson:.2} |",
                ratios.len(),
                quantile(&mut ratios, 0.1),
                quantile(&mut ratios, 0.5),
                quantile(&mut ratios, 0.9),
                quantile(&mut ratios, 1.0),
            );
        }
    }
    // The least C for which C · drift bounds every calibration run's error as auto's
    // estimate must (error · accept / tol).
    let c = calibrating
        .iter()
        .filter(|r| r.1 > 0.0)
        .map(|r| ratio(r) * r.4 / r.0)
        .fold(0.0, f64::max);
    println!("\nC = {c:.3e} (calibrated on seed {calibration}), judged on seed {test}:\n");
    println!("| tolerance | first rungs accepted by the pair | misses | accepted by C · drift | misses | evaluations to the second rung, drift / pair |");
    println!("|---|---|---|---|---|---|");
    for &tol in &tolerances {
        let at: Vec<&Row> = judged.iter().filter(|r| r.0 == tol).collect();
        let pair: Vec<&&Row> = at.iter().filter(|r| r.3 <= r.4).collect();
        let drift: Vec<&&Row> = at.iter().filter(|r| c * r.2 <= r.4).collect();
        let misses = |accepted: &[&&Row]| accepted.iter().filter(|r| r.1 > r.0).count();
        // A refused first rung costs its ladder the next rung's run at dt / 2, twice the run
        // at dt (whose own pair, with the run at dt, needs no further run).
        let next_rung = |r: &&Row, accepted: bool| if accepted { 0 } else { 2 * r.5[0] };
        let evals_pair: u64 = at
            .iter()
            .map(|r| r.5[0] + r.5[1] + next_rung(r, r.3 <= r.4))
            .sum();
        let evals_drift: u64 = at
            .iter()
            .map(|r| r.5[0] + next_rung(r, c * r.2 <= r.4))
            .sum();
        println!(
            "| {tol:.0e} | {} of {} | {} | {} | {} | {:.3} |",
            pair.len(),
            at.len(),
            misses(&pair),
            drift.len(),
            misses(&drift),
            evals_drift as f64 / evals_pair as f64
        );
    }
}
