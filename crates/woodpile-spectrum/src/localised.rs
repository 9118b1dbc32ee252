//! The modes of a long chain inside given frequency windows (a host's gaps, the range above its
//! top band): where defect modes live. Cost O(n) per bisection step and per solve, so a chain of
//! any length is searched in milliseconds; no dense matrix is formed.
//!
//! Eigenvalues come from bisection on the Sturm count of the condensed pencil
//! ([`crate::tridiagonal`]), to a few ulps of σ = ω²; each shape from inverse iteration at that
//! σ with the same O(n) solve, M-orthogonalised against the modes already found in a cluster of
//! (nearly) equal eigenvalues, as LAPACK's `dstein` does, so that two identical defects far
//! apart still give two independent modes; such a cluster is then rotated into its most localised
//! basis ([`crate::shape`]), one mode per defect. Shapes are normalised as [`crate::modes`]'s.

use std::collections::BTreeSet;

use crate::bands::Interval;
use crate::chain::LinearChain;
use crate::error::SpectrumError;
use crate::modes::Mode;
use crate::shape::{clusters, localise_cluster, CLUSTER};
use crate::tridiagonal::Condensed;

/// The most modes one search returns: a window holding more overlaps a pass band, where the
/// dense solver (short chains) is the tool.
pub const MAX_LOCALISED: usize = 256;

/// Inverse-iteration steps per mode: the shift is the eigenvalue to a few ulps, so each step
/// gains a factor gap/ulps and two already converge; the rest is margin.
const INVERSE_STEPS: usize = 4;

/// The number of undamped eigenfrequencies of `chain` below `omega` (its integrated density of
/// states), in O(n).
pub fn count_below(chain: &LinearChain, omega: f64) -> usize {
    Condensed::new(chain, omega * omega).count_below()
}

/// Every undamped mode of `chain` whose frequency lies in one of `windows` (each
/// 0 ≤ lower < upper, finite; overlapping windows give each mode once), ascending in frequency.
/// Refused with [`SpectrumError::TooManyModes`] when the windows hold more than
/// [`MAX_LOCALISED`] modes.
pub fn localised_modes(
    chain: &LinearChain,
    windows: &[Interval],
) -> Result<Vec<Mode>, SpectrumError> {
    let mut indices = BTreeSet::new();
    for w in windows {
        if !(w.lower.is_finite() && w.upper.is_finite() && 0.0 <= w.lower && w.lower < w.upper) {
            return Err(SpectrumError::BadWindow {
                lower: w.lower,
                upper: w.upper,
            });
        }
        let (first, end) = (count_below(chain, w.lower), count_below(chain, w.upper));
        if end.saturating_sub(first) > MAX_LOCALISED {
            return Err(SpectrumError::TooManyModes {
                lower: w.lower,
                upper: w.upper,
                count: end.saturating_sub(first),
                limit: MAX_LOCALISED,
            });
        }
        indices.extend(first..end);
    }
    if indices.len() > MAX_LOCALISED {
        return Err(SpectrumError::TooManyModes {
            lower: windows
                .iter()
                .map(|w| w.lower)
                .fold(f64::INFINITY, f64::min),
            upper: windows.iter().map(|w| w.upper).fold(0.0, f64::max),
            count: indices.len(),
            limit: MAX_LOCALISED,
        });
    }
    let upper = chain.frequency_bound().powi(2) * (1.0 + 1e-12) + f64::MIN_POSITIVE;
    let masses = chain.dof_masses();
    let mut found: Vec<(f64, Vec<f64>)> = Vec::with_capacity(indices.len());
    for index in indices {
        let sigma = bisect(chain, index, upper);
        let cluster: Vec<&[f64]> = found
            .iter()
            .filter(|(s, _)| (s - sigma).abs() <= CLUSTER * sigma.abs().max(f64::MIN_POSITIVE))
            .map(|(_, v)| v.as_slice())
            .collect();
        let shape = inverse_iteration(chain, sigma, &masses, &cluster, index);
        found.push((sigma, shape));
    }
    let n = chain.n_sites();
    let (sigmas, mut shapes): (Vec<f64>, Vec<Vec<f64>>) = found.into_iter().unzip();
    for cluster in clusters(&sigmas) {
        localise_cluster(&mut shapes[cluster], &masses, n);
    }
    Ok(sigmas
        .into_iter()
        .zip(shapes)
        .map(|(sigma, shape)| Mode::new(sigma.max(0.0).sqrt(), shape, &masses, n))
        .collect())
}

/// σ_index (0-based, ascending) by bisection between 0 and `upper` (above every eigenvalue),
/// until the bracket is a few ulps wide.
fn bisect(chain: &LinearChain, index: usize, upper: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, upper);
    for _ in 0..2100 {
        let mid = 0.5 * (lo + hi);
        if hi - lo <= 4.0 * f64::EPSILON * hi.abs() || mid <= lo || mid >= hi {
            break;
        }
        match Condensed::new(chain, mid).count_below() > index {
            true => hi = mid,
            false => lo = mid,
        }
    }
    0.5 * (lo + hi)
}

/// The eigenvector at eigenvalue `sigma`: repeated solves of (K − σM) x_{k+1} = M x_k from a
/// fixed pseudo-random start (seeded by `index`), M-orthogonal to `cluster`.
fn inverse_iteration(
    chain: &LinearChain,
    sigma: f64,
    masses: &[f64],
    cluster: &[&[f64]],
    index: usize,
) -> Vec<f64> {
    let pencil = Condensed::new(chain, sigma);
    let mut x = start_vector(masses.len(), index);
    for _ in 0..INVERSE_STEPS {
        orthogonalise(&mut x, cluster, masses);
        let rhs: Vec<f64> = x.iter().zip(masses).map(|(v, m)| v * m).collect();
        x = pencil.solve(&rhs);
        orthogonalise(&mut x, cluster, masses);
        let largest = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        if largest > 0.0 && largest.is_finite() {
            x.iter_mut().for_each(|v| *v /= largest);
        }
    }
    x
}

/// Removes from `x` its M-projection on each vector of `basis`.
fn orthogonalise(x: &mut [f64], basis: &[&[f64]], masses: &[f64]) {
    for b in basis {
        let dot: f64 = x
            .iter()
            .zip(b.iter())
            .zip(masses)
            .map(|((x, b), m)| x * b * m)
            .sum();
        let norm: f64 = b.iter().zip(masses).map(|(b, m)| b * b * m).sum();
        if norm > 0.0 {
            x.iter_mut()
                .zip(b.iter())
                .for_each(|(x, b)| *x -= dot / norm * b);
        }
    }
}

/// Entries in [0.5, 1.5) from a small linear congruential generator seeded by `seed`: no
/// symmetry of the chain can make it orthogonal to a mode.
fn start_vector(len: usize, seed: usize) -> Vec<f64> {
    let mut state = 0x9E37_79B9_7F4A_7C15_u64 ^ (seed as u64).wrapping_mul(0xD1B5_4A32_D192_ED03);
    (0..len)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            0.5 + (state >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

#[cfg(test)]
mod tests;
