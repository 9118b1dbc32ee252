//! Where the error of the contact methods comes from: each way of treating a contact that opens
//! or closes inside a step, with a Nyström method of order 4 and of order 6, over steps from 0.1
//! down, on the standard scene and on sweep scenes drawn from F4, F7 coarse and F7 fine.
//!
//! Variants: `plain` leaves the kink to the method's quadrature; `corrected` integrates the
//! bond's force along its path (what `rk4-contact` / `rkn4-contact` / `rkn6-contact` do);
//! `located` ends every step where a contact opens or closes, so that no step contains a kink.
//! Against the reference (`rk4-contact` at dt = 0.001, with its state at t_end), each line gives
//! the largest error of R, T and E_tr over the scenes (worst and median), the largest state error
//! at t_end (max norm), force evaluations and wall time per scene; then the orders fitted to
//! the state errors over the steps.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example error_split [-- SCENES_PER_SWEEP]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;
use woodpile_bench::{drive_fixed, on_two_cores, standard_scene};
use woodpile_pipeline::Pipeline;
use woodpile_sim::energy::{energy_density, Fractions};
use woodpile_sim::integrate::{
    ContactMode, Method, MethodChoice, Rk4Fused, Rkn, RknTableau, Stepper, DPRKN6, NYSTROM4,
};
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{fitted_order, fixed_dt, tolerance};
use woodpile_stages::sampling::sampled_sweep_scenes;
use woodpile_stages::KINDS;

const STEPS: [f64; 6] = [0.2, 0.1, 0.07, 0.05, 0.025, 0.0125];

#[derive(Clone, Copy)]
enum Variant {
    Rk4Contact,
    Nystrom(usize, ContactMode),
}

const VARIANTS: [Variant; 7] = [
    Variant::Rk4Contact,
    Variant::Nystrom(4, ContactMode::Plain),
    Variant::Nystrom(4, ContactMode::Corrected),
    Variant::Nystrom(4, ContactMode::Located),
    Variant::Nystrom(6, ContactMode::Plain),
    Variant::Nystrom(6, ContactMode::Corrected),
    Variant::Nystrom(6, ContactMode::Located),
];

impl Variant {
    fn label(self) -> String {
        match self {
            Variant::Rk4Contact => "rk4 corrected".into(),
            Variant::Nystrom(order, mode) => format!("rkn{order} {mode:?}").to_lowercase(),
        }
    }

    fn stepper(self, scenario: &Scenario) -> Box<dyn Stepper> {
        let model = &scenario.model;
        fn rkn<const S: usize>(
            model: &woodpile_sim::Model,
            t: RknTableau<S>,
            mode: ContactMode,
        ) -> Box<dyn Stepper> {
            Box::new(Rkn::new(model, t, mode))
        }
        match self {
            Variant::Rk4Contact => Box::new(Rk4Fused::with_contact_events(model)),
            Variant::Nystrom(4, mode) => rkn(model, NYSTROM4, mode),
            Variant::Nystrom(_, mode) => rkn(model, DPRKN6, mode),
        }
    }
}

/// One run: fractions, final state, force evaluations, steps (cut steps included), seconds.
struct Run {
    fractions: Fractions,
    state: Vec<f64>,
    evals: u64,
    ms: f64,
}

fn run(variant: Variant, scenario: &Scenario, dt: f64) -> Option<Run> {
    let mut stepper = variant.stepper(scenario);
    let t0 = Instant::now();
    let (y, stats) = drive_fixed(
        scenario,
        stepper.as_mut(),
        (dt, scenario.sample_every),
        Some(1e-2),
    )
    .ok()?;
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    let model = &scenario.model;
    let mut density = vec![0.0; model.n_sites()];
    energy_density(model, scenario.t_end, &y, &mut density);
    Some(Run {
        fractions: Fractions::from_density(&density, scenario.region),
        state: y,
        evals: stats.rhs_evals,
        ms,
    })
}

