//! Bloch bands of a periodic chain: the frequencies ω_j(q) of one repeating cell, its pass
//! bands and gaps, and the complex wavenumber (attenuation per cell) inside a gap.
//!
//! A cell has `n_c` sites; bond b (0 ≤ b < n_c) joins site b − 1 and site b, bond 0 joining the
//! previous cell's last site to site 0. A Bloch wave u_{n, c} = U_n e^{iqc} (cell c) turns the
//! stiffness into the Hermitian K(q), whose entries for a bond crossing into the previous cell
//! carry e^{∓iq}; the dynamical matrix D(q) = M^{-1/2} K(q) M^{-1/2} (sites then resonators) has
//! eigenvalues ω_j(q)², and the eigensolver is faer's self-adjoint one.
//!
//! Gap edges are the eigenfrequencies at q = 0 and q = π: a nearest-neighbour chain's transfer
//! matrix over one cell is 2×2 once the resonators are folded into their hosts
//! ([`crate::condense`]), so each ω has a single cos q = tr T(ω)/2 and no band can turn back
//! inside (0, π); every band runs monotonically between its values at 0 and π.
//!
//! In a gap |tr T/2| > 1 and q = q_r + iκ: κ = arccosh|tr T/2| is the attenuation per cell (an
//! evanescent amplitude shrinks by e^{−κ} per cell), q_r = 0 where tr T/2 > 1 and π where it is
//! below −1 (neighbouring cells then move in antiphase).

use faer::{c64, Mat, Side};

use crate::chain::{index_by_site, length, positive, validate_resonator, LinearResonator};
use crate::condense::effective_mass_real;
use crate::error::SpectrumError;

/// One repeating cell of a periodic chain (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    masses: Vec<f64>,
    bonds: Vec<f64>,
    resonators: Vec<LinearResonator>,
    start: Vec<usize>,
    by_site: Vec<usize>,
}

/// A frequency interval [lower, upper] (rad per unit time): a pass band, a gap, or a window to
/// search for modes in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Lower end.
    pub lower: f64,
    /// Upper end.
    pub upper: f64,
}

/// The band structure sampled on a grid of wavenumbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Bands {
    /// Wavenumbers q_i, evenly spaced from 0 to π inclusive (radians per cell).
    pub q: Vec<f64>,
    /// `omega[i][j]` = ω_j(q_i), ascending in j.
    pub omega: Vec<Vec<f64>>,
}

/// A complex wavenumber q + iκ per cell (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wavenumber {
    /// Real part in [0, π]; inside a gap 0 or π. At an exact resonance of an undamped
    /// resonator (attenuation infinite), 0.
    pub q: f64,
    /// κ ≥ 0: 0 in a pass band; the amplitude shrinks by e^{−κ} per cell in a gap.
    pub attenuation: f64,
}

impl Interval {
    /// Whether `omega` lies in [lower, upper].
    pub fn contains(&self, omega: f64) -> bool {
        self.lower <= omega && omega <= self.upper
    }
}

impl Cell {
    /// A cell of `masses.len()` sites, `bonds[b]` joining site b − 1 to b (bond 0 from the
    /// previous cell), and resonators on its sites. Every mass and bond must be > 0; the
    /// resonators must be undamped (bands are those of the conservative chain).
    pub fn new(
        masses: Vec<f64>,
        bonds: Vec<f64>,
        resonators: Vec<LinearResonator>,
    ) -> Result<Cell, SpectrumError> {
        let n = masses.len();
        if n == 0 {
            return Err(SpectrumError::EmptyChain);
        }
        length("bonds", bonds.len(), n)?;
        for (site, &m) in masses.iter().enumerate() {
            positive(|| format!("mass of site {site}"), m)?;
        }
        for (bond, &k) in bonds.iter().enumerate() {
            positive(|| format!("stiffness of bond {bond}"), k)?;
        }
        for (j, r) in resonators.iter().enumerate() {
            validate_resonator(j, r, n)?;
            if r.damping != 0.0 {
                return Err(SpectrumError::DampedCell { resonator: j });
            }
        }
        let (start, by_site) = index_by_site(&resonators, n);
        Ok(Cell {
            masses,
            bonds,
            resonators,
            start,
            by_site,
        })
    }

    /// Number of sites in the cell.
    pub fn n_sites(&self) -> usize {
        self.masses.len()
    }

    /// Number of degrees of freedom (sites + resonators), hence of bands.
    pub fn n_dof(&self) -> usize {
        self.masses.len() + self.resonators.len()
    }

    /// D(q) = M^{-1/2} K(q) M^{-1/2}, Hermitian, sites then resonators.
    pub fn dynamical_matrix(&self, q: f64) -> Mat<c64> {
        let n = self.n_sites();
        let mut k = Mat::<c64>::zeros(self.n_dof(), self.n_dof());
        let phase = c64::new(q.cos(), q.sin());
        for (b, &stiffness) in self.bonds.iter().enumerate() {
            // Bond b joins site `left` (in the previous cell when b = 0) and site b.
            let (left, across) = match b {
                0 => (n - 1, phase.conj()),
                _ => (b - 1, c64::new(1.0, 0.0)),
            };
            k[(b, b)] += stiffness;
            k[(left, left)] += stiffness;
            // Force on b from `left`: stiffness (U_left e^{-iq} - U_b) for the previous cell.
            k[(b, left)] -= across * stiffness;
            k[(left, b)] -= across.conj() * stiffness;
        }
        for (j, r) in self.resonators.iter().enumerate() {
            let dof = n + j;
            k[(r.site, r.site)] += r.stiffness;
            k[(dof, dof)] += r.stiffness;
            k[(r.site, dof)] -= r.stiffness;
            k[(dof, r.site)] -= r.stiffness;
        }
        let scale: Vec<f64> = self
            .masses
            .iter()
            .chain(self.resonators.iter().map(|r| &r.mass))
            .map(|m| 1.0 / m.sqrt())
            .collect();
        Mat::from_fn(self.n_dof(), self.n_dof(), |i, j| {
            k[(i, j)] * (scale[i] * scale[j])
        })
    }

