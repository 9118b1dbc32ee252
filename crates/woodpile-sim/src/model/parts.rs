//! What a model was built from, and nothing it derived: what a cache key must hash. Each
//! `parts` ([`Model::parts`], [`ContactLaw::parts`](crate::ContactLaw::parts), [`Region::parts`](crate::energy::Region::parts))
//! takes its type apart with no `..`, so a field added to one fails to compile there until it
//! is sorted into a defining part (hashed) or a derived one (named and dropped, with the
//! reason).

use super::{Boundary, Model, Resonator};
use crate::contact::LawOf;
use crate::damping::Damping;

/// The defining parts of a [`Model`].
#[derive(Debug, Clone)]
pub struct ModelParts<'a> {
    /// The number of sites S.
    pub n_sites: usize,
    /// The ends.
    pub boundary: Boundary,
    /// The resonators, in the model's order.
    pub resonators: &'a [Resonator],
    /// Every site's mass; `None` when all are 1.
    pub site_masses: Option<&'a [f64]>,
    /// The contact law.
    pub contacts: LawOf<'a>,
    /// The dashpots and ground damping, if any.
    pub damping: Option<&'a Damping>,
}

impl Model {
    /// The parts this model was built from.
    pub fn parts(&self) -> ModelParts<'_> {
        let Model {
            n_sites,
            boundary,
            resonators,
            site_masses,
            law,
            damping,
            // Derived: the masses' inverses, from `site_masses` and the resonators' eps.
            inv_mass: _,
            // Derived: whether `damping` or a soft end's dashpot dissipates.
            dissipative: _,
            // Derived from `boundary`.
            walls: _,
            soft_end: _,
        } = self;
        ModelParts {
            n_sites: *n_sites,
            boundary: *boundary,
            resonators,
            site_masses: site_masses.as_deref(),
            contacts: law.describe(),
            damping: damping.as_deref(),
        }
    }
}