/// Per scene: for each variant and step, (fraction error, state error, evals, ms).
type Errors = Vec<Vec<Option<(f64, f64, u64, f64)>>>;

fn measure(scenario: &Scenario) -> Errors {
    let reference = simulate(
        &Scenario {
            method: MethodChoice::Named(Method::Rk4Contact),
            accuracy: fixed_dt(0.001),
            ..scenario.clone()
        },
        &mut (),
    )
    .unwrap();
    VARIANTS
        .iter()
        .map(|&v| {
            STEPS
                .iter()
                .map(|&dt| {
                    let r = run(v, scenario, dt)?;
                    let state = r
                        .state
                        .iter()
                        .zip(&reference.final_state)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max);
                    let frac = r.fractions.largest_difference(&reference.fractions);
                    Some((frac, state, r.evals, r.ms))
                })
                .collect()
        })
        .collect()
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn report(group: &str, per_scene: &[&Errors]) {
    println!("\n### {group} ({} scenes)\n", per_scene.len());
    println!("| variant | dt | worst fraction error | median | worst state error | evals / scene | ms / scene |");
    println!("|---|---|---|---|---|---|---|");
    let mut orders = Vec::new();
    for (k, v) in VARIANTS.iter().enumerate() {
        let mut worst_states = Vec::new();
        for (j, dt) in STEPS.iter().enumerate() {
            let cells: Vec<_> = per_scene.iter().map(|e| e[k][j]).collect();
            if cells.iter().any(Option::is_none) {
                println!(
                    "| {} | {dt} | failed (drift or blow-up) | | | | |",
                    v.label()
                );
                continue;
            }
            let cells: Vec<_> = cells.into_iter().flatten().collect();
            let worst = cells.iter().map(|c| c.0).fold(0.0, f64::max);
            let med = median(cells.iter().map(|c| c.0).collect());
            let state = cells.iter().map(|c| c.1).fold(0.0, f64::max);
            let n = cells.len() as f64;
            let evals = cells.iter().map(|c| c.2 as f64).sum::<f64>() / n;
            let ms = cells.iter().map(|c| c.3).sum::<f64>() / n;
            worst_states.push((*dt, state));
            println!(
                "| {} | {dt} | {worst:.1e} | {med:.1e} | {state:.1e} | {evals:.0} | {ms:.2} |",
                v.label()
            );
        }
        if worst_states.len() >= 2 {
            let (dts, errs): (Vec<f64>, Vec<f64>) = worst_states.into_iter().unzip();
            orders.push(format!("{} {:.2}", v.label(), fitted_order(&dts, &errs)));
        }
    }
    println!(
        "\nOrders fitted to the worst state error: {}",
        orders.join(", ")
    );
}

fn main() {
    let per_sweep: usize = std::env::args().nth(1).map_or(4, |a| a.parse().unwrap());
    let mut scenes: Vec<(String, Scenario)> = vec![(
        "standard".into(),
        standard_scene(MethodChoice::Auto, tolerance(1e-6)),
    )];
    let pipeline = Pipeline::load("pipeline".as_ref(), KINDS).unwrap();
    scenes.extend(
        sampled_sweep_scenes(&pipeline, per_sweep)
            .unwrap()
            .into_iter()
            .filter(|(name, _)| name.starts_with("F4") || name.starts_with("F7")),
    );
    let errors = on_two_cores(&scenes, |(_, s)| measure(s));
    for (name, e) in scenes.iter().zip(&errors) {
        eprintln!("{}: rkn6 corrected dt=0.05 {:?}", name.0, e[5][1]);
    }
    for group in ["standard", "F4", "F7 coarse", "F7 fine"] {
        let members: Vec<&Errors> = scenes
            .iter()
            .zip(&errors)
            .filter(|((name, _), _)| name.starts_with(group))
            .map(|(_, e)| e)
            .collect();
        report(group, &members);
    }
}
