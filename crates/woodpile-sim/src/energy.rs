//! Energy density, total energy and the reflected / transmitted / trapped fractions
//! (paper Eq. 5, generalised to many resonators, exponent p and walls).
//!
//! ```text
//! e_n = m_n u_n'^2/2 + [n = s_j] (eps_j v_j'^2/2 + kappa_j (u_n - v_j)^{p_j+1}/(p_j+1))
//!       + ([u_{n-1} - u_n]_+^{5/2} + [u_n - u_{n+1}]_+^{5/2}) / 5
//! ```
//!
//! Each contact's potential (2/5) d^{5/2} is split half to each neighbour. A wall contact belongs
//! wholly to its end site, so that the sum of e_n is the conserved Hamiltonian through wall
//! collisions.

use crate::contact::{with_law, Law};
use crate::error::ModelError;
use crate::model::{odd_power, Model};

/// A "defect region" of sites [lo, hi] (inclusive, internal 0-based numbering). Energy left of
/// it is reflected, right of it transmitted, inside it trapped. With a striker (the chain's
/// site 0, a body that hits the first site), the striker's own energy is a fourth share, S.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Region {
    lo: usize,
    hi: usize,
    /// 1 when site 0 is a striker, whose energy is neither reflected nor transmitted; else 0.
    striker_sites: usize,
}

/// The defining parts of a [`Region`] ([`Region::parts`]).
#[derive(Debug, Clone, Copy)]
pub struct RegionParts {
    /// Its first site (internal index).
    pub lo: usize,
    /// Its last site.
    pub hi: usize,
    /// Whether site 0 is a striker, whose energy is the share S.
    pub striker: bool,
}

impl Region {
    /// A region of sites `lo..=hi` in a chain of `n_sites`.
    pub fn new(lo: i64, hi: i64, n_sites: usize) -> Result<Self, ModelError> {
        if lo < 0 || hi < lo || hi >= n_sites as i64 {
            return Err(ModelError::BadRegion { lo, hi, n_sites });
        }
        Ok(Self {
            lo: lo as usize,
            hi: hi as usize,
            striker_sites: 0,
        })
    }

    /// The same region in a chain whose site 0 is a striker: its energy is the share S. The
    /// region must not contain the striker.
    pub fn with_striker(self) -> Result<Self, ModelError> {
        if self.lo == 0 {
            return Err(ModelError::BadRegion {
                lo: 0,
                hi: self.hi as i64,
                n_sites: self.hi + 1,
            });
        }
        Ok(Self {
            striker_sites: 1,
            ..self
        })
    }

    /// The parts this region was built from, taken apart with no `..` (see
    /// [`crate::model::parts`]).
    pub fn parts(&self) -> RegionParts {
        let Region {
            lo,
            hi,
            striker_sites,
        } = *self;
        RegionParts {
            lo,
            hi,
            striker: striker_sites == 1,
        }
    }

    /// Whether site 0 is a striker.
    pub fn has_striker(&self) -> bool {
        self.striker_sites == 1
    }

    /// First site of the region.
    pub fn lo(&self) -> usize {
        self.lo
    }

    /// Last site of the region.
    pub fn hi(&self) -> usize {
        self.hi
    }
}

/// Energy fractions of one moment, normalised by the total of the density passed in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fractions {
    /// R: share of sites left of the region.
    pub reflected: f64,
    /// T: share of sites right of the region.
    pub transmitted: f64,
    /// E_tr: share inside the region.
    pub trapped: f64,
    /// S: the striker's share (its kinetic energy and half its contact's potential); 0
    /// without a striker.
    pub striker: f64,
    /// D: the share dissipated so far; 0 for a conservative chain.
    pub dissipated: f64,
    /// The total the shares are normalised by: the energy held at that moment, or E(0) for a
    /// dissipative chain ([`Fractions::of_ledger`]).
    pub total: f64,
}

impl Fractions {
    /// Splits a per-site density into the shares of `region`.
    pub fn from_density(density: &[f64], region: Region) -> Self {
        let held = Held::of(density, region);
        Self {
            dissipated: 0.0,
            ..Self::divided(held, 0.0, held.total)
        }
    }

    /// The shares of a dissipative chain: the density's parts and the energy `dissipated`
    /// so far, each divided by the initial energy `e_initial`, so that R + T + E_tr + S + D
    /// = 1 up to the integration error.
    pub fn of_ledger(density: &[f64], region: Region, dissipated: f64, e_initial: f64) -> Self {
        Self::divided(Held::of(density, region), dissipated, e_initial)
    }

