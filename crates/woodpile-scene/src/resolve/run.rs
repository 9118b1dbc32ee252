//! `[run]` and `[fractions]`: the horizon, the method and its accuracy, the sampling, and the
//! region whose energy counts as trapped; and the budget check that refuses an endless run.

use woodpile_sim::damped_force::Dissipator;
use woodpile_sim::integrate::MAX_STEPS;
use woodpile_sim::integrate::{Accuracy, Method, MethodChoice};
use woodpile_sim::simulation::Scenario;
use woodpile_sim::SimError;
use woodpile_sim::{OverBudget, StepSetBy};

use super::chain::Layout;
use super::check::{invalid, positive, Invalid};
use super::physical::Si;
use super::time;
use crate::raw;

const DEFAULT_T_END: f64 = 150.0;
const DEFAULT_TOLERANCE: f64 = 1e-8;
const DEFAULT_SAMPLE_EVERY: f64 = 1.0;
/// The loosest tolerance: a tenth of the fractions' whole range.
const MAX_TOLERANCE: f64 = 0.1;
/// Smallest tolerance accepted: the fractions are sums of hundreds of energies, each known to
/// about 1e-16 relative, so a finer target could never be verified.
const MIN_TOLERANCE: f64 = 1e-13;

/// What `[run]` asks for.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RunSettings {
    pub t_end: f64,
    pub method: MethodChoice,
    pub accuracy: Accuracy,
    pub sample_every: f64,
    /// Whether the file gave `sample_every` (then it, not `t_end`, is named when samples run over).
    pub sample_every_given: bool,
}

/// `run.tolerance`, between what a double can verify and what says anything about a share.
fn tolerance(given: Option<f64>) -> Result<f64, Invalid> {
    let tolerance = positive("run.tolerance", given.unwrap_or(DEFAULT_TOLERANCE))?;
    if tolerance > MAX_TOLERANCE {
        return Err(invalid(
            "run.tolerance",
            format!("{tolerance:e} is above {MAX_TOLERANCE:e}: fractions lie between 0 and 1, so a looser bound says nothing"),
        ));
    }
    if tolerance < MIN_TOLERANCE {
        return Err(invalid(
            "run.tolerance",
            format!("{tolerance:e} is below {MIN_TOLERANCE:e}: fractions summed over a chain in double precision cannot be verified that closely"),
        ));
    }
    Ok(tolerance)
}

/// The `[run]` table with its defaults; times with a unit are converted with `si`'s scale.
pub(crate) fn settings(run: Option<raw::Run>, si: Option<&Si>) -> Result<RunSettings, Invalid> {
    let run = run.unwrap_or(raw::Run {
        t_end: None,
        method: None,
        tolerance: None,
        dt: None,
        sample_every: None,
    });
    let time = |key: &str, value: &Option<raw::Time>| {
        value.as_ref().map(|v| time::scaled(key, v, si)).transpose()
    };
    let t_end = positive(
        "run.t_end",
        time("run.t_end", &run.t_end)?.unwrap_or(DEFAULT_T_END),
    )?;
    let name = run.method.as_deref().unwrap_or("auto");
    let method = MethodChoice::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
        invalid(
            "run.method",
            format!(
                "unknown method \"{name}\"; expected \"auto\" or one of {}",
                names.join(", ")
            ),
        )
    })?;
    let tolerance = tolerance(run.tolerance)?;
    let dt = time("run.dt", &run.dt)?
        .map(|dt| positive("run.dt", dt))
        .transpose()?;
    if let Some(dt) = dt {
        match method {
            MethodChoice::Auto => {
                return Err(invalid(
                    "run.dt",
                    "needs a fixed-step method; \"auto\" chooses its own step from run.tolerance",
                ))
            }
            MethodChoice::Named(m) if m.is_adaptive() => {
                return Err(invalid(
                    "run.dt",
                    format!(
                        "method \"{}\" is adaptive and takes run.tolerance, not dt",
                        m.name()
                    ),
                ))
            }
            _ if dt > t_end => {
                return Err(invalid(
                    "run.dt",
                    format!("{dt} is longer than run.t_end = {t_end}"),
                ))
            }
            _ => {}
        }
    }
    let sample_every = positive(
        "run.sample_every",
        time("run.sample_every", &run.sample_every)?.unwrap_or(DEFAULT_SAMPLE_EVERY),
    )?;
    Ok(RunSettings {
        t_end,
        method,
        accuracy: Accuracy {
            tolerance,
            tolerance_explicit: run.tolerance.is_some(),
            dt,
        },
        sample_every,
        sample_every_given: run.sample_every.is_some(),
    })
}

