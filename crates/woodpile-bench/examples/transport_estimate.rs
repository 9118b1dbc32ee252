//! The issue's transported estimate, measured in its most favourable form before anything is
//! built: does the sum of a run's own local errors, each carried to t_end by the dynamics,
//! judge the fractions' error of the very run `auto` reports, where the Richardson pair is
//! erratic?
//!
//! Along `auto`'s fine run (its method at its first step, on the whole chain) a *shadow* run
//! takes the same steps and has each step's local error taken off as it goes. The change of
//! the fractions between the run and its shadow is what a perfect adjoint (or forward
//! error-transport) estimate fed by those local errors would compute, to first order, with no
//! transport error of its own (a shadow evaluates each step's first stage afresh, never
//! reusing forces of the state before its local error was taken off). Five shadows differ in
//! which local errors they are fed:
//! - *doubled*: every step is also taken as two half steps from the same state, and their
//!   difference times 2^6 / (2^6 − 1) is the step's local error (events included: both sides
//!   correct their contacts). Two extra runs' worth of work.
//! - *event steps* and *other steps*: the doubled local errors of the steps that corrected a
//!   contact, or of the rest only: where the error comes from.
//! - *rebased coarse*: every other state is stepped once by 2 h, and the two fine steps'
//!   local error is the difference times 2 / (2^7 − 2) (the smooth local order 7): what the
//!   coarse run's half a run of work would give as local errors; and the same with the factor
//!   of local order 3.5 wherever the pair, its coarse step or the step before corrected a
//!   contact.
//!
//! Each is set beside the run's error against the independent reference (`rk4-contact` at
//! dt = 2.5e-4) and beside `auto`'s Richardson estimate from the run at 2 dt, on the scenes
//! of the linear audit (`testing::linear_audit_scene`), where that estimate misses.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example transport_estimate [-- SCENES SEED TOL]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::{at_fixed_step, auto_first_step_at, on_two_cores};
use woodpile_sim::energy::Fractions;
use woodpile_sim::integrate::{
    intervals, ContactMode, Method, Plan, Rkn, StepSpan, Stepper, DPRKN6,
};
use woodpile_sim::model::{Model, Window};
use woodpile_sim::simulation::{accepted_estimate, Scenario};
use woodpile_sim::testing::{
    linear_audit_scene, reference_fractions, tolerance, Lcg, AUDIT_REFERENCE_DT,
};

/// The shadows, in the order of [`Row::shadows`].
const SHADOWS: [&str; 5] = [
    "doubled",
    "event steps",
    "other steps",
    "rebased coarse",
    "rebased, rough 3.5",
];

/// One scene at one tolerance.
struct Row {
    /// The fine run's error against the reference.
    error: f64,
    /// `auto`'s Richardson estimate, from the run at 2 dt.
    richardson: f64,
    /// Each shadow's estimate (the fractions' change between the run and it).
    shadows: [f64; 5],
    /// The largest estimate `auto` accepts at this tolerance.
    accepted: f64,
    /// This run's fractions against `simulate`'s at the same step (0: the same run).
    same_run: f64,
    /// The share of steps that corrected a contact.
    event_share: f64,
}

fn stepper(model: &Model, method: Method) -> Rkn<6> {
    let rkn = Rkn::new(model, DPRKN6, ContactMode::Corrected);
    match method {
        Method::Erkn6Contact => rkn.with_exact_resonators(model, "erkn6-contact"),
        _ => rkn,
    }
}

/// Subtracts `scale` times (`a` − `b`) from `w`.
fn take_off(w: &mut [f64], (a, b): (&[f64], &[f64]), scale: f64) {
    for ((w, a), b) in w.iter_mut().zip(a).zip(b) {
        *w -= (a - b) * scale;
    }
}

