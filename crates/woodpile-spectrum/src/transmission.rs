//! Transmission and reflection of a scattering region placed between two semi-infinite uniform
//! chains (the leads), by transfer matrices in O(S + R) per frequency.
//!
//! The region is a [`LinearChain`] whose two end bonds (bond 0, bond S) join it to the last
//! site of the left lead and the first site of the right lead; each lead has mass m and bonds K.
//! Resonators fold into their hosts ([`crate::condense`]), dashpots into complex stiffnesses.
//! Convention u(t) = Re[u e^{−iωt}]: a wave e^{iqj} runs to the right, and
//!
//! ```text
//! left lead   u_j = e^{iqj} + r e^{−iqj}   (j < 0)
//! right lead  u_j = t e^{iqj}              (j ≥ S)       cos q = 1 − ω² m / (2K),  0 < q < π
//! ```
//!
//! so t and r are measured against the uniform chain: a region identical to the leads has
//! t = 1 and r = 0, and [`Scattering::phase`] is the phase a wave gains over the host chain.
//! Both leads carry the same flux per |amplitude|², so |r|² + |t|² = 1 without dashpots and
//! 1 − |r|² − |t|² is the share absorbed with them.
//!
//! The solution is propagated from the right lead (t = 1) to the left, site by site, as a pair
//! of displacements rescaled whenever it grows or shrinks past 1e±100 (the log of the scale
//! is kept), so a long region deep in a gap gives a tiny t rather than an overflow. Propagating
//! this way follows the solution that grows into the region, the stable direction. A site
//! pinned by an undamped resonator at exact resonance stops the wave: t = 0 exactly.

use faer::c64;

use crate::chain::{positive, LinearChain};
use crate::condense::effective_mass;
use crate::error::SpectrumError;

/// A uniform semi-infinite chain: site mass m and bond stiffness K.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lead {
    mass: f64,
    stiffness: f64,
}

/// The scattering amplitudes at one frequency (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scattering {
    /// ω (rad per unit time).
    pub omega: f64,
    /// t, the transmitted amplitude.
    pub transmission: c64,
    /// r, the reflected amplitude.
    pub reflection: c64,
    /// ln |t|, kept apart because deep in a gap |t| underflows f64 (e^{−745}) long before its
    /// logarithm loses anything; −∞ when a pinned site blocks the wave.
    pub log_transmission: f64,
}

impl Lead {
    /// A lead of site mass `mass` and bond stiffness `stiffness`, both > 0.
    pub fn new(mass: f64, stiffness: f64) -> Result<Lead, SpectrumError> {
        positive(|| "lead mass".into(), mass)?;
        positive(|| "lead stiffness".into(), stiffness)?;
        Ok(Lead { mass, stiffness })
    }

    /// Its site mass m.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Its bond stiffness K.
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// The top of its band, 2 sqrt(K/m).
    pub fn cutoff(&self) -> f64 {
        2.0 * (self.stiffness / self.mass).sqrt()
    }

    /// q in (0, π) with cos q = 1 − ω² m/(2K), for 0 < ω < cutoff.
    pub fn wavenumber(&self, omega: f64) -> Result<f64, SpectrumError> {
        if !(omega > 0.0 && omega < self.cutoff()) {
            return Err(SpectrumError::OutsideLeadBand {
                omega,
                cutoff: self.cutoff(),
            });
        }
        Ok((1.0 - omega * omega * self.mass / (2.0 * self.stiffness)).acos())
    }
}

impl Scattering {
    /// |t|², the transmitted share of the incoming energy flux.
    pub fn transmittance(&self) -> f64 {
        self.transmission.norm_sqr()
    }

    /// |r|², the reflected share.
    pub fn reflectance(&self) -> f64 {
        self.reflection.norm_sqr()
    }

    /// 1 − |r|² − |t|², the share the dashpots absorb (0 up to rounding without them).
    pub fn absorbance(&self) -> f64 {
        1.0 - self.transmittance() - self.reflectance()
    }

    /// arg t in (−π, π], relative to the uniform host chain.
    pub fn phase(&self) -> f64 {
        self.transmission.arg()
    }
}