/// `fractions.region` in paper sites (default: the paper's, around the defects) and as the
/// simulator's indices.
pub(crate) fn region(
    fractions: Option<raw::FractionsTable>,
    defects: &[raw::Defect],
    layout: &Layout,
) -> Result<([i64; 2], (usize, usize)), Invalid> {
    let region_paper = match fractions.and_then(|f| f.region) {
        Some(r) => {
            let [lo, hi] = r[..] else {
                return Err(invalid(
                    "fractions.region",
                    format!("must be [lo, hi], got {} values", r.len()),
                ));
            };
            if lo > hi {
                return Err(invalid(
                    "fractions.region",
                    format!("lo = {lo} is greater than hi = {hi}"),
                ));
            }
            [lo, hi]
        }
        None => default_region(defects, layout),
    };
    let lo = layout.index("fractions.region", region_paper[0])?;
    let hi = layout.index("fractions.region", region_paper[1])?;
    Ok((region_paper, (lo, hi)))
}

/// Refuses a scene whose run could never finish within the simulator's budgets, naming the key
/// that makes it so (`t_end` when even the largest step of any method would be too many).
pub(crate) fn within_budget(
    scenario: &Scenario,
    sample_every_given: bool,
    keys: &StepKeys<'_>,
) -> Result<(), Invalid> {
    let error = match woodpile_sim::simulation::budget::check(scenario) {
        Ok(()) => return Ok(()),
        Err(SimError::OverBudget(over)) => over,
        Err(e @ SimError::VelocityForces { .. }) => {
            return Err(invalid("run.method", e.to_string()))
        }
        Err(other) => return Err(invalid("run", other.to_string())),
    };
    let longest_step = 0.25;
    let key = match &error {
        OverBudget::Samples { .. } if sample_every_given => "run.sample_every".to_string(),
        OverBudget::Samples { .. } => "run.t_end".to_string(),
        OverBudget::Steps { .. } if scenario.t_end / longest_step > MAX_STEPS as f64 => {
            "run.t_end".to_string()
        }
        OverBudget::Steps { set_by, .. } => match set_by {
            StepSetBy::Dt => "run.dt".to_string(),
            StepSetBy::Tolerance => "run.tolerance".to_string(),
            StepSetBy::Resonator(i) => format!("defect[{i}]"),
            StepSetBy::Contacts => "chain".to_string(),
            StepSetBy::Dissipation(which) => dissipator_key(*which, keys),
            StepSetBy::DashpotOnsets => keys.contact_dashpots.first_acting().to_string(),
        },
    };
    Err(invalid(key, error.to_string()))
}

/// What a step-budget refusal blames, read from the scene file before it is taken apart.
pub(crate) struct StepKeys<'a> {
    /// The defects, whose dashpots or quality factors may set the step.
    pub defects: &'a [raw::Defect],
    /// The keys that declare the contacts' dashpots ([`ContactDashpots::of`]).
    pub contact_dashpots: ContactDashpots,
}

/// Which key declares each contact's dashpot: a segment's own on the contacts between its
/// sites, the striker's own on its contact with the first site, `[damping]`'s elsewhere, as
/// `resolve::damping` gives each bond its γ (later segments over earlier ones, the striker
/// last). Kept as the few bond ranges that have their own, not a key per bond: a chain may
/// have millions.
pub(crate) struct ContactDashpots {
    /// `damping.contact` or `damping.restitution`.
    chain: &'static str,
    /// Bond ranges with their own dashpot, in the order they are applied.
    own: Vec<(std::ops::RangeInclusive<usize>, String)>,
    /// The first key whose dashpot acts (a coefficient above 0, or a restitution): the
    /// chain's, then the striker's, then a segment's; `damping` when none does.
    first_acting: String,
}

