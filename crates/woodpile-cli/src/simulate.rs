//! `woodpile simulate SCENE.toml`: the contract of docs/scene.md. One JSON object on stdout, or one error
//! on stderr and a non-zero exit.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use serde_json::{json, Value};
use woodpile_scene::Scene;
use woodpile_sim::run::{simulate, Outcome};

use crate::Failure;

/// Arguments of `woodpile simulate`.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The scene file (TOML; see README "Scene files").
    scene: PathBuf,
    /// Indent the JSON for reading.
    #[arg(long)]
    pretty: bool,
}

pub(crate) fn run(args: &Args) -> Result<(), Failure> {
    let scene = woodpile_scene::load(&args.scene).map_err(Failure::input)?;
    let started = Instant::now();
    let outcome = simulate(&scene.scenario, &mut ())
        .with_context(|| format!("{}: simulation failed", args.scene.display()))
        .map_err(Failure::simulation)?;
    let wall_s = started.elapsed().as_secs_f64();
    let report = report(&scene, &outcome, wall_s);
    let text = if args.pretty {
        serde_json::to_string_pretty(&report)
    } else {
        serde_json::to_string(&report)
    };
    say!("{}", text.map_err(Failure::simulation)?);
    Ok(())
}

/// The JSON object: the contract's keys first, then what makes the number trustworthy and traceable.
fn report(scene: &Scene, out: &Outcome, wall_s: f64) -> Value {
    let f = out.fractions;
    let accuracy = scene.scenario.accuracy;
    let mut report = json!({
        "R": f.reflected,
        "T": f.transmitted,
        "E_tr": f.trapped,
        "E_initial": out.e_initial,
        "E_final": out.e_final,
        "method": out.plan.method.name(),
        "steps": out.stats.steps,
        "wall_s": wall_s,
        "requested_method": match scene.scenario.method {
            woodpile_sim::integrate::MethodChoice::Auto => "auto",
            woodpile_sim::integrate::MethodChoice::Named(m) => m.name(),
        },
        "dt": out.plan.dt(),
        "tolerance": accuracy.tolerance,
        "error_estimate": out.error_estimate,
        "rejected_steps": out.stats.rejected,
        "rhs_evals": out.stats.rhs_evals,
        "site_steps": out.stats.site_steps,
        "site_steps_full_chain": scene.scenario.model.n_sites() as u64 * (out.stats.steps + out.stats.rejected),
        "total_rhs_evals": out.total_rhs_evals,
        "energy_drift": if scene.scenario.model.is_time_dependent() { Value::Null } else { json!(out.stats.max_energy_drift) },
        "energy_conserved": !scene.scenario.model.is_time_dependent(),
        "normalisation": "E(t_end)",
        "region": scene.region_paper,
        "t_end": scene.scenario.t_end,
        "version": env!("CARGO_PKG_VERSION"),
    });
    if let Some(p) = &scene.physical {
        report["physical"] = json!({
            "length_scale_m": p.scales.length_m(),
            "time_scale_s": p.scales.time_s(),
            "velocity_scale_m_per_s": p.scales.velocity,
            "t_end_s": scene.scenario.t_end * p.scales.time_s(),
            "defects": p.defects,
        });
    }
    report
}
