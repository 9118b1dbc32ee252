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
use crate::integrate::{intervals, Method, MethodChoice, Plan, MAX_STEPS};
use crate::SimError;

/// Seconds one step of one site costs `auto` on a chain whose moving window spans it, as
/// measured on the development machine (a 2-core VM; `rkn6-contact`, five force evaluations
/// a step): the 401-site chain with three nonlinear resonators over t = 1500 took 33 s for
/// 3.6e9 site-steps. A narrower window (a short run on a long chain) costs less, so forecasts
/// made with it are upper bounds, within a factor of a few of any recent machine.
pub const SECONDS_PER_SITE_STEP: f64 = 9e-9;

/// Seconds one step of one site costs `auto` on a chain whose forces depend on velocities
/// (`rk4-contact` over the damped force: four evaluations a step, each with its dashpots), as
/// measured like [`SECONDS_PER_SITE_STEP`]: 4.1e-8 on the standard scene with a linear contact
/// dashpot of 0.05, 3.6e-8 on a 61-site chain with one of 1000.
pub const DAMPED_SECONDS_PER_SITE_STEP: f64 = 4e-8;

/// `auto`'s first-rung runs cost less than this, in the forecast, without a word: longer ones
/// are announced before they start.
pub const LONG_RUN_S: f64 = 10.0;

/// What `auto` will spend, forecast before it starts from its first step and the chain's size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forecast {
    /// The first rung's step.
    pub dt: f64,
    /// Steps of the first rung's fine run.
    pub steps: f64,
    /// Sites and resonators the steps move.
    pub sites: usize,
    /// Seconds of the first rung (its runs at dt and 2 dt), at [`SECONDS_PER_SITE_STEP`].
    pub first_rung_s: f64,
    /// Seconds of the whole ladder, should every halving be needed (each rung costs twice the
    /// one before).
    pub whole_ladder_s: f64,
    /// Whether the halvings are likely: a contact dashpot switches on with its contact, a
    /// kink `rk4-contact` steps through at a reduced order, and `auto` then needs most rungs
    /// (the 61-site chain above needed all six at 1e-8).
    pub halvings_likely: bool,
}

/// `auto`'s forecast for `scenario` (`None` for a named method: it runs once, as asked).
pub fn forecast(scenario: &Scenario) -> Option<Forecast> {
    if scenario.method != MethodChoice::Auto {
        return None;
    }
    let plan = Plan::choose(&scenario.model, scenario.method, scenario.accuracy).ok()?;
    let dt = auto_first_step(scenario, &plan);
    let steps = (scenario.t_end / dt).max(intervals(scenario.t_end, scenario.sample_every) as f64);
    let sites = scenario.model.n_dof();
    let model = &scenario.model;
    // `rkn6-split` steps the conservative chain, its exact flows a few products per site.
    let per_site_step = match model.is_dissipative() && plan.method != Method::Rkn6Split {
        true => DAMPED_SECONDS_PER_SITE_STEP,
        false => SECONDS_PER_SITE_STEP,
    };
    let rung = 1.5 * steps * sites as f64 * per_site_step;
    let rungs = f64::from(super::MAX_HALVINGS + 1);
    Some(Forecast {
        dt,
        steps,
        sites,
        first_rung_s: rung,
        // The coarse run once, then fine runs at dt, dt/2, ...: 0.5 + (2^rungs - 1) first-rung
        // fine runs of the first rung's 1.5.
        whole_ladder_s: rung / 1.5 * (0.5 + 2f64.powf(rungs) - 1.0),
        halvings_likely: halvings_likely(model),
    })
}

/// Whether `auto`'s halvings are likely on `model` ([`Forecast::halvings_likely`]): it has a
/// contact dashpot.
fn halvings_likely(model: &crate::Model) -> bool {
    model.damping().is_some_and(|d| d.has_contact_dashpot())
}

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
            (dt, cause(scenario, plan.method, dt, for_tolerance))
        }
        (MethodChoice::Named(_), Some(dt)) if scenario.accuracy.dt.is_some() => (dt, StepSetBy::Dt),
        (MethodChoice::Named(_), Some(dt)) => (dt, cause(scenario, plan.method, dt, for_tolerance)),
        // An adaptive method cannot step past its stability limit on the fastest resonator.
        (MethodChoice::Named(method), None) => {
            let energy = scenario.impact_energy();
            let omega = model
                .max_resonator_omega(energy, false)
                .max(model.max_contact_omega(energy));
            let dt = if omega > 0.0 {
                method.stability_limit() / omega
            } else {
                f64::INFINITY
            };
            (dt, cause(scenario, plan.method, dt, f64::INFINITY))
        }
    };
    let steps = (scenario.t_end / dt).max(intervals(scenario.t_end, scenario.sample_every) as f64);
    if steps > MAX_STEPS as f64 {
        return Err(OverBudget::Steps {
            steps,
            dt,
            set_by,
            limit: MAX_STEPS,
        }
        .into());
    }
    finest_rung_affordable(scenario, dt, steps)
}

/// Refuses an `auto` run whose halvings are likely ([`Forecast::halvings_likely`]) when its
/// finest rung would take more steps than the budget: the ladder would otherwise spend every
/// rung before it (half the finest's steps, then a quarter, ...) to be stopped at the last.
fn finest_rung_affordable(scenario: &Scenario, dt: f64, steps: f64) -> Result<(), SimError> {
    let likely = scenario.method == MethodChoice::Auto && halvings_likely(&scenario.model);
    let halving = 2f64.powi(super::MAX_HALVINGS as i32);
    if !likely || steps * halving <= MAX_STEPS as f64 {
        return Ok(());
    }
    Err(OverBudget::Steps {
        steps: steps * halving,
        dt: dt / halving,
        set_by: StepSetBy::DashpotOnsets,
        limit: MAX_STEPS,
    }
    .into())
}

/// Whether `dt` is the tolerance's step (`for_tolerance`) or a resonator's cap, and which.
fn cause(scenario: &Scenario, method: Method, dt: f64, for_tolerance: f64) -> StepSetBy {
    if dt >= for_tolerance * (1.0 - 1e-12) {
        return StepSetBy::Tolerance;
    }
    let energy = scenario.impact_energy();
    let model = &scenario.model;
    // The resonator whose cap is the smallest: a harmonic one that `method` integrates
    // exactly is capped less tightly than one it steps through.
    let tightest = (0..model.resonators().len())
        .map(|j| (j, Plan::resonator_dt(model, method, j, energy)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    let contacts = Plan::contact_dt(model, energy);
    let dissipation = model
        .fastest_dissipation(energy)
        .map(|(which, _)| (which, Plan::dissipation_dt(model, energy)));
    match (tightest, dissipation) {
        (Some((j, cap)), d) if cap < contacts && d.is_none_or(|(_, dd)| cap <= dd) => {
            StepSetBy::Resonator(j)
        }
        (_, Some((which, dd))) if dd < contacts => StepSetBy::Dissipation(which),
        _ => StepSetBy::Contacts,
    }
}
