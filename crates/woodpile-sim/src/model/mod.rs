//! The chain and its resonators: paper Eq. 3 (one linear resonator), Eq. 7 (nonlinear coupling
//! exponent p), Eq. 14 (time-dependent coupling kappa(t)), with per-site masses for the
//! dimensional woodpile of Section III.
//!
//! Dimensionless equations of motion (sites n = 0..n_sites, internal 0-based numbering):
//!
//! ```text
//! m_n u_n'' = [u_{n-1} - u_n]_+^{3/2} - [u_n - u_{n+1}]_+^{3/2} - sum_j kappa_j(t) (u_j - v_j)^{p_j} delta_{n s_j}
//! eps_j v_j'' = kappa_j(t) (u_{s_j} - v_j)^{p_j}
//! ```
//!
//! The state vector is flat: `y = [q, q']` with `q = [u_0 .. u_{S-1}, v_0 .. v_{R-1}]`, so that
//! `n_dof = S + R` and `y.len() = 2 n_dof`. Contacts push, never pull (`[x]_+ = max(x, 0)`).

mod boundary;
pub mod parts;
mod resonator;
mod window;

pub use boundary::{Boundary, End};
pub use parts::ModelParts;
pub use resonator::{odd_power, Coupling, Resonator};
pub use window::Window;

use crate::contact::{ChainLaw, ContactLaw};
use crate::damping::Damping;
use crate::error::ModelError;

/// A validated chain with its resonators. Construct with [`Model::new`].
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    n_sites: usize,
    boundary: Boundary,
    resonators: Vec<Resonator>,
    /// Per-site masses; `None` means all unit masses (the dimensionless scenes), which lets the
    /// force loop skip a multiply per site.
    site_masses: Option<Vec<f64>>,
    /// 1/mass for every degree of freedom (sites then resonators).
    inv_mass: Vec<f64>,
    /// The contact law ([`crate::contact`]): the paper's, a zero-sized type whose loops keep
    /// the paper's bits, unless the chain declares another.
    law: ChainLaw,
    /// Dashpots and ground damping ([`crate::damping`]); `None` when nothing dissipates
    /// (soft ends keep their own dashpots), so a conservative scene pays nothing for them.
    damping: Option<Box<Damping>>,
    /// Whether anything dissipates: the state then ends with D ([`Model::state_len`]).
    dissipative: bool,
    /// Whether walls lie beyond the first and the last site, and whether an end is soft:
    /// what the force loop asks of the boundary at every evaluation, answered once.
    walls: [bool; 2],
    soft_end: bool,
}

impl Model {
    /// A chain of `n_sites` unit masses with the given boundary and resonators.
    pub fn new(
        n_sites: usize,
        boundary: Boundary,
        resonators: Vec<Resonator>,
    ) -> Result<Self, ModelError> {
        Self::with_masses(n_sites, boundary, resonators, None)
    }

    /// A chain with explicit per-site masses (dimensionless, relative to the reference mass of
    /// the rescaling; see [`crate::units`]).
    pub fn with_masses(
        n_sites: usize,
        boundary: Boundary,
        resonators: Vec<Resonator>,
        site_masses: Option<Vec<f64>>,
    ) -> Result<Self, ModelError> {
        if n_sites == 0 {
            return Err(ModelError::EmptyChain);
        }
        for (index, r) in resonators.iter().enumerate() {
            validate_resonator(index, r, n_sites)?;
        }
        if let Some(masses) = &site_masses {
            if masses.len() != n_sites {
                return Err(ModelError::MassCount {
                    n_masses: masses.len(),
                    n_sites,
                });
            }
            for (site, &m) in masses.iter().enumerate() {
                positive(&format!("mass of site {site}"), m)?;
            }
        }
        for (side, end) in [("left", boundary.left()), ("right", boundary.right())] {
            if let Some((spring, damping)) = end.soft() {
                non_negative(&format!("{side} end spring"), spring)?;
                non_negative(&format!("{side} end damping"), damping)?;
            }
        }
        let site_masses = site_masses.filter(|m| m.iter().any(|&x| x != 1.0));
        let mut inv_mass: Vec<f64> = match &site_masses {
            Some(m) => m.iter().map(|x| 1.0 / x).collect(),
            None => vec![1.0; n_sites],
        };
        inv_mass.extend(resonators.iter().map(|r| 1.0 / r.eps));
        Ok(Self {
            n_sites,
            boundary,
            resonators,
            site_masses,
            inv_mass,
            law: ChainLaw::default(),
            damping: None,
            dissipative: boundary.dissipates(),
            walls: [boundary.left_wall(), boundary.right_wall()],
            soft_end: boundary.has_soft_end(),
        })
    }

