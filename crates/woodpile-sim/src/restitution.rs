//! The coefficient of restitution of an isolated pair of bodies meeting through one contact of
//! the chain's law with its dashpot, and the dashpot that gives a measured one: how a lab's
//! e ≈ 0.9 becomes `damping.contact`.
//!
//! The pair's overlap c obeys, from first touch (c = 0, ċ = v) until the bodies part,
//!
//! ```text
//! μ c̈ = −max(0, a c^α + γ g(c) ċ),   g = 1 (linear dashpot) or √c (Hertzian dashpot)
//! ```
//!
//! with μ the reduced mass. The contact never pulls: on the way out the force reaches zero
//! before the overlap does (its dashpot part is negative then), and from there the bodies move
//! apart at a constant relative velocity −e v. So e is read where the force first vanishes on
//! the rebound. The integration is RK4, its steps growing from a millionth of their size at
//! first touch (where c^α and √c are not smooth) and halved onto that event, repeated with
//! twice the steps until two answers agree to the asked tolerance.
//!
//! For the Hertzian law (α = 3/2) and little damping, e = 1 − C1 x + O(x²),
//! x = (γ/a)(a/μ)^{2/5} v^{1/5}, C1 = 1.15344 (Schwager and Pöschel, Phys. Rev. E 57, 650
//! (1998)): e falls with the impact velocity, as measured. The tests check C1 and the v^{1/5}.

use crate::damping::DashpotLaw;

/// An isolated pair of bodies and the contact between them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair {
    /// μ = m1 m2 / (m1 + m2).
    pub reduced_mass: f64,
    /// a, the contact's coefficient.
    pub coefficient: f64,
    /// α, its exponent (≥ 1).
    pub exponent: f64,
    /// The dashpot's law.
    pub law: DashpotLaw,
}

/// Why no dashpot gives the asked restitution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RestitutionError {
    /// e outside (0, 1].
    #[error(
        "e = {e} must lie in (0, 1]: 1 is an elastic contact, and no contact stops the bodies dead"
    )]
    OutOfRange {
        /// The asked e.
        e: f64,
    },
    /// A pair or velocity that is not a positive finite number.
    #[error("{what} must be finite and > 0, got {value}")]
    NotPositive {
        /// Which.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// Even the stiffest dashpot searched leaves more than e (the linear law's floor).
    #[error("e = {e} is below what any dashpot of this law gives at this velocity (γ up to {gamma:e} gives {reached})")]
    Unreachable {
        /// The asked e.
        e: f64,
        /// The largest γ tried.
        gamma: f64,
        /// Its e.
        reached: f64,
    },
    /// The integration did not settle to the tolerance.
    #[error("the collision did not settle to {tolerance:e} within {steps} steps")]
    NotConverged {
        /// The tolerance.
        tolerance: f64,
        /// Steps of the finest run.
        steps: usize,
    },
}

/// Most steps a collision is split into (before halving onto the parting event).
const MAX_STEPS: usize = 1 << 22;
/// Fewest.
const MIN_STEPS: usize = 256;
/// Largest γ the search tries, in units of the pair's own γ scale.
const MAX_GAMMA_SCALE: f64 = 1e12;

impl Pair {
    /// The pair of bodies of masses `m1` and `m2` through a contact `coefficient` with
    /// `exponent` and a dashpot of `law`.
    pub fn new(m1: f64, m2: f64, coefficient: f64, exponent: f64, law: DashpotLaw) -> Pair {
        Pair {
            reduced_mass: m1 * m2 / (m1 + m2),
            coefficient,
            exponent,
            law,
        }
    }

    /// The deepest overlap of the elastic collision at `v`, μ v²/2 = a c^{α+1}/(α+1).
    fn elastic_overlap(&self, v: f64) -> f64 {
        let alpha = self.exponent;
        ((alpha + 1.0) * self.reduced_mass * v * v / (2.0 * self.coefficient))
            .powf(1.0 / (alpha + 1.0))
    }

    /// The γ of the dashpot whose force at the elastic collision's deepest overlap and speed v
    /// equals its spring force there: the scale the search starts from.
    fn gamma_scale(&self, v: f64) -> f64 {
        let c = self.elastic_overlap(v);
        self.coefficient * c.powf(self.exponent) / self.law.force(1.0, c, v)
    }

    /// The contact force at overlap `c` closing at `rate`, before the clip at zero.
    fn unclipped_force(&self, gamma: f64, c: f64, rate: f64) -> f64 {
        let c = c.max(0.0);
        self.coefficient * c.powf(self.exponent) + self.law.force(gamma, c, rate)
    }
}

