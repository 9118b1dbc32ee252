//! The contacts of a chain as an experiment builds it: one coefficient per contact, any
//! exponent, and a static precompression (a chain issue's model; docs/scene.md, `[chain]` and
//! `[[segment]]`).
//!
//! ```text
//! force of contact b:     a_b [c_b]_+^α − F_b,   c_b = δ_b + u_left − u_right,   F_b = a_b δ_b^α
//! potential of contact b: a_b/(α+1) ([c_b]_+^{α+1} − δ_b^{α+1}) − F_b r,   r = u_left − u_right
//! ```
//!
//! With a static force F0 held by walls at both ends, each contact's static overlap is
//! δ_b = (F0 / a_b)^{1/α}, so every contact carries F0 and the rest state u = 0 is an
//! equilibrium. Each contact subtracts its own static force F_b (equal to F0 up to rounding)
//! rather than F0 itself: then a site at rest feels exactly zero force, so the sites ahead of
//! the wave stay exactly at rest and the driver's active window skips them without changing a
//! bit. The paper's chain (every a_b = 1, α = 3/2, no precompression) has no `ContactLaw` at
//! all: it runs [`super::PaperHertz`] and keeps its own bits.

use super::{scaled, Law, LawOf, NEGLIGIBLE_FORCE};
use crate::error::ModelError;
use crate::integrate::contact_event::{oscillating_path_integrals, path_integrals_of, BondPath};

/// Smallest and largest contact exponent accepted: α = 1 is a one-sided linear spring; above 5
/// no granular contact law is in use, and the powers of a unit overlap lose precision.
pub const EXPONENT_RANGE: (f64, f64) = (1.0, 5.0);

/// The power `[d]_+^α`, with the common exponents written out (3/2 as `d √d`, exactly as the
/// paper's loop computes it).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Power {
    Linear,
    ThreeHalves,
    Square,
    General(f64),
}

impl Power {
    fn of(exponent: f64) -> Power {
        match exponent {
            1.0 => Power::Linear,
            1.5 => Power::ThreeHalves,
            2.0 => Power::Square,
            alpha => Power::General(alpha),
        }
    }

    /// `[d]_+^α`.
    #[inline(always)]
    fn at(self, d: f64) -> f64 {
        let d = d.max(0.0);
        match self {
            Power::Linear => d,
            Power::ThreeHalves => d * d.sqrt(),
            Power::Square => d * d,
            Power::General(alpha) => d.powf(alpha),
        }
    }
}

/// Per-contact coefficients, one exponent and a precompression: see the module documentation.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactLaw {
    exponent: f64,
    power: Power,
    precompression: f64,
    /// g, when the static forces are the weights above each contact (0 otherwise).
    gravity: f64,
    /// a_b for bonds 0..=S.
    coefficient: Vec<f64>,
    /// δ_b for bonds 0..=S (0 without precompression).
    static_overlap: Vec<f64>,
    /// F_b = a_b \[δ_b\]^α for bonds 0..=S.
    static_force: Vec<f64>,
}

/// The defining parts of a [`ContactLaw`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawParts<'a> {
    /// a_b for every bond, walls included.
    pub coefficients: &'a [f64],
    /// The exponent α.
    pub exponent: f64,
    /// The static force F0 the walls hold.
    pub precompression: f64,
    /// g, when the chain stands in gravity (0 otherwise).
    pub gravity: f64,
}

impl LawParts<'_> {
    /// Whether these parts make the paper's law: exponent 3/2, unit coefficients, no
    /// precompression and no gravity. Taken apart with no `..`, so that a part added to the law
    /// must say whether it keeps a chain the paper's.
    pub fn is_papers(&self) -> bool {
        let LawParts {
            coefficients,
            exponent,
            precompression,
            gravity,
        } = self;
        *exponent == 1.5
            && *precompression == 0.0
            && *gravity == 0.0
            && coefficients.iter().all(|&a| a == 1.0)
    }
}

