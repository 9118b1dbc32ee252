//! The linear chain every computation of the crate reads: site masses, linear bonds with their
//! dashpots, ground dashpots and linear resonators, validated once so the numerics need not
//! check anything.
//!
//! ```text
//! m_n u_n'' = K_n (u_{n-1} - u_n) + K_{n+1} (u_{n+1} - u_n)              (bonds, u_{-1} = u_S = 0)
//!           + c_n (u'_{n-1} - u'_n) + c_{n+1} (u'_{n+1} - u'_n) - g_n u'_n  (dashpots, ground)
//!           + sum_{r on n} [k_r (v_r - u_n) + c_r (v'_r - u'_n)]
//! m_r v_r'' = k_r (u_n - v_r) + c_r (u'_n - v'_r)                          (resonator r on site n)
//! ```
//!
//! Bonds are numbered as woodpile-sim numbers contacts: bond b (1 ≤ b < S) joins sites b − 1
//! and b; bond 0 ties site 0 and bond S ties site S − 1 to a rigid support. Both ends are
//! described by that one bond, because in the linear picture every end is a spring and a dashpot
//! on a rigid support: a wall's linearised contact, a soft end's spring, or nothing (a free end,
//! or a wall whose contact carries no static force) when both are 0. One representation leaves
//! no inconsistent combination (a "free" end with a spring) to refuse; [`crate::transmission`]
//! reads the same two end bonds as the couplings to its leads.
//!
//! Degrees of freedom are ordered as in woodpile-sim's state: the S sites, then the resonators in
//! the order given.

use crate::error::SpectrumError;

/// A resonator in the linear picture: mass `mass` on a spring `stiffness` and a dashpot `damping`
/// to its host site.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearResonator {
    /// Host site (0-based).
    pub site: usize,
    /// Its mass m2 (> 0).
    pub mass: f64,
    /// k2 (≥ 0): the linear spring to the host; ω0 = sqrt(k2/m2) is its own frequency.
    pub stiffness: f64,
    /// c2 (≥ 0).
    pub damping: f64,
}

/// The plain data of a chain; [`LinearChain::new`] checks it. See the module documentation for
/// the bond numbering and the equations.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ChainSpec {
    /// m_n for the S sites (each > 0).
    pub masses: Vec<f64>,
    /// K_b for bonds 0..=S: interior bonds > 0, the two end bonds ≥ 0 (0 = free end).
    pub bond_stiffness: Vec<f64>,
    /// c_b for bonds 0..=S (each ≥ 0), or empty for none.
    pub bond_damping: Vec<f64>,
    /// g_n, a dashpot from each site to the ground (each ≥ 0), or empty for none.
    pub ground_damping: Vec<f64>,
    /// The resonators.
    pub resonators: Vec<LinearResonator>,
}

impl ChainSpec {
    /// `n_sites` sites of mass `mass` joined by bonds `stiffness`, walls of the same stiffness at
    /// both ends, no damping and no resonator.
    pub fn uniform(n_sites: usize, mass: f64, stiffness: f64) -> ChainSpec {
        ChainSpec {
            masses: vec![mass; n_sites],
            bond_stiffness: vec![stiffness; n_sites + 1],
            ..ChainSpec::default()
        }
    }
}

/// A validated [`ChainSpec`]: every length matches, every value is in range. Damping lists are
/// stored at full length (zeros when none was given).
#[derive(Debug, Clone, PartialEq)]
pub struct LinearChain {
    spec: ChainSpec,
    /// For site n, `by_site[start[n]..start[n+1]]` are the indices of its resonators.
    start: Vec<usize>,
    by_site: Vec<usize>,
}

impl LinearChain {
    /// Checks `spec` (see [`ChainSpec`] for what each field must satisfy).
    pub fn new(mut spec: ChainSpec) -> Result<LinearChain, SpectrumError> {
        let n = spec.masses.len();
        if n == 0 {
            return Err(SpectrumError::EmptyChain);
        }
        for (site, &m) in spec.masses.iter().enumerate() {
            positive(|| format!("mass of site {site}"), m)?;
        }
        length("bond_stiffness", spec.bond_stiffness.len(), n + 1)?;
        for (bond, &k) in spec.bond_stiffness.iter().enumerate() {
            let what = || format!("stiffness of bond {bond}");
            match bond == 0 || bond == n {
                true => non_negative(what, k)?,
                false => positive(what, k)?,
            }
        }
        fill_optional(&mut spec.bond_damping, "bond_damping", n + 1)?;
        fill_optional(&mut spec.ground_damping, "ground_damping", n)?;
        for (bond, &c) in spec.bond_damping.iter().enumerate() {
            non_negative(|| format!("damping of bond {bond}"), c)?;
        }
        for (site, &g) in spec.ground_damping.iter().enumerate() {
            non_negative(|| format!("ground damping of site {site}"), g)?;
        }
        for (j, r) in spec.resonators.iter().enumerate() {
            validate_resonator(j, r, n)?;
        }
        let (start, by_site) = index_by_site(&spec.resonators, n);
        Ok(LinearChain {
            spec,
            start,
            by_site,
        })
    }