    /// `held`'s parts and `dissipated`, each divided by `total`.
    fn divided(held: Held, dissipated: f64, total: f64) -> Self {
        Self {
            reflected: held.left / total,
            transmitted: held.right / total,
            trapped: held.inside / total,
            striker: held.striker / total,
            dissipated: dissipated / total,
            total,
        }
    }

    /// The fractions of state `y` of `model` at time `t`, from its energy `density` (scratch
    /// of length `n_sites`): normalised by the energy held, or, for a dissipative chain, by
    /// `e_initial` with D among them.
    pub fn of_state(
        model: &Model,
        (t, y): (f64, &[f64]),
        region: Region,
        e_initial: f64,
        density: &mut [f64],
    ) -> Self {
        energy_density(model, t, y, density);
        match model.is_dissipative() {
            true => Self::of_ledger(density, region, model.dissipated(y), e_initial),
            false => Self::from_density(density, region),
        }
    }

    /// R + T + E_tr + S + D: 1 by construction for a conservative chain, and 1 up to the
    /// integration error for a dissipative one (the ledger).
    pub fn sum(&self) -> f64 {
        self.reflected + self.transmitted + self.trapped + self.striker + self.dissipated
    }

    /// The largest difference in R, T, E_tr, S or D between two runs' fractions: the error
    /// measure of `auto`'s verification and of every accuracy check against a reference.
    pub fn largest_difference(&self, other: &Fractions) -> f64 {
        (self.reflected - other.reflected)
            .abs()
            .max((self.transmitted - other.transmitted).abs())
            .max((self.trapped - other.trapped).abs())
            .max((self.striker - other.striker).abs())
            .max((self.dissipated - other.dissipated).abs())
    }
}

/// The energy a density holds left of, inside and right of a region, and in a striker.
#[derive(Debug, Clone, Copy)]
struct Held {
    left: f64,
    inside: f64,
    right: f64,
    striker: f64,
    total: f64,
}

impl Held {
    fn of(density: &[f64], region: Region) -> Held {
        let chain = region.striker_sites;
        let left: f64 = density[chain..region.lo].iter().sum();
        let inside: f64 = density[region.lo..=region.hi].iter().sum();
        let right: f64 = density[region.hi + 1..].iter().sum();
        let (striker, total) = match chain {
            0 => (0.0, left + inside + right),
            _ => {
                let striker: f64 = density[..chain].iter().sum();
                (striker, left + inside + right + striker)
            }
        };
        Held {
            left,
            inside,
            right,
            striker,
            total,
        }
    }
}

/// The potential of bond `bond` (numbering of [`crate::contact`]) at relative displacement
/// `r`: the paper's (2/5) \[r\]_+^{5/2}, or the chain's [`crate::ContactLaw`].
fn bond_potential(model: &Model, bond: usize, r: f64) -> f64 {
    with_law!(model.law(), |law| law.potential(bond, r))
}

/// Energy density per site (length `n_sites`) of state `y` at time `t`, written into `density`.
pub fn energy_density(model: &Model, t: f64, y: &[f64], density: &mut [f64]) {
    let n_sites = model.n_sites();
    let n_dof = model.n_dof();
    let q = &y[..n_dof];
    let u = &q[..n_sites];
    kinetic_density(model, y, density);
    let boundary = model.boundary();
    let potential = |bond: usize, r: f64| bond_potential(model, bond, r);
    for bond in 0..n_sites - 1 {
        let half = 0.5 * potential(bond + 1, u[bond] - u[bond + 1]);
        density[bond] += half;
        density[bond + 1] += half;
    }
    if boundary.left_wall() {
        density[0] += potential(0, -u[0]);
    }
    if boundary.right_wall() {
        density[n_sites - 1] += potential(n_sites, u[n_sites - 1]);
    }
    if model.has_soft_end() {
        let [left, right] = spring_end_energies(model, u);
        density[0] += left;
        density[n_sites - 1] += right;
    }
    for (j, r) in model.resonators().iter().enumerate() {
        let stretch = u[r.site] - q[n_sites + j];
        let p1 = r.p + 1;
        density[r.site] += r.coupling.at(t) * odd_power(stretch, r.p) * stretch / f64::from(p1);
    }
}

