//! "Simulate a scene, return its energy fractions" as one function: every caller (the CLI's
//! `simulate`, every pipeline sweep, the tests) goes through [`simulate`].
//!
//! `method = "auto"` is verified, not trusted: it runs the calibrated step `dt` and its double
//! `2 dt`, estimates the finer run's error by Richardson's rule for the method's observed order q
//! (3 for `rkn6-contact`, auto's method), |F(dt) - F(2 dt)| / (2^q - 1), and
//! accepts when that estimate is at most half the tolerance (less with a nonlinear resonator:
//! [`accepted_estimate`]); otherwise it halves `dt` and compares again. Stiff scenes (small eps, large p) thus get the steps they need
//! without a stiffness model having to foresee them.

pub mod budget;
mod ladder;
mod lanes;

pub use ladder::accepted_estimate;
use ladder::verified;
pub use lanes::{batch_size, simulate_batch};

use crate::energy::{Fractions, Region};
use crate::error::SimError;
use crate::integrate::{intervals, Accuracy, CancelOnly, MethodChoice, Observer, Plan, Stats};
use crate::model::Model;
use crate::observe::MAX_FIELD_VALUES;
use crate::share::Share;

/// Halvings `auto` tries before giving up.
const MAX_HALVINGS: u32 = 6;

/// A fully specified, validated simulation: model, initial impulse, horizon, region, method.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The chain and its resonators.
    pub model: Model,
    /// Site given the initial velocity (internal index).
    pub impulse_site: usize,
    /// The initial velocity V of that site.
    pub impulse_velocity: f64,
    /// Integrate over [0, t_end].
    pub t_end: f64,
    /// Region whose energy counts as trapped.
    pub region: Region,
    /// Requested method.
    pub method: MethodChoice,
    /// Requested accuracy.
    pub accuracy: Accuracy,
    /// Observers and checks run this often.
    pub sample_every: f64,
}

impl Scenario {
    /// The energy the impulse gives the chain, (1/2) m V^2: all the energy the run has.
    pub fn impact_energy(&self) -> f64 {
        0.5 * self.model.site_mass(self.impulse_site)
            * self.impulse_velocity
            * self.impulse_velocity
    }
}

/// What a successful run produced.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Fractions at t_end, normalised by E(t_end), or by E(0) for a dissipative chain (with D).
    pub fractions: Fractions,
    /// E(0).
    pub e_initial: f64,
    /// E(t_end).
    pub e_final: f64,
    /// The resolved method and step control of the reported run.
    pub plan: Plan,
    /// Cost and invariants of the reported run.
    pub stats: Stats,
    /// Cost of every run made, including `auto`'s verification runs.
    pub total_rhs_evals: u64,
    /// For `auto`: the Richardson estimate of the reported run's error, the largest change of
    /// R, T or E_tr between it and the run at twice its step divided by 2^q - 1 (q: the
    /// method's observed order).
    pub error_estimate: Option<f64>,
    /// The state at t_end (`[q, q']`).
    pub final_state: Vec<f64>,
}

/// Runs `scenario`, showing every sample of the reported run to `observer`. The outcome has
/// passed [`check_shares`]: numbers that fail it come back as [`SimError::Implausible`].
pub fn simulate<O: Observer + ?Sized>(
    scenario: &Scenario,
    observer: &mut O,
) -> Result<Outcome, SimError> {
    simulate_unchecked(scenario, observer).and_then(|out| check_shares(scenario, out))
}

