//! Error types of the simulation core. Every failure carries the numbers needed to act on it.

use thiserror::Error;

/// A model that cannot be simulated: raised by constructors, before any step is taken.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ModelError {
    /// The chain has no sites.
    #[error("the chain needs at least one site")]
    EmptyChain,
    /// A site index points outside the chain.
    #[error("{what} site index {site} is outside the chain of {n_sites} sites")]
    SiteOutOfRange {
        /// What the index was for ("resonator 2", "impulse").
        what: String,
        /// The offending index (0-based, internal numbering).
        site: usize,
        /// Number of sites in the chain.
        n_sites: usize,
    },
    /// A parameter that must be finite and positive is not.
    #[error("{what} must be finite and > 0, got {value}")]
    NotPositive {
        /// Which parameter ("resonator 0 eps", "mass of site 3").
        what: String,
        /// The offending value.
        value: f64,
    },
    /// A parameter that must be finite and non-negative is not.
    #[error("{what} must be finite and >= 0, got {value}")]
    Negative {
        /// Which parameter.
        what: String,
        /// The offending value.
        value: f64,
    },
    /// A parameter that must be finite is NaN or infinite.
    #[error("{what} must be finite, got {value}")]
    NotFinite {
        /// Which parameter.
        what: String,
        /// The offending value.
        value: f64,
    },
    /// An even coupling exponent p > 1 would not be a restoring force.
    #[error("resonator {index}: coupling exponent p must be 1 or an odd integer >= 3, got {p}")]
    BadExponent {
        /// Resonator index.
        index: usize,
        /// The offending exponent.
        p: u32,
    },
    /// A contact exponent outside [`crate::contact::EXPONENT_RANGE`].
    #[error("the contact exponent must be a number from 1 to 5, got {exponent}")]
    ContactExponent {
        /// The offending exponent.
        exponent: f64,
    },
    /// The contact law does not have one coefficient per bond of the chain.
    #[error("{n_bonds} contact coefficients given for a chain of {n_sites} sites (needs sites + 1, walls included)")]
    BondCount {
        /// Number of coefficients given.
        n_bonds: usize,
        /// Number of sites.
        n_sites: usize,
    },
    /// A precompression needs walls at both ends to hold it.
    #[error("a precompression needs fixed walls at both ends")]
    PrecompressionWithoutWalls,
    /// More resonator dashpots than resonators.
    #[error("{n_dampings} resonator dashpots given for {n_resonators} resonators")]
    DampingCount {
        /// Number of dashpots given.
        n_dampings: usize,
        /// Number of resonators.
        n_resonators: usize,
    },
    /// The per-site mass list does not match the number of sites.
    #[error("{n_masses} site masses given for a chain of {n_sites} sites")]
    MassCount {
        /// Number of masses given.
        n_masses: usize,
        /// Number of sites.
        n_sites: usize,
    },
    /// A region [lo, hi] that is empty or leaves the chain.
    #[error(
        "fraction region [{lo}, {hi}] must satisfy 0 <= lo <= hi < {n_sites} (internal numbering)"
    )]
    BadRegion {
        /// Lower site (inclusive).
        lo: i64,
        /// Upper site (inclusive).
        hi: i64,
        /// Number of sites.
        n_sites: usize,
    },
}

