//! What a run will cost, estimated before it starts, so that a scene which could never finish
//! (`t_end = 1e12`, `dt = 1e-300`, `tolerance = 1e-30`, a resonator of mass 1e-300) is refused
//! at once with the estimate instead of running for a minute into the driver's step budget.
//!
//! The estimate is a lower bound on the work: the number of steps of the run's first (finest)
//! plan, or of the stability limit for an adaptive method. `auto`'s verification runs add at
//! most a factor of about 3, and halvings only make it larger, so a scene refused here would
//! also have been refused by the driver, only later.

use super::{auto_first_step, Scenario};
use crate::error::{OverBudget, StepSetBy};
use crate::integrate::{intervals, MethodChoice, Plan, MAX_STEPS};
use crate::SimError;

/// Most samples one run may record: each sample keeps five numbers per observer, so a
/// million samples are 40 MB, far beyond any figure's resolution.
pub const MAX_SAMPLES: u64 = 1_000_000;

/// Refuses `scenario` when its samples or its steps exceed the budgets; the model, run
/// settings and tolerance must already be valid (a [`SimError`] otherwise).
pub fn check(scenario: &Scenario) -> Result<(), SimError> {
    let samples = (scenario.t_end / scenario.sample_every).ceil();
    if samples.is_nan() || samples > MAX_SAMPLES as f64 {
        return Err(OverBudget::Samples {
            samples,
            limit: MAX_SAMPLES,
        }
        .into());
    }
    let model = &scenario.model;
    let plan = Plan::choose(model, scenario.method, scenario.accuracy)?;
    let for_tolerance = Plan::tolerance_dt(plan.method, scenario.accuracy.tolerance);
    let (dt, set_by) = match (scenario.method, plan.dt()) {
        (MethodChoice::Auto, _) => {
            let dt = auto_first_step(scenario, &plan);
            (dt, cause(scenario, dt, for_tolerance))
        }
        (MethodChoice::Named(_), Some(dt)) if scenario.accuracy.dt.is_some() => (dt, StepSetBy::Dt),
        (MethodChoice::Named(_), Some(dt)) => (dt, cause(scenario, dt, for_tolerance)),
        // An adaptive method cannot step past its stability limit on the fastest resonator.
        (MethodChoice::Named(method), None) => {
            let energy = scenario.impact_energy();
            let omega = model
                .max_resonator_omega(energy)
                .max(model.max_contact_omega(energy));
            let dt = if omega > 0.0 {
                method.stability_limit() / omega
            } else {
                f64::INFINITY
            };
            (dt, cause(scenario, dt, f64::INFINITY))
        }
    };
    let steps = (scenario.t_end / dt).max(intervals(scenario.t_end, scenario.sample_every) as f64);
    if steps <= MAX_STEPS as f64 {
        Ok(())
    } else {
        Err(OverBudget::Steps {
            steps,
            dt,
            set_by,
            limit: MAX_STEPS,
        }
        .into())
    }
}

/// Whether `dt` is the tolerance's step (`for_tolerance`) or a resonator's cap, and which.
fn cause(scenario: &Scenario, dt: f64, for_tolerance: f64) -> StepSetBy {
    if dt >= for_tolerance * (1.0 - 1e-12) {
        return StepSetBy::Tolerance;
    }
    let energy = scenario.impact_energy();
    let model = &scenario.model;
    if model.max_contact_omega(energy) >= model.max_resonator_omega(energy) {
        return StepSetBy::Contacts;
    }
    let fastest = model
        .resonators()
        .iter()
        .enumerate()
        .map(|(i, r)| (i, r.omega_within(model.site_mass(r.site), energy)))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    match fastest {
        Some((i, _)) => StepSetBy::Resonator(i),
        None => StepSetBy::Tolerance,
    }
}