/// The rule every reported run meets, whichever path made it (the CLI, a sweep's points, a
/// search's trials, Python): every share at t_end is finite, lies in [−a, 1 + a], and they
/// sum to 1 within a, where a is the run's allowance ([`share_allowance`]). A run that breaks
/// it (an overflow that left NaN, a ledger missing a term) is no result, however well its
/// steps went: it becomes [`SimError::Implausible`], which callers report and never write.
pub fn check_shares(scenario: &Scenario, out: Outcome) -> Result<Outcome, SimError> {
    let allowance = share_allowance(scenario, &out.plan);
    let f = &out.fractions;
    let shares = Share::ALL.map(|share| (share.name(), share.of(f)));
    let why = if let Some((name, x)) = shares.iter().find(|(_, x)| !x.is_finite()) {
        Some(format!("{name} is {x} (E(0) = {:e})", out.e_initial))
    } else if let Some((name, x)) = shares
        .iter()
        .find(|(_, x)| !(-allowance..=1.0 + allowance).contains(x))
    {
        Some(format!(
            "{name} = {x:e} lies outside [0, 1] by more than {allowance:.1e}"
        ))
    } else if (f.sum() - 1.0).abs() > allowance {
        Some(format!(
            "the shares sum to {:.15} instead of 1, off by more than {allowance:.1e}",
            f.sum()
        ))
    } else {
        None
    };
    match why {
        None => Ok(out),
        Some(why) => Err(SimError::Implausible { why }),
    }
}

/// How far the shares of a run by `plan` may stray from [0, 1] and from summing to 1: the
/// tolerance `auto` verified, or for a named method the energy drift its run was allowed
/// (the drift bound a named run is held to; at least the tolerance).
pub fn share_allowance(scenario: &Scenario, plan: &Plan) -> f64 {
    let tolerance = scenario.accuracy.tolerance;
    match scenario.method {
        MethodChoice::Auto => tolerance,
        MethodChoice::Named(_) => plan.drift_limit.max(tolerance),
    }
}

/// [`simulate`] without [`check_shares`]: for [`simulate_batch`], which checks every result
/// it returns once.
fn simulate_unchecked<O: Observer + ?Sized>(
    scenario: &Scenario,
    observer: &mut O,
) -> Result<Outcome, SimError> {
    let plan = Plan::choose(&scenario.model, scenario.method, scenario.accuracy)?;
    budget::check(scenario)?;
    match scenario.method {
        MethodChoice::Named(_) if scenario.model.is_time_dependent() => {
            step_checked(scenario, &plan, observer)
        }
        MethodChoice::Named(_) => run_plan(scenario, &plan, observer),
        MethodChoice::Auto => verified(scenario, plan, observer, None),
    }
}

/// The largest change of the fractions a fixed-step run on a time-dependent model may show
/// when its step is halved: the energy guard's allowance, which such a run cannot have.
pub const STEP_CHECK_LIMIT: f64 = 1e-3;

/// A named fixed-step run on a model whose kappa ramps, checked as energy cannot check it: run
/// again at half the step it took, and refuse the result when the fractions moved by more than
/// [`STEP_CHECK_LIMIT`]. The reported run is the one asked for; its error estimate is its own
/// (the pair's change times 2^q / (2^q − 1), the Richardson estimate of the coarser run). The
/// check run is cancelled with the reported one. An adaptive method controls its own error.
fn step_checked<O: Observer + ?Sized>(
    scenario: &Scenario,
    plan: &Plan,
    observer: &mut O,
) -> Result<Outcome, SimError> {
    let mut out = run_plan(scenario, plan, observer)?;
    if plan.dt().is_none() {
        return Ok(out);
    }
    // Half the step taken, which tiles every sample interval exactly as the taken one does.
    let half = 0.5 * out.stats.max_step;
    let check = run_plan(scenario, &plan.with_dt(half), &mut CancelOnly(&*observer))?;
    let change = out.fractions.largest_difference(&check.fractions);
    if change.is_nan() || change > STEP_CHECK_LIMIT {
        return Err(SimError::StepCheck {
            dt: half,
            change,
            limit: STEP_CHECK_LIMIT,
        });
    }
    let gain = 2f64.powf(plan.method.observed_order());
    out.error_estimate = Some(change * gain / (gain - 1.0));
    out.total_rhs_evals += check.total_rhs_evals;
    Ok(out)
}

