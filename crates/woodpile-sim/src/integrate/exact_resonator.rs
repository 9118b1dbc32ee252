//! Linear resonators integrated exactly: the extended Nyström step of `erkn6-contact`.
//!
//! Why: a linear resonator (p = 1, constant κ) and its host vibrate against each other at
//! ω² = κ (1/m + 1/ε), and light resonators make ω large. An ordinary Nyström step resolves
//! that vibration only while ω h is small: DPRKN6 grows its amplitude by 4e-6 a step at ω h = 1,
//! so `auto` capped ω h at 0.5, and on F7's light resonators the coarse run of its first pair
//! missed by 18 times what a heavy resonator's did (measured in commit bcb51da's work). Here the pair's spring
//! is integrated exactly and only the rest of the force, g (the contacts), by the tableau.
//!
//! Each pair's spring is a linear term −Ω² q of rank one: on the pair's coordinates (u, v)
//! Ω² = κ [[1/m, −1/m], [−1/ε, 1/ε]], whose eigenvalues are 0 and ω². So any function of
//! V = h²Ω² is f(V) x = f(0) x + (f(θ²) − f(0)) P x with θ = ω h and P the projector on the fast
//! mode, P x = (κ/ω²)(x_u − x_v) (1/m, −1/ε). The step is the extended Runge–Kutta–Nyström
//! (ERKN) form of the variation-of-constants formula (Wu, You and Wang, 2013):
//!
//! ```text
//! Q_i = φ0(c_i² V) q + c_i h φ1(c_i² V) p + h² Σ_j ā_ij(V) g(Q_j)
//! q+  = φ0(V) q + h φ1(V) p + h² Σ_i b̄_i(V) g(Q_i)
//! p+  = −h Ω² φ1(V) q + φ0(V) p + h Σ_i b_i(V) g(Q_i)
//! ```
//!
//! with φ0(x) = cos √x and φ1(x) = sin √x / √x. Every coefficient function equals the tableau's
//! own at V = 0, so the step is the plain tableau's on every other degree of freedom, and on a
//! pair it is the plain step plus a shift along the fast mode (`Shift`). Each coefficient's
//! change with V is that of an interpolatory rule of the variation-of-constants integral on the
//! stage nodes available to it, `exact_weights`: the weights of the new velocity are exact
//! for a forcing polynomial of degree S − 1 in time, those of a stage and of the new position
//! for degree i − 2 on the i − 1 nodes before stage i. At V = 0 those changes vanish, so the
//! method keeps the tableau's order conditions; for any θ the free vibration (g = 0) and a
//! constant forcing are integrated exactly.

use super::contact_event::BondPath;
use super::erkn_weights::{pair_step, NystromWeights, PairStep};
use crate::contact::{with_law, Law};
pub(crate) use crate::dofs::{Dofs, DofsMut};
use crate::model::Model;

/// One host site and its harmonic resonator.
#[derive(Debug, Clone, Copy)]
struct Pair {
    /// The host site, which is also its position's index in the state.
    host: usize,
    /// The resonator's position index in the state.
    resonator: usize,
    kappa: f64,
    inv_host_mass: f64,
    omega: f64,
    /// The fast mode's direction, scaled by κ/ω²: P x = (x_u − x_v) `mode`.
    mode: [f64; 2],
}

/// The harmonic pairs of a model and their coefficients for the step size last prepared.
#[derive(Debug, Clone)]
pub(crate) struct ExactResonators<const S: usize> {
    tableau: NystromWeights<S>,
    /// Each pair with its coefficients and its state in the step being taken, side by side:
    /// the stage loop reads all three.
    pairs: Vec<Oscillator<S>>,
    /// Each site's pair, if it hosts one: the contact correction asks per corrected bond.
    pair_of_site: Vec<Option<usize>>,
    /// The step size the coefficients are for.
    h: f64,
}

/// One pair: its constants, its coefficients for the step size, and the step being taken.
#[derive(Debug, Clone)]
struct Oscillator<const S: usize> {
    pair: Pair,
    step: PairStep<S>,
    now: PairNow<S>,
}

/// A pair in the step being taken: whether its host is in the window, its stretch u − v and
/// rate at the step's start, and its share of each stage's forcing (g_host − g_resonator).
#[derive(Debug, Clone, Copy)]
struct PairNow<const S: usize> {
    active: bool,
    stretch: f64,
    rate: f64,
    forcing: [f64; S],
}

