//! How localised a mode is, from the displacements of its sites alone (a resonator rides on its
//! host and is not counted separately).
//!
//! With weights w_n = |u_n|² over the sites:
//!
//! ```text
//! participation  P = (Σ w_n)² / Σ w_n²     (1 for one site, S for a uniform mode)
//! length         ξ solves P = coth(1/ξ)² / coth(2/ξ)
//! ```
//!
//! ξ is the decay length of the amplitude of the two-sided exponential |u_n| ∝ e^{−|n−n0|/ξ}
//! on an infinite lattice that has the same participation: for such a mode it is exact, so a
//! defect mode whose tails decay as e^{−κ|n|} has ξ = 1/κ (κ the attenuation per site of the
//! host's gap, [`crate::bands::Wavenumber`]). For large ξ, P ≈ 2ξ. A one-sided (surface) mode
//! of decay length ℓ has P ≈ ℓ, hence ξ ≈ ℓ/2; a mode spread over the chain has ξ ≈ P/2,
//! a fraction of the chain's length.

/// The localisation measures of one mode (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Localisation {
    /// The site of largest |u_n|.
    pub peak_site: usize,
    /// P, in sites.
    pub participation: f64,
    /// ξ, in sites (0 for a mode on a single site).
    pub length: f64,
}

/// The measures of a mode with site weights `weights` (w_n = |u_n|², not all zero).
pub fn localisation(weights: &[f64]) -> Localisation {
    let (mut sum, mut sum_sq, mut peak_site, mut peak) = (0.0, 0.0, 0, f64::NEG_INFINITY);
    for (site, &w) in weights.iter().enumerate() {
        sum += w;
        sum_sq += w * w;
        if w > peak {
            (peak_site, peak) = (site, w);
        }
    }
    let participation = match sum_sq > 0.0 {
        true => (sum * sum / sum_sq).max(1.0),
        false => 0.0,
    };
    Localisation {
        peak_site,
        participation,
        length: length_of_participation(participation),
    }
}

/// ξ from P: with c = coth(1/ξ), P = 2c³/(1 + c²), so c is the root ≥ 1 of
/// f(c) = 2c³ − P c² − P. f is convex and increasing on [P/2, P/2 + 1], which brackets the
/// root (f(P/2) = −P, f(P/2 + 1) = 2(P/2 + 1)² − P > 0), so Newton from the right end descends
/// monotonically onto it.
fn length_of_participation(participation: f64) -> f64 {
    if participation <= 1.0 {
        return 0.0;
    }
    let p = participation;
    let mut c = p / 2.0 + 1.0;
    for _ in 0..100 {
        let f = 2.0 * c * c * c - p * c * c - p;
        let slope = 6.0 * c * c - 2.0 * p * c;
        let next = c - f / slope;
        if next.is_nan() || next >= c {
            break;
        }
        c = next;
    }
    let c = c.max(1.0);
    1.0 / (1.0 / c).atanh()
}