/// A run that failed. Never returned as numbers: the caller reports it and writes nothing.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SimError {
    /// The model or run configuration was invalid.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The state became NaN or infinite.
    #[error("the solution became non-finite at t = {t:.6} (site index {site}); the step is unstable, reduce dt or tolerance")]
    NonFinite {
        /// Time of the first non-finite state seen.
        t: f64,
        /// First degree of freedom found non-finite (sites first, then resonators).
        site: usize,
    },
    /// The total energy of a conservative run drifted beyond the allowed bound.
    #[error("energy drift {drift:.3e} exceeds the allowed {limit:.1e} at t = {t:.6}; the integration is not accurate enough")]
    EnergyDrift {
        /// Time at which the drift was detected.
        t: f64,
        /// Relative drift |E(t) - E(0)| / E(0).
        drift: f64,
        /// The allowed bound.
        limit: f64,
    },
    /// A fixed-step run on a time-dependent model (a kappa ramp), where energy cannot guard
    /// it, changed by more than the allowed amount when its step was halved.
    #[error("kappa depends on time, so energy cannot check this fixed-step run: with dt halved to {dt:.3e} the fractions moved by {change:.3e}, more than the allowed {limit:.1e}; take a smaller dt, or method = \"auto\"")]
    StepCheck {
        /// The halved step.
        dt: f64,
        /// The largest change of R, T or E_tr between the two runs.
        change: f64,
        /// The allowed change.
        limit: f64,
    },
    /// An adaptive method needed a step below its floor.
    #[error("step size underflow at t = {t:.6}: dt = {dt:.3e}; the tolerance cannot be met")]
    StepUnderflow {
        /// Time at which the step collapsed.
        t: f64,
        /// The step that was too small.
        dt: f64,
    },
    /// The run exceeded its step budget.
    #[error("step budget of {max_steps} exhausted at t = {t:.6}")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// The budget.
        max_steps: u64,
    },
    /// `auto` could not verify the tolerance by step halving.
    #[error("method auto could not verify tolerance {tolerance:.1e}: at its finest step, dt = {dt:.3e}, {why}; use a looser tolerance, or a named method with a step of your choosing (method = \"erkn6-contact\", or \"rk4-contact\" with damping, and dt = ...), whose result is not verified")]
    NotConverged {
        /// Requested tolerance.
        tolerance: f64,
        /// Last Richardson error estimate.
        estimate: f64,
        /// Last (finest) step tried.
        dt: f64,
        /// What failed at that step: the estimate, the energy drift, or the pair not being in
        /// its asymptotic regime.
        why: Refusal,
        /// The finest run the ladder made, unverified: what a caller may keep, marked so.
        finest: Option<Box<Unverified>>,
    },
    /// The run ended, but its shares break the rule every reported run meets
    /// (`simulation::check_shares`): not all finite, one outside [0, 1], or their sum not 1.
    #[error("the run's energy shares at t_end cannot be right: {why}; no numbers are reported")]
    Implausible {
        /// Which share, and how it breaks the rule.
        why: String,
    },
    /// The observer asked for the run to stop (see `Observer::cancelled`).
    #[error("cancelled at t = {t:.6}")]
    Cancelled {
        /// Time of the sample at which the run stopped.
        t: f64,
    },
    /// A method for forces of positions only was asked to run a dissipative chain.
    #[error("method {method} integrates y'' = f(t, y) and cannot run a chain with damping, whose forces depend on velocities; methods that can: auto, {methods}")]
    VelocityForces {
        /// The method asked for.
        method: &'static str,
        /// The named methods that can.
        methods: String,
    },
    /// A run setting (t_end, dt, tolerance, sample interval) is invalid.
    #[error("invalid run setting: {0}")]
    BadRun(String),
    /// The run would exceed its step or sample budget: refused before it starts.
    #[error(transparent)]
    OverBudget(#[from] OverBudget),
}

/// The finest run of a refused `auto` ladder: numbers that are not verified, kept so that the
/// minutes it took are not lost (`woodpile simulate` prints them under `unverified`).
/// (Its shares are plain numbers rather than `energy::Fractions`, so that this leaf module
/// imports nothing.)
#[derive(Debug, Clone, PartialEq)]
pub struct Unverified {
    /// Its shares at `t_end`, in `Share::ALL`'s order (a share added there no longer fits
    /// here, and fails to compile until this type takes it).
    pub shares: [f64; 5],
    /// The step it took.
    pub dt: f64,
    /// The last Richardson estimate, against the run at twice its step (infinite if none).
    pub estimate: f64,
}

/// What sets the step that makes a run too long.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepSetBy {
    /// The scene's explicit `dt`.
    Dt,
    /// The step the tolerance asks for.
    Tolerance,
    /// Resolving (or keeping stable) the fastest resonator, index into the model's resonators.
    Resonator(usize),
    /// Resolving the chain's stiffest contact (a [`crate::ContactLaw`]: heavy precompression,
    /// stiff contacts or light sites).
    Contacts,
    /// Keeping the fastest dashpot or soft end stable.
    Dissipation(Dissipator),
    /// The finest rung `auto` is likely to need: a contact dashpot switches on with its
    /// contact, a kink that costs `rk4-contact` its order, so the ladder halves its first step
    /// up to `simulation::MAX_HALVINGS` times.
    DashpotOnsets,
}

/// A velocity-dependent force of a chain, by what declares it: what
/// `Model::fastest_dissipation` names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dissipator {
    /// A soft end: the first site's (`last = false`) or the last site's.
    SoftEnd {
        /// Whether it is the last site's end.
        last: bool,
    },
    /// Ground damping on every site.
    Ground,
    /// The dashpot inside resonator `j`.
    Resonator(usize),
    /// The dashpot of contact `bond` (the bond numbering of [`crate::contact`]).
    Contact {
        /// The bond whose dashpot is the fastest.
        bond: usize,
    },
}

/// A run refused before it starts.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OverBudget {
    /// `t_end / sample_every` samples.
    #[error("{samples:.3e} samples (t_end / sample_every) would be recorded, more than the {limit} a run may keep")]
    Samples {
        /// How many.
        samples: f64,
        /// The most a run may keep (`simulation::budget::MAX_SAMPLES`).
        limit: u64,
    },
    /// Too many steps.
    #[error("{} to reach t_end (set by {}), beyond the budget of {limit} steps", steps_text(*steps, *dt), set_by.describe())]
    Steps {
        /// Estimated steps.
        steps: f64,
        /// The step the estimate assumes.
        dt: f64,
        /// What sets it.
        set_by: StepSetBy,
        /// The most a run may take (`integrate::MAX_STEPS`).
        limit: u64,
    },
}