    /// Sites `sites` as a chain of their own: their masses, resonators and ground dashpots, the
    /// bonds between them, and as end bonds the bonds that joined them to their neighbours.
    pub fn sub_chain(&self, sites: std::ops::Range<usize>) -> Result<LinearChain, SpectrumError> {
        let s = &self.spec;
        let bonds = sites.start..sites.end + 1;
        let resonators = s
            .resonators
            .iter()
            .filter(|r| sites.contains(&r.site))
            .map(|r| LinearResonator {
                site: r.site - sites.start,
                ..*r
            })
            .collect();
        LinearChain::new(ChainSpec {
            masses: s.masses[sites.clone()].to_vec(),
            bond_stiffness: s.bond_stiffness[bonds.clone()].to_vec(),
            bond_damping: s.bond_damping[bonds].to_vec(),
            ground_damping: s.ground_damping[sites].to_vec(),
            resonators,
        })
    }

    /// The description it was built from (damping lists at full length).
    pub fn spec(&self) -> &ChainSpec {
        &self.spec
    }

    /// Number of sites S.
    pub fn n_sites(&self) -> usize {
        self.spec.masses.len()
    }

    /// Number of degrees of freedom S + R.
    pub fn n_dof(&self) -> usize {
        self.n_sites() + self.spec.resonators.len()
    }

    /// m_n.
    pub fn mass(&self, site: usize) -> f64 {
        self.spec.masses[site]
    }

    /// K_b (bond numbering of the module documentation).
    pub fn stiffness(&self, bond: usize) -> f64 {
        self.spec.bond_stiffness[bond]
    }

    /// c_b.
    pub fn bond_damping(&self, bond: usize) -> f64 {
        self.spec.bond_damping[bond]
    }

    /// g_n.
    pub fn ground_damping(&self, site: usize) -> f64 {
        self.spec.ground_damping[site]
    }

    /// The resonators, in degree-of-freedom order.
    pub fn resonators(&self) -> &[LinearResonator] {
        &self.spec.resonators
    }

    /// The indices (into [`LinearChain::resonators`]) of the resonators on `site`.
    pub fn resonators_on(&self, site: usize) -> &[usize] {
        &self.by_site[self.start[site]..self.start[site + 1]]
    }

    /// The mass of every degree of freedom: sites, then resonators.
    pub fn dof_masses(&self) -> Vec<f64> {
        let resonators = self.spec.resonators.iter().map(|r| r.mass);
        self.spec.masses.iter().copied().chain(resonators).collect()
    }

    /// Whether any dashpot is non-zero.
    pub fn is_damped(&self) -> bool {
        let s = &self.spec;
        let any = |v: &[f64]| v.iter().any(|&c| c > 0.0);
        any(&s.bond_damping)
            || any(&s.ground_damping)
            || s.resonators.iter().any(|r| r.damping > 0.0)
    }

    /// An upper bound on every undamped eigenfrequency: Gershgorin's bound on
    /// M^{-1/2} K M^{-1/2}, max over rows of sum_j |K_ij| / sqrt(m_i m_j), square-rooted.
    pub fn frequency_bound(&self) -> f64 {
        let n = self.n_sites();
        let mut bound: f64 = 0.0;
        for site in 0..n {
            let m = self.mass(site);
            let (left, right) = (self.stiffness(site), self.stiffness(site + 1));
            let mut row = (left + right) / m;
            if site > 0 {
                row += left / (m * self.mass(site - 1)).sqrt();
            }
            if site + 1 < n {
                row += right / (m * self.mass(site + 1)).sqrt();
            }
            for &j in self.resonators_on(site) {
                let r = &self.spec.resonators[j];
                row += r.stiffness / m + r.stiffness / (m * r.mass).sqrt();
                let own = r.stiffness / r.mass + r.stiffness / (m * r.mass).sqrt();
                bound = bound.max(own);
            }
            bound = bound.max(row);
        }
        bound.sqrt()
    }
}

/// `Ok` when `len == expected`.
pub(crate) fn length(what: &'static str, len: usize, expected: usize) -> Result<(), SpectrumError> {
    match len == expected {
        true => Ok(()),
        false => Err(SpectrumError::Length {
            what,
            len,
            expected,
        }),
    }
}

/// `Ok` when `value` is finite and > 0; `what` names it otherwise.
pub(crate) fn positive(what: impl Fn() -> String, value: f64) -> Result<(), SpectrumError> {
    match value.is_finite() && value > 0.0 {
        true => Ok(()),
        false => Err(SpectrumError::NotPositive {
            what: what(),
            value,
        }),
    }
}