/// Rotates a cluster of (numerically) degenerate mode shapes, M-orthonormal, into the most
/// localised basis of the same span, by the selected columns of the density matrix (Damle, Lin
/// and Ying, J. Chem. Theory Comput. 11, 1463 (2015)): with Y = M^{1/2} V (orthonormal
/// columns), a column-pivoted QR of Y^T picks one site per vector, the site most represented
/// in what is left of the span; each new vector is the projection of that site's unit vector
/// onto the span, Y Y^T e_s, M-orthonormalised in pivot order. For identical defects far apart,
/// whose modes agree to rounding so that any basis of their span is what an eigensolver
/// returns, this gives one mode per defect instead of arbitrary mixtures.
pub(crate) fn localise_cluster(shapes: &mut [Vec<f64>], masses: &[f64], n_sites: usize) {
    let k = shapes.len();
    if k < 2 {
        return;
    }
    let root: Vec<f64> = masses.iter().map(|m| m.sqrt()).collect();
    let y: Vec<Vec<f64>> = shapes
        .iter()
        .map(|v| v.iter().zip(&root).map(|(v, r)| v * r).collect())
        .collect();
    // Pivoted QR on the columns (sites) of Y^T: `residual[s]` holds column s with the chosen
    // directions projected out.
    let mut residual: Vec<Vec<f64>> = (0..n_sites)
        .map(|s| y.iter().map(|v| v[s]).collect())
        .collect();
    let mut pivots = Vec::with_capacity(k);
    for _ in 0..k {
        let norm = |c: &Vec<f64>| c.iter().map(|x| x * x).sum::<f64>();
        let Some(best) =
            (0..n_sites).max_by(|&a, &b| norm(&residual[a]).total_cmp(&norm(&residual[b])))
        else {
            return;
        };
        let size = norm(&residual[best]).sqrt();
        if size == 0.0 {
            return;
        }
        let q: Vec<f64> = residual[best].iter().map(|x| x / size).collect();
        for column in residual.iter_mut() {
            let dot: f64 = column.iter().zip(&q).map(|(c, q)| c * q).sum();
            column.iter_mut().zip(&q).for_each(|(c, q)| *c -= dot * q);
        }
        pivots.push(best);
    }
    let mut basis: Vec<Vec<f64>> = Vec::with_capacity(k);
    for &s in &pivots {
        let mut w = vec![0.0; masses.len()];
        for v in &y {
            w.iter_mut().zip(v).for_each(|(w, x)| *w += v[s] * x);
        }
        for b in &basis {
            let dot: f64 = w.iter().zip(b).map(|(w, b)| w * b).sum();
            w.iter_mut().zip(b).for_each(|(w, b)| *w -= dot * b);
        }
        let size = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        w.iter_mut().for_each(|x| *x /= size);
        basis.push(w);
    }
    for (shape, w) in shapes.iter_mut().zip(basis) {
        *shape = w.iter().zip(&root).map(|(w, r)| w / r).collect();
    }
}

/// Eigenvalues closer than this (relative) form a cluster whose vectors are orthogonalised.
pub(crate) const CLUSTER: f64 = 1e-8;

/// The ranges of consecutive ascending eigenvalues closer than [`CLUSTER`] (relative) to their
/// neighbour, of two or more members.
pub(crate) fn clusters(sigmas: &[f64]) -> Vec<std::ops::Range<usize>> {
    let mut ranges = Vec::new();
    let mut first = 0;
    for i in 1..=sigmas.len() {
        let joined = i < sigmas.len()
            && (sigmas[i] - sigmas[i - 1]).abs()
                <= CLUSTER * sigmas[i].abs().max(f64::MIN_POSITIVE);
        if !joined {
            if i - first > 1 {
                ranges.push(first..i);
            }
            first = i;
        }
    }
    ranges
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mixed_pair_is_rotated_back_onto_its_two_sites() {
        // Two unit vectors on sites 1 and 4, mixed at 45° (unit masses).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mut shapes = vec![
            vec![0.0, h, 0.0, 0.0, h, 0.0],
            vec![0.0, h, 0.0, 0.0, -h, 0.0],
        ];
        localise_cluster(&mut shapes, &[1.0; 6], 6);
        let peaks: Vec<usize> = shapes
            .iter()
            .map(|v| localisation(&v.iter().map(|x| x * x).collect::<Vec<_>>()).peak_site)
            .collect();
        assert!(peaks == [1, 4] || peaks == [4, 1], "{peaks:?}");
        for v in &shapes {
            assert!((v.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-14);
            assert_eq!(v.iter().filter(|x| x.abs() > 1e-14).count(), 1);
        }
    }

    #[test]
    fn one_site_and_uniform_modes() {
        let one = localisation(&[0.0, 0.0, 4.0, 0.0]);
        assert_eq!(one.peak_site, 2);
        assert_eq!(one.participation, 1.0);
        assert_eq!(one.length, 0.0);
        let uniform = localisation(&[0.3; 50]);
        assert!((uniform.participation - 50.0).abs() < 1e-12);
    }

    #[test]
    fn a_two_sided_exponential_gives_its_decay_length() {
        for xi in [0.3, 1.0, 2.5, 17.0] {
            // Long enough that the truncated tails are below rounding.
            let half = (40.0 * xi) as usize + 40;
            let weights: Vec<f64> = (0..=2 * half)
                .map(|n| (-2.0 * (n as f64 - half as f64).abs() / xi).exp())
                .collect();
            let got = localisation(&weights);
            assert_eq!(got.peak_site, half);
            assert!(
                (got.length - xi).abs() < 1e-10 * xi,
                "ξ {xi}: {}",
                got.length
            );
        }
    }
}