    /// The same chain with `damping`. A damping with every coefficient zero is dropped, so
    /// that the scene keeps the conservative path and its bits.
    pub fn with_damping(mut self, damping: Damping) -> Result<Self, ModelError> {
        if damping.resonator.len() > self.resonators.len() {
            return Err(ModelError::DampingCount {
                n_dampings: damping.resonator.len(),
                n_resonators: self.resonators.len(),
            });
        }
        if let Some(each) = &damping.contacts {
            if each.len() != self.n_sites + 1 {
                return Err(ModelError::BondCount {
                    n_bonds: each.len(),
                    n_sites: self.n_sites,
                });
            }
        }
        if damping.dissipates() {
            self.damping = Some(Box::new(damping));
            self.dissipative = true;
        }
        Ok(self)
    }

    /// The dashpots and ground damping, when any is non-zero.
    #[inline(always)]
    pub fn damping(&self) -> Option<&Damping> {
        self.damping.as_deref()
    }

    /// Whether the chain loses energy (a dashpot, ground damping, or a soft end's dashpot).
    /// Its state then carries D, the energy dissipated so far, after `[q, q']`; forces depend
    /// on velocities, and only methods for y'' = f(t, y, y') may run it.
    #[inline(always)]
    pub fn is_dissipative(&self) -> bool {
        self.dissipative
    }

    /// D, the energy dissipated up to state `y` (0 for a conservative chain).
    #[inline(always)]
    pub fn dissipated(&self, y: &[f64]) -> f64 {
        match self.dissipative {
            true => y[2 * self.n_dof()],
            false => 0.0,
        }
    }

    /// Whether every loss acts on velocities alone and linearly (ground damping, resonator
    /// dashpots, soft ends' dashpots): no contact dashpot, whose force starts with its contact
    /// and is clipped against its spring's. Such losses have an exact flow that a method may
    /// integrate apart from the conservative step ([`crate::integrate::SplitLosses`]).
    pub fn losses_are_linear(&self) -> bool {
        self.damping().is_none_or(|d| !d.has_contact_dashpot())
    }

    /// The same chain without its losses: no damping, and each soft end's dashpot removed (its
    /// spring kept). What [`crate::integrate::SplitLosses`] steps between the losses' flows.
    pub fn without_losses(&self) -> Model {
        let strip = |end: End| match end {
            End::Soft { spring, .. } => End::Soft {
                spring,
                damping: 0.0,
            },
            other => other,
        };
        let boundary = Boundary::ends(strip(self.boundary.left()), strip(self.boundary.right()));
        Model {
            boundary,
            damping: None,
            dissipative: false,
            ..self.clone()
        }
    }

    /// The same chain with the contact law `law` instead of the paper's: one coefficient per
    /// bond (sites + 1, walls included), its exponent and its precompression. A
    /// precompression needs walls at both ends.
    pub fn with_contacts(self, law: ContactLaw) -> Result<Self, ModelError> {
        self.with_law(law)
    }

    /// The same chain with the contact law `law` (any law of the registry,
    /// [`crate::contact::ChainLaw`]), written for as many bonds as the chain has; a law with a
    /// static force held by walls needs walls at both ends.
    pub fn with_law(mut self, law: impl Into<ChainLaw>) -> Result<Self, ModelError> {
        let law = law.into();
        if let Some(n_bonds) = law.n_bonds().filter(|&n| n != self.n_sites + 1) {
            return Err(ModelError::BondCount {
                n_bonds,
                n_sites: self.n_sites,
            });
        }
        if law.held_by_walls() && self.boundary != Boundary::Fixed {
            return Err(ModelError::PrecompressionWithoutWalls);
        }
        self.law = law;
        Ok(self)
    }

    /// The experiment's contact law ([`ContactLaw`]), when the chain runs it.
    #[inline(always)]
    pub fn contacts(&self) -> Option<&ContactLaw> {
        match &self.law {
            ChainLaw::Experiment(law) => Some(law),
            _ => None,
        }
    }

    /// The contact law the simulator runs, to dispatch on once per call
    /// ([`crate::contact::with_law!`]).
    #[inline(always)]
    pub fn law(&self) -> &ChainLaw {
        &self.law
    }

    /// Number of chain sites S.
    pub fn n_sites(&self) -> usize {
        self.n_sites
    }

    /// Number of degrees of freedom S + R (positions only).
    pub fn n_dof(&self) -> usize {
        self.n_sites + self.resonators.len()
    }

    /// Length of the flat state vector `[q, q']`, and D after it when the chain dissipates.
    pub fn state_len(&self) -> usize {
        2 * self.n_dof() + usize::from(self.dissipative)
    }

    /// The boundary condition.
    pub fn boundary(&self) -> Boundary {
        self.boundary
    }

