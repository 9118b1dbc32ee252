//! A one-sided linear spring across a gap: the contact of beads hung apart by a clearance, or of
//! rods with a loose fit. Bond b pushes only once its members have closed its gap g_b:
//!
//! ```text
//! force of contact b:     k_b [r − g_b]_+,       r = u_left − u_right
//! potential of contact b: k_b/2 [r − g_b]_+^2
//! ```
//!
//! The gap is a negative static overlap: the total overlap is c_b = r − g_b, the rest state
//! (u = 0) has every contact open and no force, and the contact scan, the event correction and
//! the energy read it as they read a precompressed chain's overlap. This file is the whole law,
//! the worked example of docs/adding-a-law.md; its known answer is the period of a pair of
//! beads bouncing between two walls.

use super::{scaled, Law, LawOf, NEGLIGIBLE_FORCE};
use crate::error::ModelError;
use crate::integrate::contact_event::{oscillating_path_integrals, path_integrals_of, BondPath};

/// A stiffness and a gap per bond (walls included): see the module documentation.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearGap {
    /// k_b for bonds 0..=S.
    stiffness: Vec<f64>,
    /// −g_b for bonds 0..=S: the total overlap at rest.
    rest_overlap: Vec<f64>,
    /// g_b for bonds 0..=S, as given (what a key hashes).
    gap: Vec<f64>,
}

impl LinearGap {
    /// The contacts of a chain of `stiffness.len() - 1` sites, bond b with stiffness
    /// `stiffness[b]` > 0 and gap `gap[b]` ≥ 0 (0: touching at rest).
    pub fn new(stiffness: Vec<f64>, gap: Vec<f64>) -> Result<LinearGap, ModelError> {
        if gap.len() != stiffness.len() {
            return Err(ModelError::BondCount {
                n_bonds: gap.len(),
                n_sites: stiffness.len().saturating_sub(1),
            });
        }
        for (bond, (&k, &g)) in stiffness.iter().zip(&gap).enumerate() {
            if !(k.is_finite() && k > 0.0) {
                let what = format!("stiffness of contact {bond}");
                return Err(ModelError::NotPositive { what, value: k });
            }
            if !(g.is_finite() && g >= 0.0) {
                let what = format!("gap of contact {bond}");
                return Err(ModelError::Negative { what, value: g });
            }
        }
        let rest_overlap = gap.iter().map(|&g| -g).collect();
        Ok(LinearGap {
            stiffness,
            rest_overlap,
            gap,
        })
    }
}

impl Law for LinearGap {
    fn n_bonds(&self) -> Option<usize> {
        Some(self.stiffness.len())
    }

