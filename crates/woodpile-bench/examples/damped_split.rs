//! A lever for damped chains, measured: the linear losses that act on velocities alone
//! (ground damping, resonator dashpots) integrated exactly, half a step before and half after
//! the conservative chain's `rkn6-contact` step with its contact events (Strang splitting).
//! Positions are untouched by the exact flows, so the Nyström step keeps its force reuse and
//! its event corrections; D is the kinetic energy the flows remove, exactly.
//!
//! For each damped row of the standard scene it prints, per fixed step, the split run's error
//! against the independent reference, its wall time, and the error's fall per halving, next to
//! what `auto` pays today (`rk4-contact`).
//!
//! ```text
//! cargo run --release -p woodpile-bench --example damped_split
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;
use woodpile_bench::independent::reference;
use woodpile_bench::standard_scene_with;
use woodpile_sim::energy::{energy_density, Fractions};
use woodpile_sim::integrate::{
    drive, ContactMode, DriveConfig, Rkn, StepControl, StepOutcome, StepSpan, Stepper, DPRKN6,
};
use woodpile_sim::model::Model;
use woodpile_sim::simulation::{simulate, Scenario};

/// A resonator's dashpot: host, its own index among the degrees of freedom, c, and masses.
struct Dashpot {
    host: usize,
    inner: usize,
    c: f64,
    masses: (f64, f64),
}

/// The conservative step between two exact half-flows of the linear losses.
struct Split<'a> {
    inner: Box<dyn Stepper>,
    ground: f64,
    dashpots: Vec<Dashpot>,
    masses: &'a [f64],
    n_dof: usize,
    dissipated: f64,
    /// exp(-g h / m) per site for the half-step `h` it was computed for: steps repeat.
    ground_factor: (f64, Vec<f64>),
}

impl Split<'_> {
    /// The exact flow of ground damping and the resonator dashpots over `h`, both halves of a
    /// symmetric composition (`reverse` applies them in the opposite order).
    fn losses(&mut self, y: &mut [f64], h: f64, reverse: bool) {
        match reverse {
            false => {
                self.ground_flow(y, h);
                self.dashpot_flow(y, h);
            }
            true => {
                self.dashpot_flow(y, h);
                self.ground_flow(y, h);
            }
        }
    }

    fn ground_flow(&mut self, y: &mut [f64], h: f64) {
        if self.ground == 0.0 {
            return;
        }
        if self.ground_factor.0 != h {
            let decay = self.masses.iter().map(|m| (-self.ground * h / m).exp());
            self.ground_factor = (h, decay.collect());
        }
        for (site, (&m, &decay)) in self.masses.iter().zip(&self.ground_factor.1).enumerate() {
            let v = &mut y[self.n_dof + site];
            if *v == 0.0 {
                continue; // At rest ahead of the wave.
            }
            let after = *v * decay;
            self.dissipated += 0.5 * m * (*v * *v - after * after);
            *v = after;
        }
    }

    fn dashpot_flow(&mut self, y: &mut [f64], h: f64) {
        for d in &self.dashpots {
            let (m, e) = d.masses;
            let (vh, vr) = (y[self.n_dof + d.host], y[self.n_dof + d.inner]);
            let centre = (m * vh + e * vr) / (m + e);
            let w = (vh - vr) * (-d.c * (1.0 / m + 1.0 / e) * h).exp();
            let (nh, nr) = (centre + e / (m + e) * w, centre - m / (m + e) * w);
            self.dissipated += 0.5 * (m * (vh * vh - nh * nh) + e * (vr * vr - nr * nr));
            y[self.n_dof + d.host] = nh;
            y[self.n_dof + d.inner] = nr;
        }
    }
}

impl Stepper for Split<'_> {
    fn name(&self) -> &'static str {
        "rkn6-contact split"
    }

    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        self.losses(y, 0.5 * span.h, false);
        let out = self.inner.step(model, y, span);
        self.losses(y, 0.5 * span.h, true);
        out
    }

    fn reach(&self) -> usize {
        self.inner.reach()
    }

    fn rhs_evals(&self) -> u64 {
        self.inner.rhs_evals()
    }
}

