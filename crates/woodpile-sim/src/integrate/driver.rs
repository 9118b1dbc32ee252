//! The one time loop: [`drive`] covers each sample interval by the step control's strategy
//! (equal fixed steps, or an adaptive method's accepted steps), then checks the sample (energy
//! drift, a wave reaching an end) and shows it to the observer. Failures (a non-finite state,
//! drift beyond the limit, a step below the floor, an exhausted budget) stop the run.
//!
//! Comparisons are written `!(x <= limit)` on purpose: a NaN must fail them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::{
    ActiveSites, DriveConfig, Observer, Stats, StepControl, StepOutcome, StepSpan, Stepper,
};
use crate::energy::ledger;
use crate::error::SimError;
use crate::model::Model;

/// An end site counts as reached when it moves at this fraction of sqrt(2 E(0)), the speed
/// the whole impact energy gives a unit mass. A solitary wave's precursor falls off faster
/// than exponentially, so an end moves at a thousandth of that speed only once the wave is
/// there.
pub const END_ARRIVAL_SPEED: f64 = 1e-3;

/// Between samples, the observer is asked whether to stop each time this many more site-steps
/// have been taken (about 10 ms of work at the development machine's rate): a run whose samples
/// are far apart (`sample_every = t_end`) still stops soon after Ctrl-C, at the cost of one
/// comparison a step.
pub const CANCEL_POLL_SITE_STEPS: u64 = 1 << 20;

/// The chain's end sites that were at rest at t = 0 (an impulse on an end site starts there,
/// and says nothing about a wave arriving).
struct WatchedEnds {
    sites: Vec<usize>,
    n_dof: usize,
    speed: f64,
}

impl WatchedEnds {
    fn new(model: &Model, y: &[f64], e0: f64) -> Self {
        let n_dof = model.n_dof();
        let last = model.n_sites() - 1;
        let mut sites = vec![0, last];
        sites.dedup();
        sites.retain(|&i| y[i] == 0.0 && y[n_dof + i] == 0.0);
        Self {
            sites,
            n_dof,
            speed: END_ARRIVAL_SPEED * (2.0 * e0.max(0.0)).sqrt(),
        }
    }

    fn reached(&self, y: &[f64]) -> bool {
        self.speed > 0.0
            && self
                .sites
                .iter()
                .any(|&i| y[self.n_dof + i].abs() > self.speed)
    }
}

/// Integrates `y` from t = 0 to `cfg.t_end` with `stepper`, calling `observer` at the samples.
///
/// One loop over the sample intervals: each is covered by the step control's own strategy
/// ([`Stepping::cover`]: equal fixed steps, or the adaptive method's accepted steps), then the
/// sample is checked and observed ([`Stepping::sample`]).
///
/// Errors: a non-finite state, an energy drift beyond the limit, a step below the floor, or an
/// exhausted budget stop the run; the state is then meaningless and must not be reported.
pub fn drive<S: Stepper + ?Sized, O: Observer + ?Sized>(
    model: &Model,
    stepper: &mut S,
    y: &mut [f64],
    cfg: &DriveConfig,
    observer: &mut O,
) -> Result<Stats, SimError> {
    validate(cfg)?;
    let h = match cfg.control {
        StepControl::Fixed { dt } => dt,
        StepControl::Adaptive { .. } => stepper.initial_step(model, 0.0, y, cfg.t_end),
    };
    let mut run = Stepping::start(model, cfg, y, (stepper.reach(), h), observer)?;
    let n_intervals = intervals(cfg.t_end, cfg.sample_every);
    for k in 1..=n_intervals {
        let target = sample_time(cfg, k, n_intervals);
        run.cover(stepper, y, target, observer)?;
        run.sample(y, observer)?;
    }
    run.stats.rhs_evals = stepper.rhs_evals();
    Ok(run.stats)
}

/// The time of sample `k` of `n_intervals` (the last is `t_end` itself).
pub(super) fn sample_time(cfg: &DriveConfig, k: u64, n_intervals: u64) -> f64 {
    if k == n_intervals {
        cfg.t_end
    } else {
        k as f64 * cfg.sample_every
    }
}

/// A run between samples: where it is, its next step, its active window and its statistics.
pub(super) struct Stepping<'a> {
    model: &'a Model,
    cfg: &'a DriveConfig,
    tracks_drift: bool,
    e0: f64,
    ends: WatchedEnds,
    pub active: ActiveSites,
    pub stats: Stats,
    /// Step attempts, rejected ones included (the adaptive budget).
    attempts: u64,
    t: f64,
    /// The next adaptive step (unused by fixed steps).
    h: f64,
    /// The site-steps at which the observer is next asked whether to stop
    /// ([`CANCEL_POLL_SITE_STEPS`]).
    next_poll: u64,
}