/// Kinetic energy per site (host and resonators together), length `n_sites`: the quantity the
/// woodpile experiment measures (paper Section III, Fig. 2 c, f).
pub fn kinetic_density(model: &Model, y: &[f64], density: &mut [f64]) {
    let n_sites = model.n_sites();
    let n_dof = model.n_dof();
    let qdot = &y[n_dof..];
    for (site, e) in density.iter_mut().enumerate().take(n_sites) {
        *e = 0.5 * model.site_mass(site) * qdot[site] * qdot[site];
    }
    for (j, r) in model.resonators().iter().enumerate() {
        let w = qdot[n_sites + j];
        density[r.site] += 0.5 * r.eps * w * w;
    }
}

/// Total energy E = sum_n e_n, computed without allocating.
pub fn total_energy(model: &Model, t: f64, y: &[f64]) -> f64 {
    let n_sites = model.n_sites();
    let n_dof = model.n_dof();
    let (q, qdot) = y.split_at(n_dof);
    let u = &q[..n_sites];
    let mut e = 0.0;
    for (site, w) in qdot[..n_sites].iter().enumerate() {
        e += 0.5 * model.site_mass(site) * w * w;
    }
    let potential = |bond: usize, r: f64| bond_potential(model, bond, r);
    for bond in 0..n_sites - 1 {
        e += potential(bond + 1, u[bond] - u[bond + 1]);
    }
    match (model.walls()[0], model.walls()[1]) {
        (true, true) => e += potential(0, -u[0]) + potential(n_sites, u[n_sites - 1]),
        (true, false) => e += potential(0, -u[0]),
        (false, true) => e += potential(n_sites, u[n_sites - 1]),
        (false, false) => {}
    }
    if model.has_soft_end() {
        e += spring_end_energies(model, u).iter().sum::<f64>();
    }
    for (j, r) in model.resonators().iter().enumerate() {
        let w = qdot[n_sites + j];
        let stretch = u[r.site] - q[n_sites + j];
        e += 0.5 * r.eps * w * w
            + r.coupling.at(t) * odd_power(stretch, r.p) * stretch / f64::from(r.p + 1);
    }
    e
}

/// The potential k u²/2 of each soft end's spring (0 for other ends): [left, right]. It
/// belongs wholly to its end site, as a wall contact's does.
fn spring_end_energies(model: &Model, u: &[f64]) -> [f64; 2] {
    let boundary = model.boundary();
    let spring = |end: crate::model::End, x: f64| end.soft().map_or(0.0, |(k, _)| 0.5 * k * x * x);
    [
        spring(boundary.left(), u[0]),
        spring(boundary.right(), u[u.len() - 1]),
    ]
}

/// The energy ledger E(t) + D(t): the energy the chain holds plus what it has dissipated,
/// equal to E(0) for an exact solution of any scene with a constant coupling.
pub fn ledger(model: &Model, t: f64, y: &[f64]) -> f64 {
    match model.is_dissipative() {
        true => total_energy(model, t, y) + model.dissipated(y),
        false => total_energy(model, t, y),
    }
}

/// Total momentum sum m_n u_n' + sum eps_j v_j' (conserved with free ends).
pub fn total_momentum(model: &Model, y: &[f64]) -> f64 {
    let n_dof = model.n_dof();
    y[n_dof..]
        .iter()
        .zip(model.inv_mass())
        .map(|(v, inv_m)| v / inv_m)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Boundary, Resonator};

    #[test]
    fn density_sums_to_total_energy() {
        let res = vec![Resonator::constant(2, 3.0, 0.8, 3)];
        let model = Model::new(5, Boundary::Fixed, res).unwrap();
        let y = vec![
            -0.1, 0.2, 0.1, 0.05, 0.3, -0.2, 0.5, -1.0, 0.3, 0.2, 0.1, 0.7,
        ];
        let mut e = vec![0.0; 5];
        energy_density(&model, 0.0, &y, &mut e);
        let sum: f64 = e.iter().sum();
        assert!((sum - total_energy(&model, 0.0, &y)).abs() < 1e-14);
        // The wall bonds: site 0 at -0.1 is pressed into the left wall, site 4 at 0.3 into the right.
        assert!(e[0] >= crate::contact::hertz_potential(0.1));
    }

    #[test]
    fn fractions_split_the_total() {
        let region = Region::new(1, 2, 5).unwrap();
        let f = Fractions::from_density(&[1.0, 2.0, 3.0, 4.0, 0.0], region);
        assert_eq!(f.total, 10.0);
        assert!((f.reflected - 0.1).abs() < 1e-15);
        assert!((f.trapped - 0.5).abs() < 1e-15);
        assert!((f.transmitted - 0.4).abs() < 1e-15);
        assert!(Region::new(3, 2, 5).is_err());
        assert!(Region::new(0, 5, 5).is_err());
    }
}
