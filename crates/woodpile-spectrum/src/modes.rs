//! Every normal mode of a finite undamped chain, from the dense generalised symmetric problem
//! K v = ω² M v, reduced to the standard one A y = ω² y with A = M^{-1/2} K M^{-1/2} (M is
//! diagonal) and solved by faer's self-adjoint eigensolver.
//!
//! Normalisation: v = M^{-1/2} y is mass-normalised, v^T M v = 1, and its entry of largest
//! magnitude is positive; modes whose ω² agree to 1e-8 relative (identical defects far apart)
//! are rotated into their most localised basis ([`crate::shape`]). Frequencies are angular, ascending; an eigenvalue below zero by
//! rounding (the rigid mode of a chain free at both ends) gives ω = 0. Dashpots are ignored
//! here; [`crate::damped`] keeps them.
//!
//! The dense problem costs O(n²) memory and O(n³) time, so it is refused above
//! [`MAX_DENSE_ORDER`]; [`crate::localised`] finds the modes in given frequency windows of a
//! chain of any length.

use faer::{Mat, Side};

use crate::bands::Interval;
use crate::chain::LinearChain;
use crate::error::SpectrumError;
use crate::matrices;
use crate::shape::{clusters, localisation, localise_cluster, Localisation};

/// The largest order of a matrix the dense solvers decompose: the degrees of freedom for
/// [`normal_modes`], twice that for [`crate::damped::damped_modes`]. At 2048 a matrix and its
/// eigenvectors take 2 × 32 MiB, and the decomposition takes seconds on one core (measured by
/// `examples/scale.rs`); a chain of 10,000 sites (800 MiB per matrix, minutes) is refused.
pub const MAX_DENSE_ORDER: usize = 2048;

/// One undamped normal mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// ω (rad per unit time).
    pub omega: f64,
    /// v over every degree of freedom (sites, then resonators), mass-normalised.
    pub shape: Vec<f64>,
    /// How localised it is, from its site entries ([`crate::shape`]).
    pub localisation: Localisation,
}

impl Mode {
    /// A mode from its frequency and shape: normalises the shape (v^T M v = 1, largest entry
    /// positive) with the degree-of-freedom masses `dof_masses` and measures its localisation
    /// over the first `n_sites` entries.
    pub(crate) fn new(omega: f64, mut shape: Vec<f64>, dof_masses: &[f64], n_sites: usize) -> Mode {
        let norm: f64 = shape.iter().zip(dof_masses).map(|(v, m)| m * v * v).sum();
        let largest = shape
            .iter()
            .copied()
            .fold(0.0, |a: f64, v| match v.abs() > a.abs() {
                true => v,
                false => a,
            });
        let scale = largest.signum() / norm.sqrt();
        shape.iter_mut().for_each(|v| *v *= scale);
        let weights: Vec<f64> = shape[..n_sites].iter().map(|u| u * u).collect();
        Mode {
            omega,
            localisation: localisation(&weights),
            shape,
        }
    }

    /// The site displacements (the first `n_sites` entries of the shape).
    pub fn sites(&self, n_sites: usize) -> &[f64] {
        &self.shape[..n_sites.min(self.shape.len())]
    }

    /// Whether its frequency lies in one of `windows` (for instance a host's gaps).
    pub fn in_any(&self, windows: &[Interval]) -> bool {
        windows.iter().any(|w| w.contains(self.omega))
    }
}

/// Every undamped mode of `chain`, ascending in frequency (see the module documentation).
pub fn normal_modes(chain: &LinearChain) -> Result<Vec<Mode>, SpectrumError> {
    let order = chain.n_dof();
    if order > MAX_DENSE_ORDER {
        return Err(SpectrumError::TooLargeForDense {
            order,
            limit: MAX_DENSE_ORDER,
        });
    }
    let masses = chain.dof_masses();
    let scale: Vec<f64> = masses.iter().map(|m| 1.0 / m.sqrt()).collect();
    let k = matrices::stiffness(chain);
    let a = Mat::from_fn(order, order, |i, j| k[(i, j)] * scale[i] * scale[j]);
    let eigen = a
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| SpectrumError::NoConvergence {
            what: "reduced stiffness M^-1/2 K M^-1/2",
        })?;
    let (values, vectors) = (eigen.S().column_vector(), eigen.U());
    let sigmas: Vec<f64> = values.iter().copied().collect();
    let mut shapes: Vec<Vec<f64>> = (0..order)
        .map(|j| (0..order).map(|i| vectors[(i, j)] * scale[i]).collect())
        .collect();
    for cluster in clusters(&sigmas) {
        localise_cluster(&mut shapes[cluster], &masses, chain.n_sites());
    }
    Ok(sigmas
        .into_iter()
        .zip(shapes)
        .map(|(sigma, shape)| Mode::new(sigma.max(0.0).sqrt(), shape, &masses, chain.n_sites()))
        .collect())
}

#[cfg(test)]
mod tests;