/// `scene` by the split method at step `dt`: its fractions and wall time in ms.
fn split_run(scene: &Scenario, dt: f64) -> (Fractions, f64) {
    let damped = &scene.model;
    let n = damped.n_sites();
    let masses: Vec<f64> = (0..n).map(|i| damped.site_mass(i)).collect();
    let conservative = Model::with_masses(
        n,
        damped.boundary(),
        damped.resonators().to_vec(),
        Some(masses.clone()),
    )
    .unwrap();
    let damping = damped.damping().unwrap();
    let clock = Instant::now();
    let mut split = Split {
        inner: Box::new(Rkn::new(&conservative, DPRKN6, ContactMode::Corrected)),
        ground: damping.ground,
        dashpots: damped
            .resonators()
            .iter()
            .enumerate()
            .map(|(j, r)| Dashpot {
                host: r.site,
                inner: n + j,
                c: damping.resonator(j),
                masses: (masses[r.site], r.eps),
            })
            .filter(|d| d.c > 0.0)
            .collect(),
        masses: &masses,
        n_dof: conservative.n_dof(),
        dissipated: 0.0,
        ground_factor: (f64::NAN, Vec::new()),
    };
    let mut y = conservative.rest_state();
    conservative
        .apply_impulse(&mut y, scene.impulse_site, scene.impulse_velocity)
        .unwrap();
    let cfg = DriveConfig {
        t_end: scene.t_end,
        sample_every: scene.sample_every,
        control: StepControl::Fixed { dt },
        max_steps: u64::MAX,
        energy_drift_limit: None,
        active_window: true,
    };
    drive(&conservative, &mut split, &mut y, &cfg, &mut ()).unwrap();
    let mut density = vec![0.0; n];
    energy_density(&conservative, scene.t_end, &y, &mut density);
    let fractions = Fractions::of_ledger(
        &density,
        scene.region,
        split.dissipated,
        scene.impact_energy(),
    );
    (fractions, clock.elapsed().as_secs_f64() * 1e3)
}

fn main() {
    let undamped = standard_scene_with("", "");
    let clock = Instant::now();
    simulate(&undamped, &mut ()).unwrap();
    let undamped_ms = clock.elapsed().as_secs_f64() * 1e3;
    println!("undamped, auto at 1e-8: {undamped_ms:.1} ms\n");
    let rows = [
        (
            "resonator quality_factor = 300",
            standard_scene_with("quality_factor = 300.0", ""),
        ),
        (
            "[damping] ground = 0.001",
            standard_scene_with("", "[damping]\nground = 0.001"),
        ),
        (
            "[damping] ground = 0.01",
            standard_scene_with("", "[damping]\nground = 0.01"),
        ),
    ];
    for (name, scene) in &rows {
        let exact = reference(scene, 1e-13).unwrap().fractions;
        let clock = Instant::now();
        let auto = simulate(scene, &mut ()).unwrap();
        let auto_ms = clock.elapsed().as_secs_f64() * 1e3;
        println!(
            "{name}: auto ({}) {auto_ms:.1} ms, {:.1}x, error {:.1e}",
            auto.plan.method.name(),
            auto_ms / undamped_ms,
            auto.fractions.largest_difference(&exact)
        );
        println!("| dt | error | fall per halving | ms | against undamped auto |");
        println!("|---|---|---|---|---|");
        let mut previous: Option<f64> = None;
        for dt in [0.04, 0.02, 0.01, 0.005, 0.0025] {
            let (f, ms) = split_run(scene, dt);
            let error = f.largest_difference(&exact);
            let fall = previous.map_or(String::from("–"), |p| format!("{:.1}", p / error));
            println!(
                "| {dt} | {error:.1e} | {fall} | {ms:.1} | {:.1}x |",
                ms / undamped_ms
            );
            previous = Some(error);
        }
        println!();
    }
}
