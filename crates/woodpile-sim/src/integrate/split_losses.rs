//! Losses that act on velocities alone and linearly, integrated exactly half a step before and
//! half a step after the conservative chain's `rkn6-contact` step (Strang splitting, order 2):
//! `rkn6-split`, `auto`'s method on a chain whose losses are ground damping, resonator
//! dashpots and soft ends' dashpots ([`Model::losses_are_linear`]).
//!
//! ```text
//! site n (ground g, soft end's dashpot d_n):  v_n ← v_n exp(−(g + d_n) h / m_n)
//! resonator j on host s (dashpot c_j):        w = v_s − v_j ← w exp(−c_j (1/m_s + 1/ε_j) h),
//!                                             the pair's centre-of-mass velocity unchanged
//! ```
//!
//! The flows move no position, so the Nyström step keeps what it is built on: forces of
//! positions alone, their reuse from one step to the next, and its contact events. D gains
//! exactly the kinetic energy the flows remove, so the ledger E + D = E(0) checks the
//! conservative step. A contact dashpot has no such flow (its force starts with its contact
//! and is clipped against the spring's): such a chain runs `rk4-contact`.

use super::{ContactMode, Method, Rkn, StepOutcome, StepSpan, Stepper, DPRKN6};
use crate::model::{Model, Window};

/// A resonator's dashpot, as its exact flow needs it.
#[derive(Debug, Clone, Copy)]
struct PairDashpot {
    host: usize,
    inner: usize,
    /// c (1/m_s + 1/ε): the rate the relative velocity decays at.
    rate: f64,
    /// ε / (m_s + ε) and m_s / (m_s + ε): each body's share of the relative velocity.
    shares: (f64, f64),
    masses: (f64, f64),
}

/// The decay factors of one half-step, for the step length they were computed for.
#[derive(Debug, Clone)]
struct Decay {
    half_step: f64,
    sites: Vec<f64>,
    pairs: Vec<f64>,
}

/// The split stepper: see the module documentation.
pub struct SplitLosses {
    conservative: Model,
    inner: Box<dyn Stepper>,
    /// g + the soft end's dashpot, per site (0 where nothing acts).
    site_rates: Vec<f64>,
    /// Whether any site's rate is above 0 (otherwise the site flow is skipped).
    sites_decay: bool,
    site_masses: Vec<f64>,
    pairs: Vec<PairDashpot>,
    decay: Decay,
    /// The window's velocities and D before a step, restored if the conservative step is
    /// rejected.
    saved: Vec<f64>,
}

impl SplitLosses {
    /// The stepper for `model`, whose losses must be linear ([`Model::losses_are_linear`]).
    pub fn new(model: &Model) -> SplitLosses {
        assert!(
            model.losses_are_linear(),
            "rkn6-split cannot integrate a contact dashpot (Plan::choose refuses it)"
        );
        let conservative = model.without_losses();
        let n = model.n_sites();
        let damping = model.damping();
        let ground = damping.map_or(0.0, |d| d.ground);
        let site_masses: Vec<f64> = (0..n).map(|i| model.site_mass(i)).collect();
        let mut site_rates = vec![ground; n];
        let boundary = model.boundary();
        for (site, end) in [(0, boundary.left()), (n - 1, boundary.right())] {
            site_rates[site] += end.soft().map_or(0.0, |(_, dashpot)| dashpot);
        }
        let pairs = model
            .resonators()
            .iter()
            .enumerate()
            .filter_map(|(j, r)| {
                let c = damping.map_or(0.0, |d| d.resonator(j));
                let (m, e) = (site_masses[r.site], r.eps);
                (c > 0.0).then_some(PairDashpot {
                    host: r.site,
                    inner: n + j,
                    rate: c * (1.0 / m + 1.0 / e),
                    shares: (e / (m + e), m / (m + e)),
                    masses: (m, e),
                })
            })
            .collect();
        SplitLosses {
            inner: Box::new(Rkn::new(&conservative, DPRKN6, ContactMode::Corrected)),
            conservative,
            sites_decay: site_rates.iter().any(|&r| r > 0.0),
            site_rates,
            site_masses,
            pairs,
            decay: Decay {
                half_step: f64::NAN,
                sites: Vec::new(),
                pairs: Vec::new(),
            },
            saved: Vec::new(),
        }
    }