impl StepSetBy {
    fn describe(self) -> &'static str {
        match self {
            StepSetBy::Dt => "the run's dt",
            StepSetBy::Tolerance => "the tolerance",
            StepSetBy::Resonator(_) => "the fastest resonator's frequency",
            StepSetBy::Contacts => "the chain's stiffest contact",
            StepSetBy::Dissipation(_) => "the fastest dashpot or soft end",
            StepSetBy::DashpotOnsets => "auto's finest rung, which a contact dashpot's onset makes likely: it costs rk4-contact its order; a named method with a dt runs once instead",
        }
    }
}

/// `about 1.2e9 steps of dt = 3.0e-8`; a step that underflowed to 0 (or below any float's
/// resolution) says so instead of "inf steps of dt = 0.000e0".
fn steps_text(steps: f64, dt: f64) -> String {
    match dt.is_normal() && steps.is_finite() {
        true => format!("about {steps:.3e} steps of dt = {dt:.3e}"),
        false => format!("a step of {dt:.3e}, too small for a float to count steps with,"),
    }
}

/// Why `auto`'s ladder did not accept the finest step it tried: the typed reason a
/// [`SimError::NotConverged`] carries, and the sentence its message says.
#[derive(Debug, Clone, PartialEq)]
pub enum Refusal {
    /// No rung has run yet.
    NoRunKeptEnergy,
    /// The fine run itself blew up or lost its energy.
    BlewUp(Box<SimError>),
    /// The run at twice the step blew up: no pair.
    NoPair,
    /// The pair's estimate is above what it must meet.
    Estimate {
        /// The Richardson estimate.
        estimate: f64,
        /// What it had to be at most.
        accept: f64,
        /// The tolerance asked for.
        tol: f64,
    },
    /// The fine run drifts in energy beyond what the tolerance allows.
    Drift {
        /// The largest relative drift seen.
        drift: f64,
        /// What the tolerance allows.
        limit: f64,
    },
    /// The estimate would pass, but the changes do not shrink as the method's order says.
    NotAsymptotic {
        /// The estimate that would have passed.
        estimate: f64,
        /// The change between the two runs before.
        before: f64,
        /// The change between the last two.
        after: f64,
    },
    /// The pair agreed, but a run off the ladder (1.5 dt) does not.
    OffLadder {
        /// The estimate from the run off the ladder.
        estimate: f64,
        /// What it had to be at most.
        accept: f64,
        /// The tolerance asked for.
        tol: f64,
    },
    /// The estimate is so far above what it must meet that the halvings left cannot bring it
    /// there, even falling as fast as an accepted pair's changes may.
    OutOfReach {
        /// The Richardson estimate.
        estimate: f64,
        /// What it had to be at most.
        accept: f64,
        /// The tolerance asked for.
        tol: f64,
        /// Halvings the ladder had left.
        halvings_left: u32,
        /// The most the estimate could fall per halving.
        factor: f64,
    },
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Refusal::NoRunKeptEnergy => write!(f, "no run kept its energy"),
            Refusal::BlewUp(ref e) => write!(f, "the run blew up or lost energy ({e})"),
            Refusal::NoPair => write!(f, "the run at twice the step blew up, so there is no pair to compare"),
            Refusal::Estimate { estimate, accept, tol } => write!(
                f,
                "the error estimate {estimate:.2e} is above the {accept:.1e} it must meet (tolerance {tol:.1e})"
            ),
            Refusal::Drift { drift, limit } => write!(
                f,
                "the energy drifts by {drift:.2e}, more than the {limit:.1e} the tolerance allows"
            ),
            Refusal::NotAsymptotic { estimate, before, after } => write!(
                f,
                "the error estimate {estimate:.2e} would pass, but the runs are not in their asymptotic regime (the change between runs went from {before:.2e} to {after:.2e} when the step halved, not by the factor the method's order gives), so the estimate cannot be trusted"
            ),
            Refusal::OffLadder { estimate, accept, tol } => write!(
                f,
                "the pair agreed, but a run at 1.5 times the step differs by an estimated {estimate:.2e}, above the {accept:.1e} it must meet (tolerance {tol:.1e}): the error jumps with the step"
            ),
            Refusal::OutOfReach { estimate, accept, tol, halvings_left, factor } => write!(
                f,
                "the error estimate {estimate:.2e} is above the {accept:.1e} it must meet (tolerance {tol:.1e}), and the {halvings_left} halving(s) left could not bring it there even if it fell {factor:.0} times per halving, the most an accepted pair's change may fall: refused at once rather than after them"
            ),
        }
    }
}