/// e of `pair` with dashpot `gamma` meeting at `velocity`, to `tolerance`.
pub fn restitution(
    pair: &Pair,
    gamma: f64,
    velocity: f64,
    tolerance: f64,
) -> Result<f64, RestitutionError> {
    check_pair(pair, velocity)?;
    let mut steps = MIN_STEPS;
    let mut previous = collide(pair, gamma, velocity, steps);
    while steps < MAX_STEPS {
        steps *= 2;
        let e = collide(pair, gamma, velocity, steps);
        if (e - previous).abs() <= 0.1 * tolerance {
            return Ok(e);
        }
        previous = e;
    }
    Err(RestitutionError::NotConverged { tolerance, steps })
}

/// The dashpot γ ≥ 0 that gives `pair` the restitution `e` at `velocity`, e to `tolerance`.
pub fn dashpot_for(
    pair: &Pair,
    e: f64,
    velocity: f64,
    tolerance: f64,
) -> Result<f64, RestitutionError> {
    check_pair(pair, velocity)?;
    if !(e > 0.0 && e <= 1.0) {
        return Err(RestitutionError::OutOfRange { e });
    }
    if e == 1.0 {
        return Ok(0.0);
    }
    let at = |gamma: f64| restitution(pair, gamma, velocity, tolerance);
    // Bracket: e(γ) falls from 1 at γ = 0.
    let scale = pair.gamma_scale(velocity);
    let (mut low, mut high) = (0.0, scale * (1.0 - e));
    let mut reached = at(high)?;
    while reached > e {
        if high > MAX_GAMMA_SCALE * scale {
            return Err(RestitutionError::Unreachable {
                e,
                gamma: high,
                reached,
            });
        }
        (low, high) = (high, 2.0 * high);
        reached = at(high)?;
    }
    // Bisection: e is monotone in γ, and each step halves the bracket.
    while high - low > 1e-13 * high {
        let middle = 0.5 * (low + high);
        let value = at(middle)?;
        if (value - e).abs() <= 0.1 * tolerance {
            return Ok(middle);
        }
        match value > e {
            true => low = middle,
            false => high = middle,
        }
    }
    Ok(0.5 * (low + high))
}

fn check_pair(pair: &Pair, velocity: f64) -> Result<(), RestitutionError> {
    for (what, value) in [
        ("the reduced mass", pair.reduced_mass),
        ("the contact coefficient", pair.coefficient),
        ("the impact velocity", velocity),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(RestitutionError::NotPositive { what, value });
        }
    }
    Ok(())
}

/// One collision in `steps` RK4 steps over the elastic contact's time scale, each step that
/// would cross the parting event (the force reaching zero on the rebound, or the overlap
/// closing) halved onto it; e = −ċ / v there.
fn collide(pair: &Pair, gamma: f64, v: f64, steps: usize) -> f64 {
    let scale = pair.elastic_overlap(v) / v;
    let full = 8.0 * scale / steps as f64;
    // The force grows as c^α and √c ċ from first touch, whose derivatives are singular there:
    // steps start a millionth of the full step and double up to it, so the onset costs RK4
    // none of its order.
    let mut h = full * 1e-6;
    let smallest = 1e-15 * scale;
    let (mut c, mut rate) = (0.0_f64, v);
    let accel =
        |c: f64, rate: f64| -pair.unclipped_force(gamma, c, rate).max(0.0) / pair.reduced_mass;
    let parted =
        |c: f64, rate: f64| rate < 0.0 && (c <= 0.0 || pair.unclipped_force(gamma, c, rate) <= 0.0);
    for _ in 0..16 * steps {
        let (k1c, k1v) = (rate, accel(c, rate));
        let (k2c, k2v) = (
            rate + 0.5 * h * k1v,
            accel(c + 0.5 * h * k1c, rate + 0.5 * h * k1v),
        );
        let (k3c, k3v) = (
            rate + 0.5 * h * k2v,
            accel(c + 0.5 * h * k2c, rate + 0.5 * h * k2v),
        );
        let (k4c, k4v) = (rate + h * k3v, accel(c + h * k3c, rate + h * k3v));
        let next_c = c + h / 6.0 * (k1c + 2.0 * k2c + 2.0 * k3c + k4c);
        let next_rate = rate + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if parted(next_c, next_rate) {
            if h <= smallest {
                return -next_rate / v;
            }
            h *= 0.5;
            continue;
        }
        (c, rate) = (next_c, next_rate);
        h = (2.0 * h).min(full);
    }
    -rate / v
}

#[cfg(test)]
mod tests;