impl ContactLaw {
    /// The parts this law was built from, taken apart with no `..` (see
    /// [`crate::model::parts`]).
    pub fn parts(&self) -> LawParts<'_> {
        let ContactLaw {
            exponent,
            precompression,
            gravity,
            coefficient,
            // Derived from `exponent`.
            power: _,
            // Derived: the rest state under the precompression or gravity's weights, from the
            // coefficients, the exponent and the masses each contact carries.
            static_overlap: _,
            static_force: _,
        } = self;
        LawParts {
            coefficients: coefficient,
            exponent: *exponent,
            precompression: *precompression,
            gravity: *gravity,
        }
    }

    /// The contacts of a chain of `coefficients.len() - 1` sites: `coefficients[b]` is a_b in
    /// the bond numbering of the module documentation (walls included, whether or not the ends
    /// are walls), `exponent` is α and `precompression` the static force F0 (0 for none).
    pub fn new(
        coefficients: Vec<f64>,
        exponent: f64,
        precompression: f64,
    ) -> Result<ContactLaw, ModelError> {
        let (lowest, highest) = EXPONENT_RANGE;
        if !(exponent >= lowest && exponent <= highest) {
            return Err(ModelError::ContactExponent { exponent });
        }
        for (bond, &a) in coefficients.iter().enumerate() {
            if !(a.is_finite() && a > 0.0) {
                return Err(ModelError::NotPositive {
                    what: format!("coefficient of contact {bond}"),
                    value: a,
                });
            }
        }
        if !(precompression.is_finite() && precompression >= 0.0) {
            return Err(ModelError::Negative {
                what: "precompression".into(),
                value: precompression,
            });
        }
        let loads = vec![precompression; coefficients.len()];
        Ok(ContactLaw::loaded(
            coefficients,
            exponent,
            &loads,
            precompression,
            0.0,
        ))
    }

    /// The contacts of a vertical chain in gravity `g` (the first site on top), whose site n
    /// carries the mass `carried[n]` (its own and its resonators'): bond b carries the weight
    /// g·Σ_{n<b} carried\[n\] of every body above it, so the rest state (u = 0) is
    /// an exact equilibrium and each contact subtracts its own static force, as under a
    /// precompression. Where a contact opens, the static force it subtracts is the weight it no
    /// longer carries: the motion about the rest state is the motion in gravity, exactly.
    pub fn under_gravity(
        coefficients: Vec<f64>,
        exponent: f64,
        carried: &[f64],
        gravity: f64,
    ) -> Result<ContactLaw, ModelError> {
        let law = ContactLaw::new(coefficients, exponent, 0.0)?;
        if !(gravity.is_finite() && gravity > 0.0) {
            return Err(ModelError::NotPositive {
                what: "gravity".into(),
                value: gravity,
            });
        }
        if carried.len() + 1 != law.coefficient.len()
            || carried.iter().any(|m| !(m.is_finite() && *m >= 0.0))
        {
            return Err(ModelError::Negative {
                what: "the mass a site carries".into(),
                value: carried.iter().copied().fold(f64::NAN, f64::min),
            });
        }
        let mut weights_above = Vec::with_capacity(carried.len() + 1);
        let mut total = 0.0;
        weights_above.push(0.0);
        for m in carried {
            total += m;
            weights_above.push(gravity * total);
        }
        Ok(ContactLaw::loaded(
            law.coefficient,
            exponent,
            &weights_above,
            0.0,
            gravity,
        ))
    }

    /// The law whose bond b carries the static force `loads[b]` (checked by the callers).
    fn loaded(
        coefficients: Vec<f64>,
        exponent: f64,
        loads: &[f64],
        precompression: f64,
        gravity: f64,
    ) -> ContactLaw {
        let power = Power::of(exponent);
        let static_overlap: Vec<f64> = coefficients
            .iter()
            .zip(loads)
            .map(|(&a, &load)| match load {
                0.0 => 0.0,
                f => (f / a).powf(1.0 / exponent),
            })
            .collect();
        let static_force = coefficients
            .iter()
            .zip(&static_overlap)
            .map(|(&a, &delta)| a * power.at(delta))
            .collect();
        ContactLaw {
            exponent,
            power,
            precompression,
            gravity,
            coefficient: coefficients,
            static_overlap,
            static_force,
        }
    }

    /// Number of bonds, walls included (sites + 1).
    pub fn n_bonds(&self) -> usize {
        self.coefficient.len()
    }

    /// The exponent α.
    pub fn exponent(&self) -> f64 {
        self.exponent
    }

    /// The static force F0 (0 without precompression).
    pub fn precompression(&self) -> f64 {
        self.precompression
    }

    /// g of a chain in gravity (0 for none): its contacts carry the weights above them.
    pub fn gravity(&self) -> f64 {
        self.gravity
    }

    /// a_b.
    pub fn coefficient(&self, bond: usize) -> f64 {
        self.coefficient[bond]
    }

    /// δ_b, the static overlap of bond `bond`.
    #[inline(always)]
    pub fn static_overlap(&self, bond: usize) -> f64 {
        self.static_overlap[bond]
    }

    /// F_b = a_b δ_b^α, the static force bond `bond` carries (F0 up to rounding).
    #[inline(always)]
    pub fn static_force(&self, bond: usize) -> f64 {
        self.static_force[bond]
    }

    /// `[c]_+^α` for a total overlap `c` (the elastic force of a unit coefficient).
    #[inline(always)]
    pub fn power(&self, c: f64) -> f64 {
        self.power.at(c)
    }

    /// The elastic force a_b [δ_b + r]_+^α of bond `bond` at relative displacement `r`
    /// (left member minus right member): what the contact-event correction integrates.
    #[inline(always)]
    pub fn elastic(&self, bond: usize, r: f64) -> f64 {
        <Self as Law>::elastic(self, bond, r)
    }

    /// The force bond `bond` adds to the rest state's: [`ContactLaw::elastic`] − F_b. Zero,
    /// exactly, at r = 0.
    #[inline(always)]
    pub fn net_force(&self, bond: usize, r: f64) -> f64 {
        self.elastic(bond, r) - self.static_force[bond]
    }

    /// The potential of bond `bond` measured from the rest state:
    /// a_b/(α+1) ([δ_b + r]_+^{α+1} − δ_b^{α+1}) − F_b r. Its derivative in r is
    /// [`ContactLaw::net_force`].
    pub fn potential(&self, bond: usize, r: f64) -> f64 {
        <Self as Law>::potential(self, bond, r)
    }

    /// The stiffness α a_b c^{α−1} of bond `bond` at total overlap `c` (> 0).
    pub fn stiffness(&self, bond: usize, c: f64) -> f64 {
        <Self as Law>::stiffness(self, bond, c)
    }

    /// A bound on the total overlap bond `bond` reaches when it holds all of `energy` on top
    /// of its static state: see the `Law` implementation below.
    pub fn overlap_within(&self, bond: usize, energy: f64) -> f64 {
        <Self as Law>::overlap_within(self, bond, energy)
    }
}