/// t and r of `region` between two `lead`s at each of `omegas` (each inside the leads' band,
/// 0 < ω < 2 sqrt(K/m)). The region's end bonds must be > 0.
pub fn scatter(
    lead: &Lead,
    region: &LinearChain,
    omegas: &[f64],
) -> Result<Vec<Scattering>, SpectrumError> {
    let n = region.n_sites();
    for (side, bond) in [("left", 0), ("right", n)] {
        if region.stiffness(bond) == 0.0 {
            return Err(SpectrumError::Detached { side });
        }
    }
    omegas
        .iter()
        .map(|&omega| Ok(scatter_one(lead, region, omega, lead.wavenumber(omega)?)))
        .collect()
}

/// The propagated pair (u_j, u_{j+1}) with its scale: true values = stored × e^{log_scale}.
struct Pair {
    here: c64,
    next: c64,
    log_scale: f64,
    /// Whether a pinned site was crossed (t = 0).
    blocked: bool,
}

impl Pair {
    /// Steps one site to the left: from site j's equation
    /// K~_left u_{j−1} = diagonal u_j − K~_right u_{j+1}.
    fn step(&mut self, diagonal: c64, left: c64, right: c64) {
        let previous = (diagonal * self.here - right * self.next) / left;
        self.next = self.here;
        self.here = previous;
        let size = self.here.norm().max(self.next.norm());
        if !(1e-100..=1e100).contains(&size) && size > 0.0 {
            self.here /= size;
            self.next /= size;
            self.log_scale += size.ln();
        }
    }

    /// Crossing a site pinned at resonance: u_j must vanish, so the pair is (any, 0) ∝ (1, 0).
    fn pin(&mut self) {
        self.next = c64::new(0.0, 0.0);
        self.here = c64::new(1.0, 0.0);
        self.blocked = true;
    }
}

/// t and r at one frequency ω with lead wavenumber q.
fn scatter_one(lead: &Lead, region: &LinearChain, omega: f64, q: f64) -> Scattering {
    let n = region.n_sites();
    let (m, k) = (c64::new(lead.mass, 0.0), c64::new(lead.stiffness, 0.0));
    let w2 = omega * omega;
    let bond = |b: usize| c64::new(region.stiffness(b), -omega * region.bond_damping(b));
    // Right lead, t = 1: u_S = e^{iqS}, u_{S+1} = e^{iq(S+1)}.
    let mut pair = Pair {
        here: c64::from_polar(1.0, q * n as f64),
        next: c64::from_polar(1.0, q * (n + 1) as f64),
        log_scale: 0.0,
        blocked: false,
    };
    pair.step(bond(n) + k - w2 * m, bond(n), k);
    for site in (0..n).rev() {
        let resonators = region
            .resonators_on(site)
            .iter()
            .map(|&j| region.resonators()[j]);
        let Some(mass) = effective_mass(region.mass(site), resonators, omega) else {
            pair.pin();
            continue;
        };
        let (left, right) = (bond(site), bond(site + 1));
        let ground = c64::new(0.0, -omega * region.ground_damping(site));
        pair.step(left + right + ground - w2 * mass, left, right);
    }
    // Now (here, next) = (u_{-1}, u_0); site −1 of the left lead gives u_{-2}.
    pair.step(k + bond(0) - w2 * m, k, bond(0));
    let (u1, u2) = (pair.next, pair.here);
    let e = c64::from_polar(1.0, q);
    let det = c64::new(0.0, 2.0 * q.sin());
    let incoming = (u1 * e * e - u2 * e) / det;
    let reflected = (u2 / e - u1 / (e * e)) / det;
    let (transmission, log_transmission) = match pair.blocked {
        true => (c64::new(0.0, 0.0), f64::NEG_INFINITY),
        false => (
            (-pair.log_scale).exp() / incoming,
            -pair.log_scale - incoming.norm().ln(),
        ),
    };
    Scattering {
        omega,
        transmission,
        reflection: reflected / incoming,
        log_transmission,
    }
}

#[cfg(test)]
mod tests;
