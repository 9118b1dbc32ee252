//! The audit of `auto`'s promise: random scenes drawn wider than any stage file, each run by
//! `auto` at several tolerances and compared with an independent reference. A scene is
//! `ok` (within tolerance plus the reference's own error), `refused` (exit-3 material: `auto`
//! said it could not verify), or `MISS` (a number presented as verified that is not).
//!
//! Scenes: chains with n from 50 to 150 (101 to 301 sites), fixed or free ends; an impulse of
//! velocity 0.5 to 2 somewhere left of centre; 1 to 5 defects near the centre with eps from 0.05
//! to 100, kappa from 0.1 to 10, p in {1, 3, 5, 7}, a fifth of them switched on by a tanh ramp;
//! t_end from 100 to 200.
//!
//! Reference: `rk4-contact` at dt = 2.5e-4, checked against `rkn6-contact` at the same step
//! (a second method of another order and quadrature); their difference is the reference's
//! error bound, reported per scene.
//!
//! With `--chain` first, the scenes are those of the experiment's chain
//! (`woodpile_sim::testing::chain_audit_scene`): the same draws given another contact exponent,
//! masses and contact coefficients in a repeated pattern, wall contacts, and a precompression
//! or a striker.
//!
//! With `--damped` first, the scenes are either kind given every kind of dissipation
//! (`woodpile_sim::testing::damped_audit_scene`: contact dashpots of both laws, ground damping,
//! resonator dashpots, soft ends). Their reference shares no force code with the simulator:
//! `woodpile_bench::independent`, the first-order system written afresh and integrated by
//! DOP853 at rtol 1e-13 with every contact switch located, checked against itself at 1e-12
//! (the difference is reported as the bound).
//!
//! With `--linear-losses` first, the damped scenes without their contact dashpots
//! (`woodpile_sim::testing::linear_losses_audit_scene`): `auto` splits the slow ones' losses
//! from its step (`rkn6-split`); the same independent reference.
//!
//! With `--linear` first, the scenes are the plain ones with every resonator made linear and
//! constant (`woodpile_sim::testing::linear_audit_scene`): the paper's kind of scene, judged
//! without the stricter rules of a nonlinear or ramped resonator.
//!
//! With `--gravity` first, linear scenes stood upright in gravity
//! (`woodpile_sim::testing::gravity_audit_scene`). With `--gap` first, the plain scenes with
//! every contact a one-sided linear spring across a gap
//! (`woodpile_sim::testing::gap_audit_scene`), against the independent reference as on a
//! damped chain.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example auto_audit [-- [--chain | --damped | --linear-losses | --linear | --gravity | --gap] SCENES [SEED [TOLERANCES [ONLY]]]]
//! cargo run --release -p woodpile-bench --example auto_audit -- 200 2026 1e-5,1e-6,1e-7,1e-8
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::{independent, on_two_cores};
use woodpile_sim::contact::ChainLaw;
use woodpile_sim::energy::Fractions;
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::model::Coupling;
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{
    audit_scene, chain_audit_scene, damped_audit_scene, fixed_dt, gap_audit_scene,
    gravity_audit_scene, linear_audit_scene, linear_losses_audit_scene, tolerance, Lcg,
    AUDIT_REFERENCE_DT as REFERENCE_DT,
};
use woodpile_sim::SimError;

fn fixed(scene: &Scenario, method: Method) -> Fractions {
    let s = Scenario {
        method: MethodChoice::Named(method),
        accuracy: fixed_dt(REFERENCE_DT),
        ..scene.clone()
    };
    simulate(&s, &mut ()).unwrap().fractions
}

/// The independent reference's tolerance on a dissipative chain; its check runs at ten times it.
const INDEPENDENT_RTOL: f64 = 1e-13;

/// The reference fractions and a bound on their error: `rk4-contact` checked by `rkn6-contact`
/// at the same step, or, on a dissipative chain or one of gapped contacts, the independent
/// reference (which shares no force code) checked by itself at a looser tolerance.
fn reference(k: usize, scene: &Scenario) -> (Fractions, f64) {
    let gapped = matches!(scene.model.law(), ChainLaw::LinearGap(_));
    if scene.model.is_dissipative() || gapped {
        let run = |rtol: f64| match independent::reference(scene, rtol) {
            Ok(r) => r.fractions,
            Err(why) => panic!("scene {k}: the independent reference failed at {rtol:e}: {why}"),
        };
        let (reference, check) = (run(INDEPENDENT_RTOL), run(10.0 * INDEPENDENT_RTOL));
        return (reference, reference.largest_difference(&check));
    }
    let reference = fixed(scene, Method::Rk4Contact);
    let check = fixed(scene, Method::Rkn6Contact);
    (reference, reference.largest_difference(&check))
}

/// What `auto` did at one tolerance.
enum Verdict {
    Ok { error: f64 },
    Miss { error: f64, estimate: f64 },
    Refused(String),
}

struct Audit {
    line: String,
    verdicts: Vec<Verdict>,
    evals: Vec<u64>,
}