impl<const S: usize> ExactResonators<S> {
    /// The harmonic pairs of `model` ([`Model::is_harmonic`]) for the tableau of `weights`, or
    /// `None` when it has none. The tableau must end on the force at the new position (FSAL),
    /// as DPRKN6 does: the new position is then its last stage, shifted like every stage.
    pub fn of(model: &Model, tableau: NystromWeights<S>) -> Option<Self> {
        assert!(
            tableau.c[S - 1] == 1.0,
            "an exact resonator step needs an FSAL tableau"
        );
        let pairs: Vec<Oscillator<S>> = (0..model.resonators().len())
            .filter(|&j| model.is_harmonic(j))
            .map(|j| {
                let r = model.resonators()[j];
                let kappa = r.coupling.max_value();
                let inv_host_mass = 1.0 / model.site_mass(r.site);
                let inv_eps = 1.0 / r.eps;
                let omega_squared = kappa * (inv_host_mass + inv_eps);
                let scale = kappa / omega_squared;
                let pair = Pair {
                    host: r.site,
                    resonator: model.n_sites() + j,
                    kappa,
                    inv_host_mass,
                    omega: omega_squared.sqrt(),
                    mode: [scale * inv_host_mass, -scale * inv_eps],
                };
                let now = PairNow {
                    active: false,
                    stretch: 0.0,
                    rate: 0.0,
                    forcing: [0.0; S],
                };
                Oscillator {
                    pair,
                    step: pair_step(&tableau, 0.0, 1.0),
                    now,
                }
            })
            .collect();
        let mut pair_of_site = vec![None; model.n_sites()];
        for (k, o) in pairs.iter().enumerate() {
            pair_of_site[o.pair.host] = Some(k);
        }
        (!pairs.is_empty()).then_some(Self {
            tableau,
            pairs,
            pair_of_site,
            h: f64::NAN,
        })
    }

    /// Makes the coefficients those of step size `h` (computed only when it changed).
    fn prepare(&mut self, h: f64) {
        if h == self.h {
            return;
        }
        self.h = h;
        for o in &mut self.pairs {
            o.step = pair_step(&self.tableau, o.pair.omega * h, h);
        }
    }

    /// Starts a step of size `h` from `(q, p)` on the sites `lo..=hi`: prepares the
    /// coefficients and notes each pair's stretch and its rate (a pair whose host is outside
    /// the window is at rest and takes no part).
    #[inline(always)]
    pub fn begin_step<D: Dofs + ?Sized>(
        &mut self,
        h: f64,
        (q, p): (&D, &D),
        (lo, hi): (usize, usize),
    ) {
        self.prepare(h);
        for o in &mut self.pairs {
            let (host, resonator) = (o.pair.host, o.pair.resonator);
            o.now.active = host >= lo && host <= hi;
            if o.now.active {
                o.now.stretch = q.at(host) - q.at(resonator);
                o.now.rate = p.at(host) - p.at(resonator);
            }
        }
    }

    /// Turns stage `i`'s accelerations `acc` (of positions `q`) into the forcing g: each
    /// pair's spring force taken out of its host's acceleration, and its resonator's set to
    /// zero (a resonator feels its spring only). Keeps the pair's share of g for the shifts.
    #[inline(always)]
    pub fn remove_springs<D: Dofs + ?Sized, A: DofsMut + ?Sized>(
        &mut self,
        i: usize,
        q: &D,
        acc: &mut A,
    ) {
        for o in &mut self.pairs {
            o.remove_spring(i, q, acc);
        }
    }

    /// [`ExactResonators::remove_springs`] for the pair hosted at `site` only, if any: for a
    /// stage whose forces were evaluated again at a few sites (the lanes' patch, and
    /// `ContactEvents::patch_reused_stage`).
    pub fn remove_spring_at<D: Dofs + ?Sized, A: DofsMut + ?Sized>(
        &mut self,
        (i, site): (usize, usize),
        q: &D,
        acc: &mut A,
    ) {
        if let Some(k) = self.pair_of_site[site] {
            self.pairs[k].remove_spring(i, q, acc);
        }
    }

    /// Stage `to`'s forcing is stage `from`'s (a stage the next step reuses, FSAL).
    pub fn reuse_stage(&mut self, from: usize, to: usize) {
        for o in &mut self.pairs {
            o.now.forcing[to] = o.now.forcing[from];
        }
    }

    /// Adds stage `i`'s shift along each pair's fast mode to the stage position `q_stage`
    /// (already the plain tableau's), from the step's start and the forcings of the stages
    /// before it.
    #[inline(always)]
    pub fn shift_stage<A: DofsMut + ?Sized>(&self, i: usize, q_stage: &mut A) {
        for o in &self.pairs {
            if o.now.active {
                let (step, now) = (&o.step, &o.now);
                let mut shift = step.stage_q[i] * now.stretch + step.stage_p[i] * now.rate;
                for (weight, g) in step.stage_g[i][..i].iter().zip(&now.forcing) {
                    shift += weight * g;
                }
                q_stage.add(o.pair.host, shift * o.pair.mode[0]);
                q_stage.add(o.pair.resonator, shift * o.pair.mode[1]);
            }
        }
    }