    /// Whether walls lie beyond the first and the last site.
    #[inline(always)]
    pub fn walls(&self) -> [bool; 2] {
        self.walls
    }

    /// Whether an end is soft (a spring, perhaps with a dashpot).
    #[inline(always)]
    pub fn has_soft_end(&self) -> bool {
        self.soft_end
    }

    /// The resonators, in the order their coordinates follow the sites in the state.
    pub fn resonators(&self) -> &[Resonator] {
        &self.resonators
    }

    /// Mass of site `site` (1 unless per-site masses were given).
    pub fn site_mass(&self, site: usize) -> f64 {
        self.site_masses.as_ref().map_or(1.0, |m| m[site])
    }

    /// The per-site masses; `None` when every site mass is 1, so the force loop can skip the
    /// division.
    pub(crate) fn site_masses(&self) -> Option<&[f64]> {
        self.site_masses.as_deref()
    }

    /// 1/mass for every degree of freedom (sites then resonators).
    pub fn inv_mass(&self) -> &[f64] {
        &self.inv_mass
    }

    /// Whether any coupling depends on time (energy then is not conserved).
    pub fn is_time_dependent(&self) -> bool {
        self.resonators
            .iter()
            .any(|r| r.coupling.is_time_dependent())
    }

    /// The fastest linear resonator frequency omega = sqrt(kappa (1/m + 1/eps)): the stiffness
    /// scale that bounds explicit steps (dt * omega must stay below a method's stability limit).
    /// With `skip_harmonic`, over the resonators a method that integrates harmonic ones exactly
    /// ([`Model::is_harmonic`]) still steps through.
    pub fn max_linear_omega(&self, skip_harmonic: bool) -> f64 {
        self.stepped_resonators(skip_harmonic)
            .map(|r| r.linear_omega(self.site_mass(r.site)))
            .fold(0.0, f64::max)
    }

    /// The fastest resonator frequency a motion of total energy `energy` can reach
    /// ([`Resonator::omega_within`]): equal to [`Model::max_linear_omega`] when every resonator
    /// is linear, and a bound on the stiffest moment of a nonlinear one. `skip_harmonic` as
    /// there.
    pub fn max_resonator_omega(&self, energy: f64, skip_harmonic: bool) -> f64 {
        self.stepped_resonators(skip_harmonic)
            .map(|r| r.omega_within(self.site_mass(r.site), energy))
            .fold(0.0, f64::max)
    }

    /// The fastest harmonic resonator's frequency ([`Model::is_harmonic`]), 0 without one.
    pub fn max_harmonic_omega(&self) -> f64 {
        (0..self.resonators.len())
            .filter(|&j| self.is_harmonic(j))
            .map(|j| self.resonators[j].linear_omega(self.site_mass(self.resonators[j].site)))
            .fold(0.0, f64::max)
    }

    /// The resonators, without the harmonic ones when `skip_harmonic`.
    fn stepped_resonators(&self, skip_harmonic: bool) -> impl Iterator<Item = &Resonator> {
        (0..self.resonators.len())
            .filter(move |&j| !(skip_harmonic && self.is_harmonic(j)))
            .map(|j| &self.resonators[j])
    }

    /// Whether resonator `j` is harmonic: linear (p = 1), its coupling a constant κ > 0, on a
    /// conservative chain, and the only resonator of its host. Its pair with the host is then
    /// a linear oscillator of one frequency that `erkn6-contact` integrates exactly.
    pub fn is_harmonic(&self, j: usize) -> bool {
        let r = &self.resonators[j];
        let alone = self.resonators.iter().filter(|o| o.site == r.site).count() == 1;
        r.p == 1
            && !r.coupling.is_time_dependent()
            && r.coupling.max_value() > 0.0
            && !self.dissipative
            && alone
    }

    /// A state vector at rest: all displacements and velocities zero.
    pub fn rest_state(&self) -> Vec<f64> {
        vec![0.0; self.state_len()]
    }

    /// Gives site `site` the velocity `velocity` (the striker impulse of Eq. 2).
    pub fn apply_impulse(
        &self,
        y: &mut [f64],
        site: usize,
        velocity: f64,
    ) -> Result<(), ModelError> {
        if site >= self.n_sites {
            return Err(ModelError::SiteOutOfRange {
                what: "impulse".into(),
                site,
                n_sites: self.n_sites,
            });
        }
        finite("impulse velocity", velocity)?;
        y[self.n_dof() + site] = velocity;
        Ok(())
    }
}