impl<'a> Stepping<'a> {
    /// A run of `model` from `y` at t = 0 by a stepper of `reach`, whose first step is `h`:
    /// the start checked and shown to `observer`.
    pub fn start<O: Observer + ?Sized>(
        model: &'a Model,
        cfg: &'a DriveConfig,
        y: &[f64],
        (reach, h): (usize, f64),
        observer: &mut O,
    ) -> Result<Self, SimError> {
        // The ledger E + D: the total energy itself for a conservative chain.
        let e0 = ledger(model, 0.0, y);
        check_finite(y, 0.0)?;
        observer.observe(model, 0.0, y);
        Ok(Stepping {
            model,
            cfg,
            // Drift is measured (and bounded) only where energy is conserved and a relative
            // drift exists.
            tracks_drift: !model.is_time_dependent() && e0 > 0.0,
            e0,
            ends: WatchedEnds::new(model, y, e0),
            active: ActiveSites::new(model, y, reach, cfg.active_window),
            stats: Stats::default(),
            attempts: 0,
            t: 0.0,
            h,
            next_poll: CANCEL_POLL_SITE_STEPS,
        })
    }

    /// Between steps: once every [`CANCEL_POLL_SITE_STEPS`] site-steps, whether `observer`
    /// wants the run stopped.
    pub fn poll<O: Observer + ?Sized>(&mut self, observer: &O) -> Result<(), SimError> {
        if self.stats.site_steps < self.next_poll {
            return Ok(());
        }
        self.next_poll = self.stats.site_steps + CANCEL_POLL_SITE_STEPS;
        match observer.cancelled() {
            true => Err(SimError::Cancelled { t: self.t }),
            false => Ok(()),
        }
    }

    /// The equal steps of at most `dt` that tile the way to `target`: their number and size.
    pub fn tiling(&self, target: f64, dt: f64) -> (u64, f64) {
        let span = target - self.t;
        let n_steps = (span / dt - 1e-9).ceil().max(1.0) as u64;
        (n_steps, span / n_steps as f64)
    }

    /// Counts a fixed step of size `h_eq` towards `target` (the `last` of its tiling lands on
    /// it), and enforces the budget.
    pub fn count_fixed_step(&mut self, last: bool, target: f64, h_eq: f64) -> Result<(), SimError> {
        self.t = if last { target } else { self.t + h_eq };
        self.stats.steps += 1;
        self.stats.max_step = self.stats.max_step.max(h_eq);
        if self.stats.steps > self.cfg.max_steps {
            return Err(SimError::TooManySteps {
                t: self.t,
                max_steps: self.cfg.max_steps,
            });
        }
        Ok(())
    }

    /// Where the run is.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Advances from `t` to `target` by the step control's strategy, asking `observer` now
    /// and then whether to stop ([`Stepping::poll`]).
    fn cover<S: Stepper + ?Sized, O: Observer + ?Sized>(
        &mut self,
        stepper: &mut S,
        y: &mut [f64],
        target: f64,
        observer: &O,
    ) -> Result<(), SimError> {
        match self.cfg.control {
            StepControl::Fixed { dt } => self.fixed_steps(stepper, y, (target, dt), observer),
            StepControl::Adaptive { h_min } => {
                self.adaptive_steps(stepper, y, (target, h_min), observer)
            }
        }
    }

    /// Equal steps of at most `dt` that end exactly on `target`.
    fn fixed_steps<S: Stepper + ?Sized, O: Observer + ?Sized>(
        &mut self,
        stepper: &mut S,
        y: &mut [f64],
        (target, dt): (f64, f64),
        observer: &O,
    ) -> Result<(), SimError> {
        let (n_steps, h_eq) = self.tiling(target, dt);
        for i in 0..n_steps {
            let window = self.active.window();
            self.stats.site_steps += window.len() as u64;
            stepper.step(
                self.model,
                y,
                StepSpan {
                    t: self.t,
                    h: h_eq,
                    window,
                },
            );
            self.active.update(self.model, y, window);
            self.count_fixed_step(i + 1 == n_steps, target, h_eq)?;
            check_finite_in(y, self.t, &window.state_ranges(self.model))?;
            self.poll(observer)?;
        }
        Ok(())
    }

    /// The adaptive method's steps up to `target`, the last shortened to land on it.
    fn adaptive_steps<S: Stepper + ?Sized, O: Observer + ?Sized>(
        &mut self,
        stepper: &mut S,
        y: &mut [f64],
        (target, h_min): (f64, f64),
        observer: &O,
    ) -> Result<(), SimError> {
        while self.t < target {
            let remaining = target - self.t;
            let lands = self.h >= remaining * (1.0 - 1e-12);
            let h_try = if lands { remaining } else { self.h };
            self.attempts += 1;
            if self.attempts > self.cfg.max_steps {
                return Err(SimError::TooManySteps {
                    t: self.t,
                    max_steps: self.cfg.max_steps,
                });
            }
            let window = self.active.window();
            self.stats.site_steps += window.len() as u64;
            let span = StepSpan {
                t: self.t,
                h: h_try,
                window,
            };
            match stepper.step(self.model, y, span) {
                StepOutcome::Accepted { h_next } => {
                    self.active.update(self.model, y, window);
                    self.t = if lands { target } else { self.t + h_try };
                    self.stats.steps += 1;
                    self.stats.max_step = self.stats.max_step.max(h_try);
                    check_finite_in(y, self.t, &window.state_ranges(self.model))?;
                    // A step shortened to land on a sample says nothing about the step the
                    // method could take: keep the larger proposal.
                    self.h = if lands { h_next.max(self.h) } else { h_next };
                }
                StepOutcome::Rejected { h_next } => {
                    self.stats.rejected += 1;
                    self.h = h_next;
                }
            }
            if !(self.h >= h_min) {
                return Err(SimError::StepUnderflow {
                    t: self.t,
                    dt: self.h,
                });
            }
            self.poll(observer)?;
        }
        Ok(())
    }

