//! A cheaper error estimate for `auto`, measured before it is trusted: Richardson's estimate
//! from the pair (dt, 4 dt), |F(dt) - F(4 dt)| / (4^q - 1), whose coarse run costs a quarter
//! of the fine run where the pair (dt, 2 dt) that `auto` uses costs a half.
//!
//! On the audit's random scenes (`testing::audit_scene`, drawn wider than any stage file), at
//! each tolerance, the first two rungs of `auto`'s ladder (its first step and half of it) are
//! judged by each pair alone, with `auto`'s acceptance threshold, and the run at dt is set
//! against the independent reference (`rk4-contact` at dt = 2.5e-4). A pair that accepts a run
//! whose error is above the tolerance is a miss. `auto` adds rules of its own (three runs in
//! the asymptotic regime, a run off the ladder) that this comparison leaves out, so the misses
//! here are the pair's, not `auto`'s.
//!
//! With `paper` in place of a seed, the scenes are SCENES drawn from each sweep stage file.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example cheaper_estimate [-- SCENES [SEED|paper [TOLERANCES]]]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::{at_fixed_step, auto_first_step_at, on_two_cores};
use woodpile_pipeline::Pipeline;
use woodpile_sim::energy::Fractions;
use woodpile_sim::integrate::Method;
use woodpile_sim::simulation::{accepted_estimate, Scenario};
use woodpile_sim::testing::{audit_scene, Lcg, AUDIT_REFERENCE_DT};
use woodpile_stages::sampling::sampled_sweep_scenes;
use woodpile_stages::KINDS;

/// `scene` by `method` at the fixed step `dt`: its fractions and force evaluations, or `None`
/// when the run blew up or lost its energy (an estimate that would then say "halve").
fn at_step(scene: &Scenario, method: Method, dt: f64) -> Option<(Fractions, u64)> {
    at_fixed_step(scene, method, dt).map(|o| (o.fractions, o.stats.rhs_evals))
}

/// One decision of the ladder: (tolerance, the error of the run at dt, the estimate from the
/// pair (dt, 2 dt), from (dt, 4 dt), the largest estimate accepted, evals of the dt, 2 dt and
/// 4 dt runs).
type Row = (f64, f64, f64, f64, f64, [u64; 3]);

/// The first two rungs of `auto`'s ladder (its first step dt0, then dt0 / 2), each judged by
/// both pairs.
fn measure(scene: &Scenario, tolerances: &[f64]) -> Vec<Row> {
    let Some((reference, _)) = at_step(scene, Method::Rk4Contact, AUDIT_REFERENCE_DT) else {
        return Vec::new();
    };
    let q = Method::Rkn6Contact.observed_order();
    let mut rows = Vec::new();
    for &tol in tolerances {
        let Some(dt0) = auto_first_step_at(scene, tol) else {
            continue;
        };
        for rung in 0..2 {
            let dt = dt0 / f64::from(1 << rung);
            let Some((fine, fine_evals)) = at_step(scene, Method::Rkn6Contact, dt) else {
                continue;
            };
            let estimate = |k: f64| {
                at_step(scene, Method::Rkn6Contact, k * dt).map_or((f64::INFINITY, 0), |(f, n)| {
                    (f.largest_difference(&fine) / (k.powf(q) - 1.0), n)
                })
            };
            let ((e2, evals2), (e4, evals4)) = (estimate(2.0), estimate(4.0));
            let error = fine.largest_difference(&reference);
            rows.push((
                tol,
                error,
                e2,
                e4,
                accepted_estimate(&scene.model, tol),
                [fine_evals, evals2, evals4],
            ));
        }
    }
    rows
}

/// Two ladders to their first accept within the two rungs: `auto`'s, every rung judged by
/// (dt, 2 dt), and a cheaper first rung judged by (dt, 4 dt), later rungs by (dt, 2 dt) (whose
/// coarse run is the rung before, free). Per ladder: (accepted, missed, evaluations).
fn ladders(rungs: &[&Row]) -> [(bool, bool, u64); 2] {
    let [r0, r1] = [rungs[0], rungs[1]];
    let tol = r0.0;
    let decide = |first_estimate: f64, first_coarse: u64| {
        if first_estimate <= r0.4 {
            (true, r0.1 > tol, first_coarse + r0.5[0])
        } else {
            let ok = r1.2 <= r1.4;
            (ok, ok && r1.1 > tol, first_coarse + r0.5[0] + r1.5[0])
        }
    };
    [decide(r0.2, r0.5[1]), decide(r0.3, r0.5[2])]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(100, |s| s.parse().unwrap());
    let seed = args.next().unwrap_or_else(|| "2026".into());
    let tolerances: Vec<f64> = args.next().map_or(vec![1e-6, 1e-7], |s| {
        s.split(',').map(|t| t.parse().unwrap()).collect()
    });
    let scenes: Vec<Scenario> = if seed == "paper" {
        let pipeline = Pipeline::load("pipeline".as_ref(), KINDS).unwrap();
        sampled_sweep_scenes(&pipeline, n)
            .unwrap()
            .into_iter()
            .map(|(_, s)| s)
            .collect()
    } else {
        let mut rng = Lcg(seed.parse().unwrap());
        (0..n).map(|_| audit_scene(&mut rng)).collect()
    };
    let per_scene: Vec<Vec<Row>> = on_two_cores(&scenes, |s| measure(s, &tolerances));
    let n = scenes.len();
    println!("{n} scenes ({seed}): auto's first two rungs, judged by either pair\n");
    println!("| tolerance | pair judging the first rung | first rungs accepted | accepted within two rungs | misses (error > tolerance) | worst error / tolerance accepted | evaluations / auto's |");
    println!("|---|---|---|---|---|---|---|");
    for &tol in &tolerances {
        let mut sums = [(0usize, 0usize, 0usize, 0.0f64, 0u64); 2];
        for rows in &per_scene {
            let rungs: Vec<&Row> = rows.iter().filter(|r| r.0 == tol).collect();
            if rungs.len() != 2 {
                continue;
            }
            for (k, (ok, miss, evals)) in ladders(&rungs).into_iter().enumerate() {
                let first = if k == 0 { rungs[0].2 } else { rungs[0].3 } <= rungs[0].4;
                let error = if first { rungs[0].1 } else { rungs[1].1 };
                let sum = &mut sums[k];
                sum.0 += usize::from(first);
                sum.1 += usize::from(ok);
                sum.2 += usize::from(miss);
                if ok {
                    sum.3 = sum.3.max(error / tol);
                }
                sum.4 += evals;
            }
        }
        for (k, label) in ["dt, 2 dt (auto)", "dt, 4 dt"].iter().enumerate() {
            let (first, ok, miss, worst, evals) = sums[k];
            println!(
                "| {tol:.0e} | {label} | {first} | {ok} | {miss} | {worst:.2} | {:.3} |",
                evals as f64 / sums[0].4 as f64
            );
        }
    }
}
