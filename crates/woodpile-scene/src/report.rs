//! The JSON object of `woodpile simulate` (docs/scene.md): one scene's outcome, the contract's
//! keys first, then what makes the numbers trustworthy and traceable. The CLI prints it and
//! the Python package's `as_dict()` returns it, so the two can never disagree.

use serde_json::{json, Value};
use woodpile_sim::integrate::MethodChoice;
use woodpile_sim::simulation::{budget, Outcome};
use woodpile_sim::{Share, ShareSet};

use crate::Scene;

/// The report of `scene`'s `outcome`, which took `wall_s` seconds.
pub fn simulate_report(scene: &Scene, out: &Outcome, wall_s: f64) -> Value {
    let f = out.fractions;
    let scenario = &scene.scenario;
    // A dissipative chain's energy_drift is its ledger's, |E(t) + D(t) − E(0)| / E(0).
    let dissipative = scenario.model.is_dissipative();
    let mut report = json!({
        "E_initial": out.e_initial,
        "E_final": out.e_final,
        "method": out.plan.method.name(),
        "steps": out.stats.steps,
        "wall_s": wall_s,
        "requested_method": match scenario.method {
            MethodChoice::Auto => "auto",
            MethodChoice::Named(m) => m.name(),
        },
        "dt": out.plan.dt().map(|_| out.stats.max_step),
        "dt_requested": out.plan.dt(),
        "tolerance": scenario.accuracy.tolerance,
        "error_estimate": out.error_estimate,
        "rejected_steps": out.stats.rejected,
        "rhs_evals": out.stats.rhs_evals,
        "site_steps": out.stats.site_steps,
        "site_steps_full_chain": scenario.model.n_sites() as u64 * (out.stats.steps + out.stats.rejected),
        "total_rhs_evals": out.total_rhs_evals,
        "energy_drift": if scenario.model.is_time_dependent() { Value::Null } else { json!(out.stats.max_energy_drift) },
        // With losses, "conserved" is the ledger E(t) + D(t) = E(0), held to the drift bound
        // the run was held to (`auto`'s, or a named method's).
        "energy_conserved": match dissipative {
            true => out.stats.max_energy_drift <= out.plan.drift_limit,
            false => !scenario.model.is_time_dependent(),
        },
        "normalisation": if dissipative { "E(0)" } else { "E(t_end)" },
        "region": scene.region_paper,
        "t_end": scenario.t_end,
        "end_reached_at": out.stats.end_reached_at,
        "version": env!("CARGO_PKG_VERSION"),
    });
    // The shares (R, T, E_tr, and S and D where the scene has them); serde_json's map keeps
    // its keys sorted, so where they are added does not move them.
    for share in ShareSet::of(&scenario.model, &scenario.region).iter() {
        report[share.name()] = json!(unsigned_zero(share.of(&f)));
    }
    if let Some(p) = &scene.physical {
        report["physical"] = json!({
            "length_scale_m": p.scales.length_m(),
            "time_scale_s": p.scales.time_s(),
            "velocity_scale_m_per_s": p.scales.velocity,
            "t_end_s": scenario.t_end * p.scales.time_s(),
            "defects": p.defects,
        });
        for (name, value) in &p.derived {
            report["physical"][name] = json!(value);
        }
        // The model's scaled units, until `units_out::SiFactors::report` converts them.
        report["units"] = json!(crate::units_out::Units::Scaled.name());
    }
    report
}

/// The note for a run whose wave reached an end of the chain before `t_end`, naming the time:
/// its R and T then hold what that end sent back. `None` when it did not.
pub fn wall_note(scene: &Scene, out: &Outcome) -> Option<String> {
    let t_end = scene.scenario.t_end;
    let reached = out.stats.end_reached_at.filter(|&t| t < t_end)?;
    let (reached, t_end) = (time_text(scene, reached), time_text(scene, t_end));
    Some(format!(
        "the wave reached an end of the chain at t = {reached}, before t_end = {t_end}: R and T include what that end sent back (a longer chain, or an earlier t_end, keeps them apart)"
    ))
}

/// The scaled time `t` as a user of `scene` wrote it: in seconds for a `[physical]` scene
/// (its scaled value beside), else as the number it is.
fn time_text(scene: &Scene, t: f64) -> String {
    match &scene.physical {
        Some(p) => format!("{:.4e} s ({t:.4} in scaled time)", t * p.scales.time_s()),
        None => format!("{t}"),
    }
}

/// The note for a run `auto` forecasts to be long ([`budget::LONG_RUN_S`] for its first rung),
/// said before it starts, with what it will cost if the tolerance needs every halving.
pub fn cost_note(scene: &Scene) -> Option<String> {
    let f = budget::forecast(&scene.scenario)?;
    let long = f.first_rung_s > budget::LONG_RUN_S
        || (f.halvings_likely && f.whole_ladder_s > budget::LONG_RUN_S);
    let likely = match f.halvings_likely {
        true => " (likely: a contact dashpot's onset costs rk4-contact its order)",
        false => "",
    };
    long.then(|| {
        format!(
            "auto's first rung is two runs of about {:.2e} and {:.2e} steps over {} sites and resonators (step {:.2e}): roughly {} at the rate measured on woodpile's development machine, and up to {} if the tolerance needs every halving{likely}; a looser tolerance or a shorter t_end is faster",
            f.steps,
            f.steps / 2.0,
            f.sites,
            f.dt,
            duration(f.first_rung_s),
            duration(f.whole_ladder_s),
        )
    })
}

/// A share as printed: −0.0 (a sum of tiny cancelling terms) is 0, which is what it means.
fn unsigned_zero(share: f64) -> f64 {
    share + 0.0
}

/// `0.4 s`, `12 s`, `7 min`, `3.2 h`.
fn duration(seconds: f64) -> String {
    match seconds {
        s if s < 10.0 => format!("{s:.1} s"),
        s if s < 120.0 => format!("{s:.0} s"),
        s if s < 7200.0 => format!("{:.0} min", s / 60.0),
        s => format!("{:.1} h", s / 3600.0),
    }
}

/// What a refused `auto` keeps of its finest run, marked unverified: the fractions at `t_end`
/// (S and D where the scene has them), the step, and the last estimate, which did not meet
/// the tolerance. `woodpile simulate` prints it under `unverified` with exit 3, and Python's
/// `SimulationError.result` holds it.
pub fn unverified_report(scene: &Scene, finest: &woodpile_sim::Unverified) -> Value {
    let scenario = &scene.scenario;
    let mut report = json!({
        "dt": finest.dt,
        "error_estimate": finest.estimate.is_finite().then_some(finest.estimate),
        "tolerance": scenario.accuracy.tolerance,
        "verified": false,
    });
    // `Unverified::shares` holds the shares in `Share::ALL`'s order.
    let reported = ShareSet::of(&scenario.model, &scenario.region);
    for (share, value) in Share::ALL.into_iter().zip(finest.shares) {
        if reported.has(share) {
            report[share.name()] = json!(value);
        }
    }
    report
}

#[cfg(test)]
mod tests {
    use super::unsigned_zero;

    #[test]
    fn a_negative_zero_share_is_printed_as_zero() {
        assert_eq!(unsigned_zero(-0.0).to_bits(), 0.0_f64.to_bits());
        assert_eq!(serde_json::json!(unsigned_zero(-0.0)).to_string(), "0.0");
        assert_eq!(unsigned_zero(-1e-300), -1e-300);
        assert_eq!(unsigned_zero(0.25), 0.25);
    }
}