    /// Taken apart with no `..`: a field added to the law fails to compile here until it is
    /// hashed or named as derived.
    fn describe(&self) -> LawOf<'_> {
        let LinearGap {
            stiffness,
            gap,
            // Derived from `gap`.
            rest_overlap: _,
        } = self;
        LawOf::Named {
            name: "linear-gap",
            numbers: vec![("stiffness", stiffness), ("gap", gap)],
        }
    }

    fn exponent(&self) -> f64 {
        1.0
    }

    fn gravity(&self) -> f64 {
        0.0
    }

    #[inline(always)]
    fn static_overlap(&self, bond: usize) -> f64 {
        self.rest_overlap[bond]
    }


    #[inline(always)]
    fn elastic(&self, bond: usize, r: f64) -> f64 {
        self.stiffness[bond] * (self.rest_overlap[bond] + r).max(0.0)
    }

    fn static_force(&self, _bond: usize) -> f64 {
        0.0
    }

    #[inline(always)]
    fn net(&self, _bond: usize, elastic: f64) -> f64 {
        elastic
    }

    fn potential(&self, bond: usize, r: f64) -> f64 {
        let c = (self.rest_overlap[bond] + r).max(0.0);
        0.5 * self.stiffness[bond] * c * c
    }

    fn static_overlaps(&self) -> Option<&[f64]> {
        Some(&self.rest_overlap)
    }

    fn path_integrals(&self, bond: usize, path: &BondPath, h: f64) -> (f64, f64) {
        scaled(self.stiffness[bond], path_integrals_of(path, h, |c| c.max(0.0)))
    }

    fn oscillating_integrals(
        &self,
        bond: usize,
        path: &BondPath,
        h: f64,
        theta: f64,
    ) -> (f64, f64) {
        scaled(self.stiffness[bond], oscillating_path_integrals(path, h, theta, |c| c.max(0.0)))
    }

    fn force_negligible(&self, bond: usize, c: f64) -> bool {
        self.stiffness[bond] * c.max(0.0) < NEGLIGIBLE_FORCE
    }

    fn stiffness(&self, bond: usize, c: f64) -> f64 {
        if c > 0.0 {
            self.stiffness[bond]
        } else {
            0.0
        }
    }

    /// k c²/2 ≤ energy bounds the total overlap by √(2 energy / k).
    fn overlap_within(&self, bond: usize, energy: f64) -> f64 {
        (2.0 * energy.max(0.0) / self.stiffness[bond]).sqrt()
    }

    /// The stiffness is k wherever the contact is closed.
    fn stiffness_within(&self, bond: usize, _energy: f64) -> Option<f64> {
        Some(self.stiffness[bond])
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::energy::Region;
    use crate::integrate::{Accuracy, MethodChoice};
    use crate::model::{Boundary, Model};
    use crate::simulation::{simulate, Scenario};
    use std::f64::consts::PI;

    const STIFFNESS: f64 = 2.0;
    const GAP: f64 = 1.0;
    const SPEED: f64 = 0.5;

    /// Two unit beads between walls, every contact of stiffness k across a gap g, the left
    /// bead struck at speed v, run to `t_end` at tolerance 1e-10.
    fn bouncing_pair(t_end: f64) -> Vec<f64> {
        let law = LinearGap::new(vec![STIFFNESS; 3], vec![GAP; 3]).unwrap();
        let model = Model::new(2, Boundary::Fixed, vec![])
            .unwrap()
            .with_law(law)
            .unwrap();
        let scenario = Scenario {
            model,
            impulse_site: 0,
            impulse_velocity: SPEED,
            t_end,
            region: Region::new(1, 1, 2).unwrap(),
            method: MethodChoice::Auto,
            accuracy: Accuracy {
                tolerance: 1e-10,
                tolerance_explicit: true,
                dt: None,
            },
            sample_every: t_end,
        };
        simulate(&scenario, &mut ()).unwrap().final_state
    }

    /// Equal beads exchange their velocities through a linear contact that lasts
    /// τ = π/√(2k) (the pair's reduced mass is 1/2), while their centre of mass moves at v/2.
    /// A bead bounces off a wall in π/√k. So the struck bead flies g/v, the pair touches for
    /// τ and the left bead stops at g + vτ/2; the right bead flies g − vτ/2 to its wall, bounces
    /// and flies back as far, the pair touches again for τ and leaves the left bead at g, which
    /// flies 2g to its wall, bounces and flies g back to 0: the motion repeats after
    /// T = 6g/v + τ + 2π/√k.
    #[test]
    fn a_bouncing_pair_repeats_with_its_closed_form_period() {
        let (k, g, v) = (STIFFNESS, GAP, SPEED);
        let touch = PI / (2.0 * k).sqrt();
        let wall = PI / k.sqrt();

        // Just after the first touch: the left bead at rest at g + vτ/2, the right one flying.
        let after = 0.1 * g / v;
        let state = bouncing_pair(g / v + touch + after);
        let expected = [g + v * touch / 2.0, v * touch / 2.0 + v * after, 0.0, v];
        for (got, want) in state.iter().zip(expected) {
            assert!((got - want).abs() < 1e-9, "{state:?} against {expected:?}");
        }

        // One whole period later the pair is back where it started.
        let period = 6.0 * g / v + touch + 2.0 * wall;
        let state = bouncing_pair(period);
        for (got, want) in state.iter().zip([0.0, 0.0, v, 0.0]) {
            assert!((got - want).abs() < 1e-9, "{state:?} after T = {period}");
        }
    }

    #[test]
    fn force_is_the_derivative_of_the_potential_and_zero_across_the_gap() {
        let law = LinearGap::new(vec![1.5, 3.0], vec![0.2, 0.0]).unwrap();
        for bond in 0..2 {
            assert_eq!(law.elastic(bond, 0.0), 0.0);
            assert_eq!(law.potential(bond, 0.0), 0.0);
            for r in [-0.3, 0.1, 0.25, 0.7] {
                let h = 1e-6;
                let slope = (law.potential(bond, r + h) - law.potential(bond, r - h)) / (2.0 * h);
                let force = law.net(bond, law.elastic(bond, r));
                assert!((slope - force).abs() < 1e-8, "bond {bond}, r {r}");
            }
        }
        assert_eq!(law.elastic(0, 0.2), 0.0);
        assert!(law.elastic(0, 0.21) > 0.0);
    }

    #[test]
    fn bad_gaps_and_stiffnesses_are_refused() {
        assert!(LinearGap::new(vec![1.0, 0.0], vec![0.0, 0.0]).is_err());
        assert!(LinearGap::new(vec![1.0, 1.0], vec![0.0, -0.1]).is_err());
        assert!(LinearGap::new(vec![1.0, 1.0], vec![0.0]).is_err());
    }
}