impl ContactDashpots {
    /// The keys of `file`'s dashpots on the chain `layout` lays out.
    pub fn of(file: &raw::SceneFile, layout: &Layout) -> ContactDashpots {
        let damping = file.damping.as_ref();
        let chain = match damping.is_some_and(|d| d.restitution.is_some()) {
            true => "damping.restitution",
            false => "damping.contact",
        };
        let chain_acts =
            damping.is_some_and(|d| d.contact.is_some_and(|c| c > 0.0) || d.restitution.is_some());
        let mut ranges = Vec::new();
        let mut first_segment = None;
        for (i, segment) in file.segment.iter().enumerate() {
            let restitution = segment.restitution.is_some();
            let Some((field, acts)) = own_dashpot(segment.damping, restitution) else {
                continue;
            };
            let key = format!("segment[{i}]");
            let own = format!("{key}.{field}");
            if acts && first_segment.is_none() {
                first_segment = Some(own.clone());
            }
            let sites = segment
                .sites
                .as_deref()
                .and_then(|s| <[i64; 2]>::try_from(s).ok());
            let Some([lo, hi]) = sites else {
                continue;
            };
            if let (Ok(start), Ok(end)) = (layout.index(&key, lo), layout.index(&key, hi)) {
                ranges.push((start + 1..=end, own));
            }
        }
        let striker = file.striker.as_ref().and_then(|s| {
            let (field, acts) = own_dashpot(s.damping, s.restitution.is_some())?;
            let own = format!("striker.{field}");
            ranges.push((1..=1, own.clone()));
            acts.then_some(own)
        });
        let first_acting = match chain_acts {
            true => chain.to_string(),
            false => striker
                .or(first_segment)
                .unwrap_or_else(|| "damping".into()),
        };
        ContactDashpots {
            chain,
            own: ranges,
            first_acting,
        }
    }

    /// The first key whose dashpot acts: what a refusal blames when every dashpot's onsets
    /// together set the step.
    pub fn first_acting(&self) -> &str {
        &self.first_acting
    }

    /// The key that declares bond `bond`'s dashpot.
    pub fn key_of(&self, bond: usize) -> String {
        let own = self
            .own
            .iter()
            .rev()
            .find(|(range, _)| range.contains(&bond));
        own.map_or_else(|| self.chain.to_string(), |(_, key)| key.clone())
    }
}

/// A segment's or the striker's own dashpot: the key of its table that declares it
/// (`restitution` or `damping`), and whether it acts (a restitution, or a coefficient above
/// 0); `None` when neither is given, so that a table without one costs no key.
fn own_dashpot(damping: Option<f64>, restitution: bool) -> Option<(&'static str, bool)> {
    match (damping, restitution) {
        (_, true) => Some(("restitution", true)),
        (Some(gamma), false) => Some(("damping", gamma > 0.0)),
        (None, false) => None,
    }
}

/// The key that declares `which` dashpot or soft end.
fn dissipator_key(which: Dissipator, keys: &StepKeys<'_>) -> String {
    let defects = keys.defects;
    match which {
        Dissipator::SoftEnd { last: false } => "chain.boundary.left".into(),
        Dissipator::SoftEnd { last: true } => "chain.boundary.right".into(),
        Dissipator::Ground => "damping.ground".into(),
        Dissipator::Contact { bond } => keys.contact_dashpots.key_of(bond),
        Dissipator::Resonator(j) => match defects.get(j).and_then(|d| d.quality_factor) {
            Some(_) => format!("defect[{j}].quality_factor"),
            None => format!("defect[{j}].damping"),
        },
    }
}

/// The paper's region (Eqs. 10 and 11) spans the defects and one neighbour on each side, [min - 1, max + 1]
/// (adjacent defects 0..L give [-1, L + 1]; separated d1 < d2 give [d1 - 1, d2 + 1]). Without
/// defects, the single-defect region [-1, 1] around site 0, or around the chain's middle site
/// when site 0 is not on it. Either is cut to the chain, so that the default fits any chain
/// (a defect on the first site reads R as 0: nothing lies left of it).
fn default_region(defects: &[raw::Defect], layout: &Layout) -> [i64; 2] {
    let (first, last) = (layout.first, layout.last);
    let centre = match (first..=last).contains(&0) {
        true => 0,
        false => first + (last - first) / 2,
    };
    let sites = defects.iter().filter_map(|d| d.site);
    let lo = sites.clone().min().unwrap_or(centre);
    let hi = sites.max().unwrap_or(centre);
    [(lo - 1).max(first), (hi + 1).min(last)]
}