/// The first (finest) step of `auto`'s ladder: the calibrated step for the tolerance, capped so
/// that every resonator stays resolved at the stiffest moment the impact's energy allows.
pub fn auto_first_step(scenario: &Scenario, plan: &Plan) -> f64 {
    plan.dt().unwrap_or(0.01).min(Plan::resolving_dt(
        &scenario.model,
        plan.method,
        scenario.impact_energy(),
    ))
}

fn run_plan<O: Observer + ?Sized>(
    scenario: &Scenario,
    plan: &Plan,
    observer: &mut O,
) -> Result<Outcome, SimError> {
    run_with_plan(scenario, plan, observer, true)
}

/// Runs `scenario` with an explicit `plan` (no `auto` ladder): for tools that adjust a plan
/// themselves, such as a reference run without a drift bound or a stability probe.
/// `active_window = false` works on the full chain every step (same bits, more work).
pub fn run_with_plan<O: Observer + ?Sized>(
    scenario: &Scenario,
    plan: &Plan,
    observer: &mut O,
    active_window: bool,
) -> Result<Outcome, SimError> {
    let model: &Model = &scenario.model;
    let (mut y, e_initial) = struck(scenario)?;
    let stats = plan.integrate_model(
        model,
        &mut y,
        (scenario.t_end, scenario.sample_every),
        observer,
        active_window,
    )?;
    Ok(outcome_of(scenario, plan, (y, e_initial), stats))
}

/// `scenario`'s chain at rest and struck: the state a run starts from, and its energy.
pub(crate) fn struck(scenario: &Scenario) -> Result<(Vec<f64>, f64), SimError> {
    let model = &scenario.model;
    let mut y = model.rest_state();
    model.apply_impulse(&mut y, scenario.impulse_site, scenario.impulse_velocity)?;
    let e_initial = crate::energy::total_energy(model, 0.0, &y);
    Ok((y, e_initial))
}

/// The fractions of a run of `scenario` that ended in state `y`, having started with the energy
/// `e_initial`, and the energy density they were read from.
pub(crate) fn end_fractions(
    scenario: &Scenario,
    y: &[f64],
    e_initial: f64,
) -> (Fractions, Vec<f64>) {
    let model = &scenario.model;
    let mut density = vec![0.0; model.n_sites()];
    let end = (scenario.t_end, y);
    let fractions = Fractions::of_state(model, end, scenario.region, e_initial, &mut density);
    (fractions, density)
}

/// The outcome of a run of `scenario` by `plan` that ended in state `y` with `stats`, having
/// started with the energy `e_initial`.
fn outcome_of(
    scenario: &Scenario,
    plan: &Plan,
    (y, e_initial): (Vec<f64>, f64),
    stats: Stats,
) -> Outcome {
    let (fractions, density) = end_fractions(scenario, &y, e_initial);
    let e_final = match scenario.model.is_dissipative() {
        true => density.iter().sum(),
        false => fractions.total,
    };
    Outcome {
        fractions,
        e_initial,
        e_final,
        plan: *plan,
        stats,
        total_rhs_evals: stats.rhs_evals,
        error_estimate: None,
        final_state: y,
    }
}

/// Refuses, before the run, a field of more than [`MAX_FIELD_VALUES`] values per array:
/// `width` sites at every sample of `scenario`. The reason names the sizes.
pub fn check_field_size(scenario: &Scenario, width: usize) -> Result<(), String> {
    // The resonator arrays are as wide as the chain has resonators.
    let width = width.max(scenario.model.resonators().len());
    let samples = intervals(scenario.t_end, scenario.sample_every) + 1;
    let values = samples.saturating_mul(width as u64);
    if values > MAX_FIELD_VALUES {
        return Err(format!(
            "a field {width} columns wide (sites or resonators) at {samples} samples is {values} values per array, more than the {MAX_FIELD_VALUES} it may have; keep fewer sites or sample less often"
        ));
    }
    Ok(())
}