    /// ω_j(q), ascending (eigenvalues of D(q) below 0 by rounding count as 0).
    pub fn frequencies(&self, q: f64) -> Result<Vec<f64>, SpectrumError> {
        let eigenvalues = self
            .dynamical_matrix(q)
            .self_adjoint_eigenvalues(Side::Lower)
            .map_err(|_| SpectrumError::NoConvergence {
                what: "dynamical matrix D(q)",
            })?;
        Ok(eigenvalues.into_iter().map(|l| l.max(0.0).sqrt()).collect())
    }

    /// The bands on `n_q` ≥ 2 evenly spaced wavenumbers from 0 to π.
    pub fn bands(&self, n_q: usize) -> Result<Bands, SpectrumError> {
        if n_q < 2 {
            return Err(SpectrumError::TooFewWavenumbers { n_q });
        }
        let q: Vec<f64> = (0..n_q)
            .map(|i| std::f64::consts::PI * i as f64 / (n_q - 1) as f64)
            .collect();
        let omega = q
            .iter()
            .map(|&q| self.frequencies(q))
            .collect::<Result<_, _>>()?;
        Ok(Bands { q, omega })
    }

    /// The pass bands, ascending, each from its values at q = 0 and q = π (see the module
    /// documentation for why these are its edges).
    pub fn pass_bands(&self) -> Result<Vec<Interval>, SpectrumError> {
        let at_zero = self.frequencies(0.0)?;
        let at_pi = self.frequencies(std::f64::consts::PI)?;
        Ok(at_zero
            .iter()
            .zip(&at_pi)
            .map(|(&a, &b)| Interval {
                lower: a.min(b),
                upper: a.max(b),
            })
            .collect())
    }

    /// The gaps between consecutive pass bands, ascending; bands that touch (to 1e-12 relative)
    /// leave no gap. The range above the top band is not listed.
    pub fn gaps(&self) -> Result<Vec<Interval>, SpectrumError> {
        let bands = self.pass_bands()?;
        Ok(bands
            .windows(2)
            .filter(|pair| pair[1].lower - pair[0].upper > 1e-12 * pair[1].lower)
            .map(|pair| Interval {
                lower: pair[0].upper,
                upper: pair[1].lower,
            })
            .collect())
    }

    /// Where a finite chain built on this host can have localised modes below `upper` (for
    /// instance [`crate::chain::LinearChain::frequency_bound`]): the gaps, and the range from the
    /// top band's upper edge to `upper` when that is higher. The windows to hand to
    /// [`crate::localised::localised_modes`].
    pub fn stop_bands(&self, upper: f64) -> Result<Vec<Interval>, SpectrumError> {
        let mut windows = self.gaps()?;
        let top = self.pass_bands()?.last().map_or(0.0, |band| band.upper);
        if upper > top {
            windows.push(Interval { lower: top, upper });
        }
        Ok(windows)
    }

    /// The complex wavenumber at angular frequency `omega` ≥ 0, from the cell's 2×2 transfer
    /// matrix (see the module documentation).
    pub fn wavenumber(&self, omega: f64) -> Result<Wavenumber, SpectrumError> {
        crate::chain::non_negative(|| "frequency".into(), omega)?;
        let Some(half_trace) = self.half_trace(omega) else {
            return Ok(Wavenumber {
                q: 0.0,
                attenuation: f64::INFINITY,
            });
        };
        let pi = std::f64::consts::PI;
        Ok(match half_trace {
            h if h > 1.0 => Wavenumber {
                q: 0.0,
                attenuation: h.acosh(),
            },
            h if h < -1.0 => Wavenumber {
                q: pi,
                attenuation: (-h).acosh(),
            },
            h => Wavenumber {
                q: h.acos(),
                attenuation: 0.0,
            },
        })
    }

    /// tr T(ω)/2 = cos q for the transfer matrix over one cell; `None` when a resonator is
    /// exactly at resonance (its host pinned).
    fn half_trace(&self, omega: f64) -> Option<f64> {
        let n = self.n_sites();
        // T maps (u_0, u_{-1}) to (u_n, u_{n-1}); start from the identity.
        let mut t = [[1.0, 0.0], [0.0, 1.0]];
        for site in 0..n {
            let resonators = self.by_site[self.start[site]..self.start[site + 1]]
                .iter()
                .map(|&j| self.resonators[j]);
            let mass = effective_mass_real(self.masses[site], resonators, omega)?;
            let (left, right) = (self.bonds[site], self.bonds[(site + 1) % n]);
            let diagonal = (left + right - omega * omega * mass) / right;
            let back = -left / right;
            // [[diagonal, back], [1, 0]] · t
            t = [
                [
                    diagonal * t[0][0] + back * t[1][0],
                    diagonal * t[0][1] + back * t[1][1],
                ],
                t[0],
            ];
        }
        Some(0.5 * (t[0][0] + t[1][1]))
    }
}

#[cfg(test)]
mod tests;
