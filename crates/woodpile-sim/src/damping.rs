//! Dissipation: contact dashpots, ground damping and resonator dashpots (docs/scene.md,
//! `[damping]`), with the dissipated power that the energy ledger integrates.
//!
//! ```text
//! contact b (while c_b > 0):  F_b = max(0, a_b c_b^α + γ g(c_b) ċ_b),   g = 1 ("linear") or √c ("hertzian")
//! ground:                     −g u̇_n on every site
//! resonator j:                −c_j (u̇_s − v̇_j) on its host, the opposite on the resonator
//! ```
//!
//! A contact's total force never pulls: it is clipped at zero. Its dissipated power is its
//! dashpot force after clipping, F_b − a_b c_b^α, times ċ_b (never negative: the clip acts only
//! while the contact opens). Soft ends carry their own dashpot ([`crate::model::End::Soft`]).
//!
//! The forces themselves are [`crate::damped_force`]'s. A model with any of these has one more state entry, D, the energy dissipated so far
//! ([`crate::model::Model::is_dissipative`]): the ledger E(t) + D(t) = E(0) then replaces
//! energy conservation, and the fractions are normalised by E(0).

use crate::error::ModelError;

/// How a contact's dashpot force grows with its overlap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DashpotLaw {
    /// γ ċ: the force jumps to γ ċ as the contact closes.
    Linear,
    /// γ √c ċ (Kuwabara–Kono / Tsuji): the force grows from zero with the overlap.
    Hertzian,
}

impl DashpotLaw {
    /// The scene-file name.
    pub fn name(self) -> &'static str {
        match self {
            DashpotLaw::Linear => "linear",
            DashpotLaw::Hertzian => "hertzian",
        }
    }

    /// The dashpot force γ g(c) ċ of a contact at total overlap `c` > 0 closing at rate `rate`.
    #[inline(always)]
    pub fn force(self, gamma: f64, c: f64, rate: f64) -> f64 {
        match self {
            DashpotLaw::Linear => gamma * rate,
            DashpotLaw::Hertzian => gamma * c.max(0.0).sqrt() * rate,
        }
    }
}

/// The dissipation of a chain besides its soft ends: see the module documentation.
#[derive(Debug, Clone, PartialEq)]
pub struct Damping {
    /// γ, every contact's dashpot (walls and a striker's contact included).
    pub contact: f64,
    /// The dashpot's law.
    pub law: DashpotLaw,
    /// g, the ground damping of every site.
    pub ground: f64,
    /// c_j, one per resonator in the model's order.
    pub resonator: Vec<f64>,
    /// γ_b of each bond (walls included, the bond numbering of [`crate::contact`]) where a
    /// segment or the striker gives its own dashpot; `None`: every contact has `contact`.
    pub contacts: Option<Vec<f64>>,
}

impl Damping {
    /// Damping with these coefficients, each finite and ≥ 0.
    pub fn new(
        contact: f64,
        law: DashpotLaw,
        ground: f64,
        resonator: Vec<f64>,
    ) -> Result<Damping, ModelError> {
        let named = [("damping.contact", contact), ("damping.ground", ground)];
        for (what, value) in named {
            non_negative(what, value)?;
        }
        for (j, &c) in resonator.iter().enumerate() {
            non_negative(&format!("resonator {j} damping"), c)?;
        }
        Ok(Damping {
            contact,
            law,
            ground,
            resonator,
            contacts: None,
        })
    }

    /// The same damping with each bond's own γ_b (`contacts[b]`, walls included), each finite
    /// and ≥ 0: what segments and a striker with their own dashpots give.
    pub fn with_contacts(self, contacts: Vec<f64>) -> Result<Damping, ModelError> {
        for (b, &c) in contacts.iter().enumerate() {
            non_negative(&format!("contact {b} damping"), c)?;
        }
        Ok(Damping {
            contacts: Some(contacts),
            ..self
        })
    }

    /// γ of bond `bond`: its own, or every contact's.
    #[inline(always)]
    pub fn contact_at(&self, bond: usize) -> f64 {
        match &self.contacts {
            Some(each) => each[bond],
            None => self.contact,
        }
    }

    /// Whether any contact has a dashpot.
    pub fn has_contact_dashpot(&self) -> bool {
        match &self.contacts {
            Some(each) => each.iter().any(|&c| c > 0.0),
            None => self.contact > 0.0,
        }
    }

    /// Whether any coefficient is non-zero: a model with none keeps the conservative path.
    pub fn dissipates(&self) -> bool {
        self.has_contact_dashpot() || self.ground > 0.0 || self.resonator.iter().any(|&c| c > 0.0)
    }

    /// The resonator `j`'s dashpot (0 when none was given).
    #[inline(always)]
    pub fn resonator(&self, j: usize) -> f64 {
        self.resonator.get(j).copied().unwrap_or(0.0)
    }
}

fn non_negative(what: &str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ModelError::Negative {
            what: what.into(),
            value,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn laws_and_refusals() {
        assert_eq!(DashpotLaw::Linear.force(2.0, 0.25, 3.0), 6.0);
        assert_eq!(DashpotLaw::Hertzian.force(2.0, 0.25, 3.0), 3.0);
        assert!(Damping::new(-1.0, DashpotLaw::Linear, 0.0, vec![]).is_err());
        assert!(Damping::new(0.0, DashpotLaw::Linear, f64::NAN, vec![]).is_err());
        assert!(Damping::new(0.0, DashpotLaw::Linear, 0.0, vec![f64::INFINITY]).is_err());
        let none = Damping::new(0.0, DashpotLaw::Hertzian, 0.0, vec![0.0]).unwrap();
        assert!(!none.dissipates());
        assert!(Damping::new(0.0, DashpotLaw::Linear, 0.0, vec![0.0, 0.1])
            .unwrap()
            .dissipates());
    }
}