/// The run at `dt` (whole chain), its shadows' final states and the share of event steps.
fn run_and_shadows(scene: &Scenario, method: Method, dt: f64) -> (Vec<f64>, [Vec<f64>; 5], f64) {
    let model = &scene.model;
    let mut y = model.rest_state();
    model
        .apply_impulse(&mut y, scene.impulse_site, scene.impulse_velocity)
        .unwrap();
    let mut run = stepper(model, method);
    let mut w: [Vec<f64>; 5] = std::array::from_fn(|_| y.clone());
    let mut shadow: [Rkn<6>; 5] = std::array::from_fn(|_| run.clone());
    let mut coarse = y.clone();
    // Whether the pair of fine steps being judged, its coarse step or the step before it
    // corrected a contact: its local order is then low (about 2.5 where a kink is inside).
    let (mut rough, mut last_event) = (false, false);
    let (window, n_intervals) = (
        Window::full(model),
        intervals(scene.t_end, scene.sample_every),
    );
    let (mut t, mut steps, mut event_steps) = (0.0, 0u64, 0u64);
    for k in 1..=n_intervals {
        let target = match k == n_intervals {
            true => scene.t_end,
            false => k as f64 * scene.sample_every,
        };
        let n_steps = ((target - t) / dt - 1e-9).ceil().max(1.0) as u64;
        let h = (target - t) / n_steps as f64;
        for i in 0..n_steps {
            let span = |t: f64, h: f64| StepSpan { t, h, window };
            if i % 2 == 0 && i + 1 < n_steps {
                coarse.clone_from(&y);
                let mut long = run.clone();
                long.step(model, &mut coarse, span(t, 2.0 * h));
                rough = last_event || long.contact_events() > run.contact_events();
            }
            let (mut halves, mut z) = (run.clone(), y.clone());
            halves.step(model, &mut z, span(t, 0.5 * h));
            halves.step(model, &mut z, span(t + 0.5 * h, 0.5 * h));
            let events = run.contact_events();
            run.step(model, &mut y, span(t, h));
            let event = run.contact_events() > events;
            (steps, event_steps) = (steps + 1, event_steps + u64::from(event));
            rough |= event;
            last_event = event;
            for (m, (w, shadow)) in w.iter_mut().zip(&mut shadow).enumerate() {
                shadow.step(model, w, span(t, h));
                match m {
                    0 => take_off(w, (&y, &z), 64.0 / 63.0),
                    1 | 2 if (m == 1) == event => take_off(w, (&y, &z), 64.0 / 63.0),
                    3 if i % 2 == 1 => take_off(w, (&y, &coarse), 2.0 / 126.0),
                    4 if i % 2 == 1 => {
                        let order = if rough { 3.5f64 } else { 7.0 };
                        take_off(w, (&y, &coarse), 2.0 / (2f64.powf(order) - 2.0));
                    }
                    _ => {}
                }
                shadow.forget_last_stage();
            }
            t = if i + 1 == n_steps { target } else { t + h };
        }
    }
    (y, w, event_steps as f64 / steps as f64)
}

fn measure(scene: &Scenario, tol: f64) -> Option<Row> {
    if scene.model.is_time_dependent() {
        return None;
    }
    let dt = auto_first_step_at(scene, tol)?;
    let at_tol = Scenario {
        accuracy: tolerance(tol),
        ..scene.clone()
    };
    let method = Plan::choose(&at_tol.model, at_tol.method, at_tol.accuracy)
        .ok()?
        .method;
    let fine = at_fixed_step(scene, method, dt)?;
    let coarse = at_fixed_step(scene, method, 2.0 * dt)?;
    let reference = reference_fractions(scene, AUDIT_REFERENCE_DT).ok()?;
    let (y, w, event_share) = run_and_shadows(scene, method, dt);
    let e0 = fine.e_initial;
    let mut density = vec![0.0; scene.model.n_sites()];
    let mut fractions = |y: &[f64]| {
        let end = (scene.t_end, y);
        Fractions::of_state(&scene.model, end, scene.region, e0, &mut density)
    };
    let run = fractions(&y);
    Some(Row {
        error: fine.fractions.largest_difference(&reference),
        richardson: fine.fractions.largest_difference(&coarse.fractions) / 7.0,
        shadows: std::array::from_fn(|m| run.largest_difference(&fractions(&w[m]))),
        accepted: accepted_estimate(&scene.model, tol),
        same_run: run.largest_difference(&fine.fractions),
        event_share,
    })
}

/// Smallest, 10%, median, 90% and largest of `v`.
fn quantiles(mut v: Vec<f64>) -> String {
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    let qs = [0.0, 0.1, 0.5, 0.9, 1.0].map(|q| format!("{:.2}", at(q)));
    qs.join(", ")
}

fn summary(rows: &[&Row], tol: f64, label: &str) {
    println!("{label} ({} scenes): error / estimate, smallest, 10%, median, 90%, largest; runs accepted that miss", rows.len());
    if rows.is_empty() {
        return;
    }
    let judge = |estimate: &dyn Fn(&Row) -> f64, name: &str| {
        let ratios = rows.iter().map(|r| r.error / estimate(r)).collect();
        let misses = rows
            .iter()
            .filter(|r| estimate(r) <= r.accepted && r.error > tol)
            .count();
        println!("  {name:16} {}; {misses}", quantiles(ratios));
    };
    judge(&|r| r.richardson, "richardson");
    for (m, name) in SHADOWS.iter().enumerate() {
        judge(&|r| r.shadows[m], name);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map_or(60, |a| a.parse().unwrap());
    let seed: u64 = args.get(1).map_or(2026, |a| a.parse().unwrap());
    let tol: f64 = args.get(2).map_or(1e-6, |a| a.parse().unwrap());
    let mut rng = Lcg(seed);
    let scenes: Vec<Scenario> = (0..n).map(|_| linear_audit_scene(&mut rng)).collect();
    let rows = on_two_cores(&scenes, |s| measure(s, tol));
    println!(
        "scene error richardson {} event-step-share same-run",
        SHADOWS.join(" / ")
    );
    for (k, r) in rows.iter().enumerate() {
        if let Some(r) = r {
            let shadows = r.shadows.map(|e| format!("{e:.2e}")).join(" ");
            println!(
                "{k:4} {:.2e} {:.2e} {shadows} {:.2} {:.0e}",
                r.error, r.richardson, r.event_share, r.same_run
            );
        }
    }
    let kept: Vec<&Row> = rows.iter().flatten().collect();
    summary(&kept, tol, "all scenes");
    let near: Vec<&Row> = kept
        .iter()
        .copied()
        .filter(|r| r.error > 0.1 * tol)
        .collect();
    summary(&near, tol, "errors above a tenth of the tolerance");
}