    /// At a sample: the energy drift checked, the ends watched, the observer told (and asked
    /// whether to stop).
    pub fn sample<O: Observer + ?Sized>(
        &mut self,
        y: &[f64],
        observer: &mut O,
    ) -> Result<(), SimError> {
        let (model, t) = (self.model, self.t);
        if self.tracks_drift {
            let drift = ((ledger(model, t, y) - self.e0) / self.e0).abs();
            self.stats.max_energy_drift = self.stats.max_energy_drift.max(drift);
            if let Some(limit) = self.cfg.energy_drift_limit {
                if !(drift <= limit) {
                    return Err(SimError::EnergyDrift { t, drift, limit });
                }
            }
        }
        if self.stats.end_reached_at.is_none() && self.ends.reached(y) {
            self.stats.end_reached_at = Some(t);
        }
        observer.observe(model, t, y);
        if observer.cancelled() {
            return Err(SimError::Cancelled { t });
        }
        Ok(())
    }
}

/// Number of sample intervals covering [0, t_end]; the last may be shorter.
pub fn intervals(t_end: f64, sample_every: f64) -> u64 {
    ((t_end / sample_every) - 1e-9).ceil().max(1.0) as u64
}

pub(super) fn validate(cfg: &DriveConfig) -> Result<(), SimError> {
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(cfg.t_end) {
        return Err(SimError::BadRun(format!(
            "t_end must be finite and > 0, got {}",
            cfg.t_end
        )));
    }
    if !positive(cfg.sample_every) {
        return Err(SimError::BadRun(format!(
            "sample interval must be finite and > 0, got {}",
            cfg.sample_every
        )));
    }
    match cfg.control {
        StepControl::Fixed { dt } if !positive(dt) => Err(SimError::BadRun(format!(
            "dt must be finite and > 0, got {dt}"
        ))),
        StepControl::Adaptive { h_min } if !(h_min >= 0.0) => {
            Err(SimError::BadRun(format!("h_min must be >= 0, got {h_min}")))
        }
        _ => Ok(()),
    }
}

fn check_finite(y: &[f64], t: f64) -> Result<(), SimError> {
    check_finite_in(y, t, std::slice::from_ref(&(0..y.len())))
}

/// Fails if any entry of `y` in `ranges` is NaN or infinite. x - x is 0 for a finite x and NaN
/// otherwise, and never overflows; eight independent partial sums let the loop vectorise.
#[allow(unsafe_code)]
pub(super) fn check_finite_in(
    y: &[f64],
    t: f64,
    ranges: &[std::ops::Range<usize>],
) -> Result<(), SimError> {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::tier() >= crate::simd::Tier::Avx2 {
        // SAFETY: `tier()` is AVX2 or above only when the CPU has AVX2 and FMA.
        return unsafe { check_finite_avx2(y, t, ranges) };
    }
    check_finite_body(y, t, ranges)
}

/// [`check_finite_in`] compiled with AVX2 (`crate::simd`), which the AVX-512 tier runs too.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn check_finite_avx2(y: &[f64], t: f64, ranges: &[std::ops::Range<usize>]) -> Result<(), SimError> {
    check_finite_body(y, t, ranges)
}

#[inline(always)]
#[allow(clippy::eq_op)] // x - x is the point: it is NaN exactly when x is not finite
fn check_finite_body(y: &[f64], t: f64, ranges: &[std::ops::Range<usize>]) -> Result<(), SimError> {
    let mut lanes = [0.0f64; 8];
    // The tails have a sum of their own: added into `lanes`, they were compiled as a masked
    // store to the stack read back at once, a stall (the check took 4.5% of the paper
    // sample's time, 3.2% without it; `perf`).
    let mut tails = 0.0f64;
    for range in ranges {
        let part = &y[range.clone()];
        let chunks = part.chunks_exact(8);
        let tail = chunks.remainder();
        for chunk in chunks {
            for (lane, &x) in lanes.iter_mut().zip(chunk) {
                *lane += x - x;
            }
        }
        for &x in tail {
            tails += x - x;
        }
    }
    if lanes.iter().sum::<f64>() + tails == 0.0 {
        return Ok(());
    }
    let site = y.iter().position(|x| !x.is_finite()).unwrap_or(0);
    let n_dof = y.len() / 2;
    Err(SimError::NonFinite {
        t,
        site: site % n_dof,
    })
}