/// `Ok` when `value` is finite and ≥ 0; `what` names it otherwise.
pub(crate) fn non_negative(what: impl Fn() -> String, value: f64) -> Result<(), SpectrumError> {
    match value.is_finite() && value >= 0.0 {
        true => Ok(()),
        false => Err(SpectrumError::Negative {
            what: what(),
            value,
        }),
    }
}

/// Checks one resonator of a chain (or cell) of `n_sites` sites.
pub(crate) fn validate_resonator(
    j: usize,
    r: &LinearResonator,
    n_sites: usize,
) -> Result<(), SpectrumError> {
    if r.site >= n_sites {
        return Err(SpectrumError::SiteOutOfRange {
            resonator: j,
            site: r.site,
            n_sites,
        });
    }
    positive(|| format!("mass of resonator {j}"), r.mass)?;
    non_negative(|| format!("stiffness of resonator {j}"), r.stiffness)?;
    non_negative(|| format!("damping of resonator {j}"), r.damping)
}

/// For each site, the indices of its resonators, as (start offsets, indices) in CSR form.
pub(crate) fn index_by_site(
    resonators: &[LinearResonator],
    n_sites: usize,
) -> (Vec<usize>, Vec<usize>) {
    let mut start = vec![0; n_sites + 1];
    for r in resonators {
        start[r.site + 1] += 1;
    }
    for site in 0..n_sites {
        start[site + 1] += start[site];
    }
    let mut next = start.clone();
    let mut by_site = vec![0; resonators.len()];
    for (j, r) in resonators.iter().enumerate() {
        by_site[next[r.site]] = j;
        next[r.site] += 1;
    }
    (start, by_site)
}

/// An empty optional list becomes `len` zeros; a non-empty one must have length `len`.
fn fill_optional(list: &mut Vec<f64>, what: &'static str, len: usize) -> Result<(), SpectrumError> {
    if list.is_empty() {
        *list = vec![0.0; len];
    }
    length(what, list.len(), len)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn resonator(site: usize) -> LinearResonator {
        LinearResonator {
            site,
            mass: 0.5,
            stiffness: 2.0,
            damping: 0.0,
        }
    }

    #[test]
    fn refuses_bad_descriptions() {
        assert_eq!(
            LinearChain::new(ChainSpec::default()),
            Err(SpectrumError::EmptyChain)
        );
        let mut spec = ChainSpec::uniform(4, 1.0, 1.0);
        spec.bond_stiffness.pop();
        assert!(matches!(
            LinearChain::new(spec),
            Err(SpectrumError::Length { expected: 5, .. })
        ));
        let mut spec = ChainSpec::uniform(4, 1.0, 1.0);
        spec.bond_stiffness[2] = 0.0;
        assert!(matches!(
            LinearChain::new(spec),
            Err(SpectrumError::NotPositive { .. })
        ));
        let mut spec = ChainSpec::uniform(4, 1.0, 1.0);
        spec.masses[1] = f64::NAN;
        assert!(matches!(
            LinearChain::new(spec),
            Err(SpectrumError::NotPositive { .. })
        ));
        let mut spec = ChainSpec::uniform(4, 1.0, 1.0);
        spec.resonators.push(resonator(4));
        assert!(matches!(
            LinearChain::new(spec),
            Err(SpectrumError::SiteOutOfRange { site: 4, .. })
        ));
        let mut spec = ChainSpec::uniform(4, 1.0, 1.0);
        spec.ground_damping = vec![0.1; 3];
        assert!(matches!(
            LinearChain::new(spec),
            Err(SpectrumError::Length { .. })
        ));
        let mut spec = ChainSpec::uniform(4, 1.0, 1.0);
        spec.bond_damping = vec![-0.1; 5];
        assert!(matches!(
            LinearChain::new(spec),
            Err(SpectrumError::Negative { .. })
        ));
    }

    #[test]
    fn free_ends_and_resonator_index() {
        let mut spec = ChainSpec::uniform(4, 1.0, 1.0);
        spec.bond_stiffness[0] = 0.0;
        spec.bond_stiffness[4] = 0.0;
        spec.resonators = vec![resonator(2), resonator(0), resonator(2)];
        let chain = LinearChain::new(spec).unwrap();
        assert_eq!(chain.resonators_on(0), &[1]);
        assert_eq!(chain.resonators_on(1), &[] as &[usize]);
        assert_eq!(chain.resonators_on(2), &[0, 2]);
        assert_eq!(chain.n_dof(), 7);
        assert_eq!(chain.bond_damping(3), 0.0);
        assert!(!chain.is_damped());
        assert_eq!(chain.dof_masses()[4..], [0.5, 0.5, 0.5]);
    }

    #[test]
    fn frequency_bound_covers_the_monatomic_cutoff() {
        // The cutoff of K = 1, m = 1 is 2; Gershgorin gives exactly 2 for interior rows.
        let chain = LinearChain::new(ChainSpec::uniform(10, 1.0, 1.0)).unwrap();
        assert!((chain.frequency_bound() - 2.0).abs() < 1e-15);
    }
}