    /// The decay factors over `half_step`, computed once per step length.
    fn decay_over(&mut self, half_step: f64) {
        if self.decay.half_step == half_step {
            return;
        }
        let sites = self.site_rates.iter().zip(&self.site_masses);
        self.decay = Decay {
            half_step,
            sites: sites.map(|(r, m)| (-r * half_step / m).exp()).collect(),
            pairs: self
                .pairs
                .iter()
                .map(|p| (-p.rate * half_step).exp())
                .collect(),
        };
    }

    /// The losses' exact flow over the half-step of [`SplitLosses::decay_over`] on the
    /// velocities `v`: sites, then each resonator pair in turn; or (`reverse`) the same flows
    /// in the opposite order, pairs last to first, then sites. The step is then a palindrome,
    /// which is what makes it order 2: two dashpots on one host do not commute, and repeating
    /// their order would leave the method at order 1. The kinetic energy it removes. Sites
    /// outside `window` are at rest.
    fn flow(&self, v: &mut [f64], window: Window, reverse: bool) -> f64 {
        match reverse {
            false => self.site_flow(v, window) + self.pair_flow(v, false),
            true => self.pair_flow(v, true) + self.site_flow(v, window),
        }
    }

    fn site_flow(&self, v: &mut [f64], window: Window) -> f64 {
        if !self.sites_decay {
            return 0.0;
        }
        let sites = window.lo..window.hi + 1;
        let mut removed = 0.0;
        for ((v, &decay), &m) in v[sites.clone()]
            .iter_mut()
            .zip(&self.decay.sites[sites.clone()])
            .zip(&self.site_masses[sites])
        {
            let after = *v * decay;
            removed += m * (*v * *v - after * after);
            *v = after;
        }
        0.5 * removed
    }

    fn pair_flow(&self, v: &mut [f64], reverse: bool) -> f64 {
        let mut removed = 0.0;
        let pairs = self.pairs.iter().zip(&self.decay.pairs);
        let ordered: Box<dyn Iterator<Item = _>> = match reverse {
            false => Box::new(pairs),
            true => Box::new(pairs.rev()),
        };
        for (p, &decay) in ordered {
            let (host, inner) = (v[p.host], v[p.inner]);
            let (m, e) = p.masses;
            let centre = (m * host + e * inner) / (m + e);
            let relative = (host - inner) * decay;
            let (h, i) = (
                centre + p.shares.0 * relative,
                centre - p.shares.1 * relative,
            );
            removed += 0.5 * (m * (host * host - h * h) + e * (inner * inner - i * i));
            v[p.host] = h;
            v[p.inner] = i;
        }
        removed
    }
}

impl Stepper for SplitLosses {
    fn name(&self) -> &'static str {
        Method::Rkn6Split.name()
    }

    fn step(&mut self, model: &Model, y: &mut [f64], span: StepSpan) -> StepOutcome {
        let n_dof = self.conservative.n_dof();
        // What the flows change: the window's velocities and D (the fixed-step Nyström step
        // never rejects, but a rejection must leave the state as it was).
        let changed = &span.window.state_ranges(model)[2..];
        self.saved.clear();
        for range in changed {
            self.saved.extend_from_slice(&y[range.clone()]);
        }
        self.decay_over(0.5 * span.h);
        let (state, dissipated) = y.split_at_mut(2 * n_dof);
        let mut removed = self.flow(&mut state[n_dof..], span.window, false);
        let outcome = self.inner.step(&self.conservative, state, span);
        if let StepOutcome::Rejected { .. } = outcome {
            let mut saved = self.saved.as_slice();
            for range in changed {
                let (part, rest) = saved.split_at(range.len());
                y[range.clone()].copy_from_slice(part);
                saved = rest;
            }
            return outcome;
        }
        removed += self.flow(&mut state[n_dof..], span.window, true);
        // A chain without losses has no D, and the step is `rkn6-contact`'s.
        if let Some(d) = dissipated.first_mut() {
            *d += removed;
        }
        outcome
    }

    fn reach(&self) -> usize {
        self.inner.reach()
    }

    fn rhs_evals(&self) -> u64 {
        self.inner.rhs_evals()
    }
}
