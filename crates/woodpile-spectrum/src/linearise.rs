//! From a woodpile-sim [`Model`] and its static state to a [`LinearChain`]: the only module that
//! knows the simulator's types, kept apart from the numerics.
//!
//! About static overlaps δ_b (bond numbering of woodpile-sim: bond 0 the left wall, bond b
//! joining sites b − 1 and b, bond S the right wall):
//!
//! ```text
//! contact b:   K_b = α a_b δ_b^{α−1}              (Hertz, α = 3/2: K_b = (3/2) a_b δ_b^{1/2})
//!              c_b = γ (linear dashpot) or γ δ_b^{1/2} (Hertzian dashpot)
//! soft end:    K = spring, c = damping             (its own spring, whatever δ says)
//! free end:    K = c = 0
//! resonator:   k = κ(t) for p = 1; for p > 1 at zero static stretch the force κ s^p has no
//!              linear part, so the resonator is detached: left out and listed
//! ground:      g on every site; resonator dashpots c_j
//! ```
//!
//! The paper's chain (no [`woodpile_sim::ContactLaw`]) has a_b = 1 and α = 3/2. A contact
//! between two sites with δ_b = 0 carries no load: the chain is a sonic vacuum and has no linear
//! spectrum, which is refused ([`SpectrumError::NoStaticLoad`]) rather than returned as zeros. A
//! wall contact with δ_b = 0 is open, a free end; a chain none of whose contacts is loaded is
//! refused too.

use woodpile_sim::{End, Model};

use crate::chain::{length, non_negative, ChainSpec, LinearChain, LinearResonator};
use crate::error::SpectrumError;

/// The linear chain of a model, and the resonators that have no linear coupling.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearised {
    /// The chain, resonators in the model's order less the detached ones.
    pub chain: LinearChain,
    /// Indices (in the model's order) of the resonators left out: p > 1, or κ(t) = 0.
    pub detached: Vec<usize>,
}

/// The linear chain of `model` about static overlaps `overlaps` (one per bond, S + 1, each
/// ≥ 0; entries for soft or free ends are not read), with the couplings at time `time`.
pub fn linearise(model: &Model, overlaps: &[f64], time: f64) -> Result<Linearised, SpectrumError> {
    let n = model.n_sites();
    length("overlaps", overlaps.len(), n + 1)?;
    for (bond, &delta) in overlaps.iter().enumerate() {
        non_negative(|| format!("static overlap of bond {bond}"), delta)?;
    }
    let (bond_stiffness, bond_damping) = bonds(model, overlaps)?;
    let damping = model.damping();
    let mut resonators = Vec::new();
    let mut detached = Vec::new();
    for (j, r) in model.resonators().iter().enumerate() {
        let kappa = r.coupling.at(time);
        if r.p != 1 || kappa == 0.0 {
            detached.push(j);
            continue;
        }
        resonators.push(LinearResonator {
            site: r.site,
            mass: r.eps,
            stiffness: kappa,
            damping: damping.map_or(0.0, |d| d.resonator(j)),
        });
    }
    let spec = ChainSpec {
        masses: (0..n).map(|site| model.site_mass(site)).collect(),
        bond_stiffness,
        bond_damping,
        ground_damping: vec![damping.map_or(0.0, |d| d.ground); n],
        resonators,
    };
    Ok(Linearised {
        chain: LinearChain::new(spec)?,
        detached,
    })
}

/// [`linearise`] about the static state of the model's own precompression (its
/// [`woodpile_sim::ContactLaw`]'s overlaps; none for the paper's chain, which is then refused
/// as a sonic vacuum).
pub fn linearise_precompressed(model: &Model, time: f64) -> Result<Linearised, SpectrumError> {
    let overlaps: Vec<f64> = (0..=model.n_sites())
        .map(|bond| model.static_overlap(bond))
        .collect();
    linearise(model, &overlaps, time)
}

/// K_b and c_b for bonds 0..=S (see the module documentation).
fn bonds(model: &Model, overlaps: &[f64]) -> Result<(Vec<f64>, Vec<f64>), SpectrumError> {
    let n = model.n_sites();
    let contact = |bond: usize| -> (f64, f64) {
        let delta = overlaps[bond];
        let stiffness = model.contact_stiffness(bond, delta);
        // The dashpot's force per unit closing rate at the static overlap.
        let damping = model
            .damping()
            .map_or(0.0, |d| d.law.force(d.contact_at(bond), delta, 1.0));
        match delta > 0.0 {
            true => (stiffness, damping),
            false => (0.0, 0.0),
        }
    };
    let end = |end: End, bond: usize| match end {
        End::Fixed => contact(bond),
        End::Free => (0.0, 0.0),
        End::Soft { spring, damping } => (spring, damping),
    };
    let boundary = model.boundary();
    let mut pairs = Vec::with_capacity(n + 1);
    pairs.push(end(boundary.left(), 0));
    for (bond, &overlap) in overlaps.iter().enumerate().take(n).skip(1) {
        if overlap == 0.0 {
            return Err(SpectrumError::NoStaticLoad { bond, overlap });
        }
        pairs.push(contact(bond));
    }
    pairs.push(end(boundary.right(), n));
    let walls = [(boundary.left(), 0), (boundary.right(), n)];
    let wall_loaded = walls
        .iter()
        .any(|&(e, bond)| matches!(e, End::Fixed) && overlaps[bond] > 0.0);
    let soft = walls.iter().any(|&(e, _)| matches!(e, End::Soft { .. }));
    if n == 1 && !wall_loaded && !soft {
        return Err(SpectrumError::NoStaticLoad {
            bond: 0,
            overlap: overlaps[0],
        });
    }
    Ok(pairs.into_iter().unzip())
}

#[cfg(test)]
mod tests;