    /// Adds each pair's fast-mode shift to the new velocity `new_p` (already the plain
    /// tableau's). The new position needs none of its own: it is the last stage's.
    #[inline(always)]
    pub fn shift_velocity<A: DofsMut + ?Sized>(&self, new_p: &mut A) {
        for o in &self.pairs {
            if o.now.active {
                let (step, now) = (&o.step, &o.now);
                let mut shift = step.velocity_q * now.stretch + step.velocity_p * now.rate;
                for (weight, g) in step.velocity_g.iter().zip(&now.forcing) {
                    shift += weight * g;
                }
                new_p.add(o.pair.host, shift * o.pair.mode[0]);
                new_p.add(o.pair.resonator, shift * o.pair.mode[1]);
            }
        }
    }

    /// The pair whose host is `site`, if any: its index, θ and the fast mode's share of a unit
    /// force on the host, `P e_host / m` (host and resonator entries).
    pub fn host(&self, site: usize) -> Option<HostOf<S>> {
        let k = self.pair_of_site[site]?;
        let (pair, step) = (&self.pairs[k].pair, &self.pairs[k].step);
        Some(HostOf {
            host: pair.host,
            resonator: pair.resonator,
            theta: step.theta,
            share: [
                pair.mode[0] * pair.inv_host_mass,
                pair.mode[1] * pair.inv_host_mass,
            ],
            b_velocity: step.b_velocity,
            b_position: step.b_position,
        })
    }
}

impl<const S: usize> Oscillator<S> {
    /// Takes the pair's spring out of stage `i`'s accelerations `acc` (of positions `q`) and
    /// keeps its share of g ([`ExactResonators::remove_springs`]).
    #[inline(always)]
    fn remove_spring<D: Dofs + ?Sized, A: DofsMut + ?Sized>(
        &mut self,
        i: usize,
        q: &D,
        acc: &mut A,
    ) {
        if self.now.active {
            let (host, resonator) = (self.pair.host, self.pair.resonator);
            let spring = self.pair.kappa * (q.at(host) - q.at(resonator)) * self.pair.inv_host_mass;
            acc.add(host, spring);
            acc.set(resonator, 0.0);
            // The pair's share of g, g_host − g_resonator, with the latter now zero.
            self.now.forcing[i] = acc.at(host);
        }
    }
}

/// What the contact correction needs of a host's pair ([`ExactResonators::host`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct HostOf<const S: usize> {
    pub host: usize,
    pub resonator: usize,
    /// ω h.
    pub theta: f64,
    /// P e_host / m_host: how a unit impulse on the host splits into the fast mode.
    pub share: [f64; 2],
    /// The ERKN weights at θ²: the new velocity's b_i and the new position's b̄_i.
    pub b_velocity: [f64; S],
    pub b_position: [f64; S],
}

/// A conservative bond's impulse and moment along its path under the fast-mode weights of a
/// host whose resonator is integrated exactly ([`Law::oscillating_integrals`]).
fn oscillating_bond_integrals(
    model: &Model,
    bond: usize,
    path: &BondPath,
    h: f64,
    theta: f64,
) -> (f64, f64) {
    with_law!(model.law(), |law| law
        .oscillating_integrals(bond, path, h, theta))
}

/// The part of a bond's correction that reaches a host's fast mode in an extended Nyström step
/// (`erkn6-contact`, [`ExactResonators`]). The plain correction (impulse − quadrature) acts on
/// the host as on any site; the fast mode's share of the force is integrated with the
/// variation-of-constants weights instead, so this adds the difference of the two
/// corrections, (weighted integral − weighted quadrature) − (plain correction), along the fast
/// mode. `sign` is −1 for the bond's left member, +1 for its right.
pub(crate) fn fast_mode_correction<const S: usize>(
    model: &Model,
    (bond, path, stage): (usize, &BondPath, [f64; S]),
    h: f64,
    (plain_impulse, plain_moment): (f64, f64),
    (pair, sign): (HostOf<S>, f64),
) -> FastModeCorrection {
    let (impulse, moment) = oscillating_bond_integrals(model, bond, path, h, pair.theta);
    let weigh = |w: &[f64; S]| w.iter().zip(&stage).map(|(w, f)| w * f).sum::<f64>();
    let extra_impulse = (impulse - h * weigh(&pair.b_velocity)) - plain_impulse;
    let extra_moment = (moment - h * h * weigh(&pair.b_position)) - plain_moment;
    FastModeCorrection {
        sites: [pair.host, pair.resonator],
        velocity: pair.share.map(|s| sign * extra_impulse * s),
        position: pair.share.map(|s| sign * extra_moment * s),
    }
}

/// A fast-mode correction: added to the host's and its resonator's velocity and position.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FastModeCorrection {
    pub sites: [usize; 2],
    pub velocity: [f64; 2],
    pub position: [f64; 2],
}