fn audit(k: usize, scene: &Scenario, tolerances: &[f64]) -> Audit {
    let (reference, reference_error) = reference(k, scene);
    let mut verdicts = Vec::new();
    let mut evals = Vec::new();
    let mut cells = Vec::new();
    for &tol in tolerances {
        let s = Scenario {
            accuracy: tolerance(tol),
            ..scene.clone()
        };
        match simulate(&s, &mut ()) {
            Ok(out) => {
                let error = out.fractions.largest_difference(&reference);
                let estimate = out.error_estimate.unwrap_or(f64::NAN);
                evals.push(out.total_rhs_evals);
                cells.push(format!(
                    "{tol:.0e}: err {error:.1e} est {estimate:.1e} ({})",
                    out.plan.method.name()
                ));
                if error > tol + reference_error {
                    verdicts.push(Verdict::Miss { error, estimate });
                } else {
                    verdicts.push(Verdict::Ok { error });
                }
            }
            Err(
                e @ (SimError::NotConverged { .. }
                | SimError::StepUnderflow { .. }
                | SimError::TooManySteps { .. }
                | SimError::OverBudget(_)),
            ) => {
                evals.push(0);
                cells.push(format!("{tol:.0e}: refused"));
                verdicts.push(Verdict::Refused(e.to_string()));
            }
            Err(e) => panic!("scene {k} at {tol:e}: {e}"),
        }
    }
    let m = &scene.model;
    let resonators: Vec<String> = m
        .resonators()
        .iter()
        .map(|r| {
            let ramp = matches!(r.coupling, Coupling::Ramp { .. });
            format!(
                "eps {:.2} p {}{}",
                r.eps,
                r.p,
                if ramp { " ramp" } else { "" }
            )
        })
        .collect();
    let flag = if verdicts.iter().any(|v| matches!(v, Verdict::Miss { .. })) {
        "MISS"
    } else {
        "    "
    };
    let line = format!(
        "{k:3} {flag} n {} {:?} v {:.2} t_end {:.0} ref_err {reference_error:.1e} | {} | {}",
        m.n_sites() / 2,
        m.boundary(),
        scene.impulse_velocity,
        scene.t_end,
        cells.join("; "),
        resonators.join(", ")
    );
    Audit {
        line,
        verdicts,
        evals,
    }
}

fn main() {
    let mut args = std::env::args().skip(1).peekable();
    let draw: fn(&mut Lcg) -> Scenario = match args.peek().map(String::as_str) {
        Some("--chain") => {
            args.next();
            chain_audit_scene
        }
        Some("--damped") => {
            args.next();
            damped_audit_scene
        }
        Some("--linear-losses") => {
            args.next();
            linear_losses_audit_scene
        }
        Some("--linear") => {
            args.next();
            linear_audit_scene
        }
        Some("--gravity") => {
            args.next();
            gravity_audit_scene
        }
        Some("--gap") => {
            args.next();
            gap_audit_scene
        }
        _ => audit_scene,
    };
    let n: usize = args.next().map_or(200, |s| s.parse().unwrap());
    let seed: u64 = args.next().map_or(2026, |s| s.parse().unwrap());
    let tolerances: Vec<f64> = args.next().map_or(vec![1e-5, 1e-6, 1e-7, 1e-8], |s| {
        s.split(',').map(|t| t.parse().unwrap()).collect()
    });
    // Optionally only these scene indices (the rest are drawn and dropped): a miss's scene.
    let only: Option<Vec<usize>> = args
        .next()
        .map(|s| s.split(',').map(|k| k.parse().unwrap()).collect());
    let mut rng = Lcg(seed);
    let scenes: Vec<(usize, Scenario)> = (0..n)
        .map(|k| (k, draw(&mut rng)))
        .filter(|(k, _)| only.as_ref().is_none_or(|o| o.contains(k)))
        .collect();
    let audits = on_two_cores(&scenes, |(k, scene)| audit(*k, scene, &tolerances));
    for a in &audits {
        println!("{}", a.line);
    }
    println!();
    println!("| tolerance | scenes | within | refused | silent misses | worst error / tolerance among the accepted | force evaluations |");
    println!("|---|---|---|---|---|---|---|");
    for (i, tol) in tolerances.iter().enumerate() {
        let (mut ok, mut refused, mut missed, mut worst) = (0, 0, 0, 0.0f64);
        for a in &audits {
            match &a.verdicts[i] {
                Verdict::Ok { error, .. } => {
                    ok += 1;
                    worst = worst.max(error / tol);
                }
                Verdict::Miss { error, .. } => {
                    missed += 1;
                    worst = worst.max(error / tol);
                }
                Verdict::Refused(_) => refused += 1,
            }
        }
        let evals: u64 = audits.iter().map(|a| a.evals[i]).sum();
        println!("| {tol:.0e} | {n} | {ok} | {refused} | {missed} | {worst:.2} | {evals} |");
    }
    for (a, (k, _)) in audits.iter().zip(&scenes) {
        for (v, tol) in a.verdicts.iter().zip(&tolerances) {
            match v {
                Verdict::Refused(why) => println!("scene {k} at {tol:.0e} refused: {why}"),
                Verdict::Miss { error, estimate } => println!(
                    "scene {k} at {tol:.0e} MISSED: error {error:.2e}, estimate {estimate:.2e} ({:.1}x low)",
                    error / estimate
                ),
                Verdict::Ok { .. } => {}
            }
        }
    }
}