/// The law's formulas. The inherent methods of the same names call these, for the crates
/// that cannot name the trait.
impl Law for ContactLaw {
    fn n_bonds(&self) -> Option<usize> {
        Some(self.coefficient.len())
    }

    fn held_by_walls(&self) -> bool {
        self.precompression > 0.0
    }

    fn describe(&self) -> LawOf<'_> {
        LawOf::Experiment(self.parts())
    }

    fn exponent(&self) -> f64 {
        self.exponent
    }

    fn gravity(&self) -> f64 {
        self.gravity
    }

    #[inline(always)]
    fn static_overlap(&self, bond: usize) -> f64 {
        self.static_overlap[bond]
    }


    #[inline(always)]
    fn elastic(&self, bond: usize, r: f64) -> f64 {
        self.coefficient[bond] * self.power.at(self.static_overlap[bond] + r)
    }

    #[inline(always)]
    fn static_force(&self, bond: usize) -> f64 {
        self.static_force[bond]
    }

    #[inline(always)]
    fn net(&self, bond: usize, elastic: f64) -> f64 {
        elastic - self.static_force[bond]
    }

    fn potential(&self, bond: usize, r: f64) -> f64 {
        let (a, delta) = (self.coefficient[bond], self.static_overlap[bond]);
        let c = (delta + r).max(0.0);
        let rise = c * self.power.at(c) - delta * self.power.at(delta);
        a / (self.exponent + 1.0) * rise - self.static_force[bond] * r
    }

    fn static_overlaps(&self) -> Option<&[f64]> {
        let delta = &self.static_overlap;
        delta.iter().any(|&d| d > 0.0).then_some(&delta[..])
    }

    fn path_integrals(&self, bond: usize, path: &BondPath, h: f64) -> (f64, f64) {
        scaled(self.coefficient[bond], path_integrals_of(path, h, |d| self.power.at(d)))
    }

    fn oscillating_integrals(
        &self,
        bond: usize,
        path: &BondPath,
        h: f64,
        theta: f64,
    ) -> (f64, f64) {
        scaled(self.coefficient[bond], oscillating_path_integrals(path, h, theta, |d| self.power.at(d)))
    }

    fn force_negligible(&self, bond: usize, c: f64) -> bool {
        self.coefficient[bond] * self.power.at(c) < NEGLIGIBLE_FORCE
    }

    /// Since (δ + r)^α ≥ δ^α + r^α for α ≥ 1, the potential of a compression r is at least
    /// a r^{α+1}/(α+1), so r ≤ ((α+1) energy / a)^{1/(α+1)}.
    fn overlap_within(&self, bond: usize, energy: f64) -> f64 {
        let alpha1 = self.exponent + 1.0;
        let r = (alpha1 * energy.max(0.0) / self.coefficient[bond]).powf(1.0 / alpha1);
        self.static_overlap[bond] + r
    }

    fn stiffness(&self, bond: usize, c: f64) -> f64 {
        self.exponent * self.coefficient[bond] * c.max(0.0).powf(self.exponent - 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_static_state_is_an_exact_equilibrium() {
        let law = ContactLaw::new(vec![0.7, 1.0, 2.3, 0.4], 1.5, 0.8).unwrap();
        for bond in 0..4 {
            assert_eq!(law.net_force(bond, 0.0), 0.0);
            assert_eq!(law.potential(bond, 0.0), 0.0);
            // Every contact carries the static force, up to rounding.
            let carried = law.elastic(bond, 0.0);
            assert!((carried - 0.8).abs() < 1e-15, "bond {bond}: {carried}");
        }
    }

    #[test]
    fn force_is_the_derivative_of_the_potential() {
        for (exponent, f0) in [(1.5, 0.0), (1.5, 0.3), (1.0, 0.2), (2.5, 0.0), (3.7, 1.1)] {
            let law = ContactLaw::new(vec![1.3, 0.6], exponent, f0).unwrap();
            for r in [-0.4, -0.05, 0.02, 0.3, 0.9] {
                let h = 1e-6;
                let slope = (law.potential(1, r + h) - law.potential(1, r - h)) / (2.0 * h);
                let force = law.net_force(1, r);
                assert!(
                    (slope - force).abs() < 1e-7,
                    "alpha {exponent}, F0 {f0}, r {r}: {slope} vs {force}"
                );
            }
        }
    }

    #[test]
    fn three_halves_is_the_papers_power() {
        let law = ContactLaw::new(vec![1.0, 1.0], 1.5, 0.0).unwrap();
        for d in [0.0, 0.013, 0.5, 1.7] {
            assert_eq!(law.elastic(1, d), super::super::hertz_force(d));
        }
        assert_eq!(law.elastic(1, -0.2), 0.0);
    }

    #[test]
    fn bad_laws_are_refused() {
        assert!(matches!(
            ContactLaw::new(vec![1.0], 0.9, 0.0),
            Err(ModelError::ContactExponent { .. })
        ));
        assert!(ContactLaw::new(vec![1.0], f64::NAN, 0.0).is_err());
        assert!(ContactLaw::new(vec![1.0, 0.0], 1.5, 0.0).is_err());
        assert!(ContactLaw::new(vec![1.0], 1.5, -1.0).is_err());
    }
}
