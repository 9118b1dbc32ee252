//! Complex frequencies of a damped chain: the quadratic eigenproblem
//! (λ² M + λ C + K) v = 0, solved as the standard problem of the 2n × 2n state-space companion
//!
//! ```text
//! d/dt [u; u'] = A [u; u'],   A = [[0, I], [−M⁻¹K, −M⁻¹C]],   u(t) = v e^{λt}
//! ```
//!
//! with faer's general (non-symmetric) eigendecomposition, eigenvectors included.
//!
//! Sign convention: a mode decays as e^{λt} with λ = −γ + iω_d. [`DampedMode::decay_rate`] is
//! γ = −Re λ, positive for a decaying mode; [`DampedMode::omega`] is ω_d = Im λ ≥ 0 (of each
//! conjugate pair only the member with Im λ ≥ 0 is returned; an overdamped mode, λ real, is
//! returned once per eigenvalue). The quality factor is Q = |λ| / (2γ): for one oscillator
//! (m, c, k), |λ| = sqrt(k/m) and γ = c/(2m), so Q = sqrt(k m)/c, the usual one; Q is infinite
//! without loss and 1/2 for a real λ.

use faer::{c64, Mat};

use crate::chain::LinearChain;
use crate::error::SpectrumError;
use crate::matrices;
use crate::modes::MAX_DENSE_ORDER;

/// One mode of the damped chain.
#[derive(Debug, Clone, PartialEq)]
pub struct DampedMode {
    /// λ, with u(t) = Re[v e^{λt}].
    pub eigenvalue: c64,
    /// v over the degrees of freedom (sites, then resonators), scaled so that its entry of
    /// largest magnitude is 1.
    pub shape: Vec<c64>,
}

impl DampedMode {
    /// ω_d = Im λ ≥ 0, the frequency at which it oscillates.
    pub fn omega(&self) -> f64 {
        self.eigenvalue.im
    }

    /// γ = −Re λ: positive when the mode decays.
    pub fn decay_rate(&self) -> f64 {
        -self.eigenvalue.re
    }

    /// |λ|: the undamped frequency for one oscillator, sqrt(ω_d² + γ²).
    pub fn natural_frequency(&self) -> f64 {
        self.eigenvalue.norm()
    }

    /// Q = |λ| / (2γ); infinite when γ ≤ 0.
    pub fn q_factor(&self) -> f64 {
        match self.decay_rate() > 0.0 {
            true => self.natural_frequency() / (2.0 * self.decay_rate()),
            false => f64::INFINITY,
        }
    }
}

/// Every mode of `chain` with its dashpots, ascending in |λ| (see the module documentation).
/// Refused when 2 × degrees of freedom exceeds [`MAX_DENSE_ORDER`].
pub fn damped_modes(chain: &LinearChain) -> Result<Vec<DampedMode>, SpectrumError> {
    let n = chain.n_dof();
    if 2 * n > MAX_DENSE_ORDER {
        return Err(SpectrumError::TooLargeForDense {
            order: 2 * n,
            limit: MAX_DENSE_ORDER,
        });
    }
    let eigen = companion(chain)
        .eigen()
        .map_err(|_| SpectrumError::NoConvergence {
            what: "state-space companion of (M, C, K)",
        })?;
    let (values, vectors) = (eigen.S().column_vector(), eigen.U());
    let mut modes: Vec<DampedMode> = (0..2 * n)
        .filter(|&j| values[j].im >= 0.0)
        .map(|j| DampedMode {
            eigenvalue: values[j],
            shape: scaled((0..n).map(|i| vectors[(i, j)]).collect()),
        })
        .collect();
    modes.sort_by(|a, b| a.natural_frequency().total_cmp(&b.natural_frequency()));
    Ok(modes)
}

/// A = [[0, I], [−M⁻¹K, −M⁻¹C]].
fn companion(chain: &LinearChain) -> Mat<f64> {
    let n = chain.n_dof();
    let masses = chain.dof_masses();
    let (k, c) = (matrices::stiffness(chain), matrices::damping(chain));
    Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => 0.0,
        (true, false) => f64::from(u8::from(j - n == i)),
        (false, true) => -k[(i - n, j)] / masses[i - n],
        (false, false) => -c[(i - n, j - n)] / masses[i - n],
    })
}