fn validate_resonator(index: usize, r: &Resonator, n_sites: usize) -> Result<(), ModelError> {
    if r.site >= n_sites {
        return Err(ModelError::SiteOutOfRange {
            what: format!("resonator {index}"),
            site: r.site,
            n_sites,
        });
    }
    positive(&format!("resonator {index} eps"), r.eps)?;
    if !(r.p == 1 || (r.p >= 3 && r.p % 2 == 1)) {
        return Err(ModelError::BadExponent { index, p: r.p });
    }
    match r.coupling {
        Coupling::Constant(k) => non_negative(&format!("resonator {index} kappa"), k)?,
        Coupling::Ramp { k1, k2, t0, tau } => {
            non_negative(&format!("resonator {index} kappa.k1"), k1)?;
            non_negative(&format!("resonator {index} kappa.k2"), k2)?;
            finite(&format!("resonator {index} kappa.t0"), t0)?;
            positive(&format!("resonator {index} kappa.tau"), tau)?;
        }
    }
    Ok(())
}

fn finite(what: &str, value: f64) -> Result<(), ModelError> {
    require(value.is_finite(), what, value, |what, value| {
        ModelError::NotFinite { what, value }
    })
}

fn positive(what: &str, value: f64) -> Result<(), ModelError> {
    require(
        value.is_finite() && value > 0.0,
        what,
        value,
        |what, value| ModelError::NotPositive { what, value },
    )
}

fn non_negative(what: &str, value: f64) -> Result<(), ModelError> {
    require(
        value.is_finite() && value >= 0.0,
        what,
        value,
        |what, value| ModelError::Negative { what, value },
    )
}

/// `Ok` when `holds`; otherwise the error `error` makes of the quantity's name and value.
fn require(
    holds: bool,
    what: &str,
    value: f64,
    error: fn(String, f64) -> ModelError,
) -> Result<(), ModelError> {
    match holds {
        true => Ok(()),
        false => Err(error(what.into(), value)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn res(site: usize, eps: f64, p: u32) -> Resonator {
        Resonator::constant(site, eps, 1.0, p)
    }

    #[test]
    fn resonator_frequency_within_an_energy() {
        // Linear: the energy does not matter.
        let linear = res(0, 0.5, 1);
        assert_eq!(linear.omega_within(1.0, 123.0), linear.linear_omega(1.0));
        // p = 3, kappa = 1, eps = 1, host mass 1: the largest stretch holds all the energy,
        // a^4 / 4 = E, and there the stiffness is 3 a^2, so omega^2 = 3 a^2 (1 + 1).
        let cubic = res(0, 1.0, 3);
        let a = (4.0_f64 * 0.5).powf(0.25);
        let expected = (3.0 * a * a * 2.0).sqrt();
        assert!((cubic.omega_within(1.0, 0.5) - expected).abs() < 1e-12 * expected);
        // More energy, a stiffer moment; the model takes the fastest resonator.
        assert!(cubic.omega_within(1.0, 2.0) > cubic.omega_within(1.0, 0.5));
        let model = Model::new(5, Boundary::Fixed, vec![linear, res(3, 1.0, 3)]).unwrap();
        let fastest = linear.linear_omega(1.0).max(expected);
        assert_eq!(model.max_resonator_omega(0.5, false), fastest);
    }

    #[test]
    fn rejects_bad_resonators() {
        assert!(matches!(
            Model::new(5, Boundary::Fixed, vec![res(5, 1.0, 1)]),
            Err(ModelError::SiteOutOfRange { site: 5, .. })
        ));
        assert!(matches!(
            Model::new(5, Boundary::Fixed, vec![res(0, 0.0, 1)]),
            Err(ModelError::NotPositive { .. })
        ));
        assert!(matches!(
            Model::new(5, Boundary::Fixed, vec![res(0, 1.0, 4)]),
            Err(ModelError::BadExponent { p: 4, .. })
        ));
        assert!(matches!(
            Model::new(5, Boundary::Fixed, vec![res(0, 1.0, 0)]),
            Err(ModelError::BadExponent { p: 0, .. })
        ));
        assert!(Model::new(5, Boundary::Fixed, vec![res(0, 1.0, 19)]).is_ok());
    }

    #[test]
    fn ramp_interpolates_between_k1_and_k2() {
        let c = Coupling::Ramp {
            k1: 0.0,
            k2: 2.5,
            t0: 40.0,
            tau: 0.1,
        };
        assert!(c.at(0.0).abs() < 1e-12);
        assert!((c.at(40.0) - 1.25).abs() < 1e-12);
        assert!((c.at(100.0) - 2.5).abs() < 1e-12);
        assert!(c.is_time_dependent());
        assert!(!Coupling::Constant(1.0).is_time_dependent());
    }

    #[test]
    fn unit_masses_are_not_stored() {
        let m = Model::with_masses(3, Boundary::Free, vec![], Some(vec![1.0; 3])).unwrap();
        assert!(m.site_masses().is_none());
    }
}