/// `v` divided by its entry of largest magnitude (unchanged if all zero).
fn scaled(mut v: Vec<c64>) -> Vec<c64> {
    let largest = v
        .iter()
        .copied()
        .fold(c64::new(0.0, 0.0), |a, x| match x.norm() > a.norm() {
            true => x,
            false => a,
        });
    if largest.norm() > 0.0 {
        v.iter_mut().for_each(|x| *x /= largest);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chain::ChainSpec;
    use std::f64::consts::PI;

    /// One mass m on a spring k and a dashpot c to a wall: λ = −c/(2m) ± i sqrt(k/m − c²/(4m²)).
    #[test]
    fn a_damped_oscillator() {
        let (m, k, c) = (2.0, 3.0, 0.4);
        let spec = ChainSpec {
            masses: vec![m],
            bond_stiffness: vec![k, 0.0],
            bond_damping: vec![c, 0.0],
            ..ChainSpec::default()
        };
        let modes = damped_modes(&LinearChain::new(spec).unwrap()).unwrap();
        assert_eq!(modes.len(), 1);
        let mode = &modes[0];
        let gamma = c / (2.0 * m);
        let omega_d = (k / m - gamma * gamma).sqrt();
        assert!((mode.decay_rate() - gamma).abs() < 1e-10 * gamma);
        assert!((mode.omega() - omega_d).abs() < 1e-10 * omega_d);
        assert!((mode.natural_frequency() - (k / m).sqrt()).abs() < 1e-10);
        let q = (k * m).sqrt() / c;
        assert!((mode.q_factor() - q).abs() < 1e-10 * q);
        assert_eq!(mode.shape, vec![c64::new(1.0, 0.0)]);
    }

    /// Ground dashpots proportional to the masses, g = a m: every mode keeps its shape and gets
    /// λ = −a/2 ± i sqrt(ω_k² − a²/4), ω_k the undamped frequencies of the chain.
    #[test]
    fn mass_proportional_damping_shifts_every_mode_alike() {
        let (n, m, k, a) = (12, 1.5, 2.0, 0.3);
        let mut spec = ChainSpec::uniform(n, m, k);
        spec.ground_damping = vec![a * m; n];
        let modes = damped_modes(&LinearChain::new(spec).unwrap()).unwrap();
        assert_eq!(modes.len(), n);
        for (j, mode) in modes.iter().enumerate() {
            let omega_k =
                2.0 * (k / m).sqrt() * ((j + 1) as f64 * PI / (2.0 * (n + 1) as f64)).sin();
            let omega_d = (omega_k * omega_k - a * a / 4.0).sqrt();
            assert!((mode.decay_rate() - a / 2.0).abs() < 1e-10, "mode {j}");
            assert!((mode.omega() - omega_d).abs() < 1e-10 * omega_d, "mode {j}");
        }
    }

    #[test]
    fn an_overdamped_oscillator_has_two_real_modes() {
        // m = 1, k = 1, c = 3: λ = (−3 ± sqrt(5))/2, both real.
        let spec = ChainSpec {
            masses: vec![1.0],
            bond_stiffness: vec![1.0, 0.0],
            bond_damping: vec![3.0, 0.0],
            ..ChainSpec::default()
        };
        let modes = damped_modes(&LinearChain::new(spec).unwrap()).unwrap();
        assert_eq!(modes.len(), 2);
        let slow = (3.0 - 5f64.sqrt()) / 2.0;
        assert!((modes[0].decay_rate() - slow).abs() < 1e-10);
        assert_eq!(modes[0].omega(), 0.0);
        assert!((modes[0].q_factor() - 0.5).abs() < 1e-12);
    }

    #[test]
    fn undamped_modes_do_not_decay() {
        let chain = LinearChain::new(ChainSpec::uniform(6, 1.0, 1.0)).unwrap();
        for mode in damped_modes(&chain).unwrap() {
            assert!(mode.decay_rate().abs() < 1e-12);
            assert!(mode.q_factor() > 1e10);
        }
    }

    #[test]
    fn refuses_beyond_the_dense_limit() {
        let chain =
            LinearChain::new(ChainSpec::uniform(MAX_DENSE_ORDER / 2 + 1, 1.0, 1.0)).unwrap();
        assert!(matches!(
            damped_modes(&chain),
            Err(SpectrumError::TooLargeForDense { .. })
        ));
    }
}
