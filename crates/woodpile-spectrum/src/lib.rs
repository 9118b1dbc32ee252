//! The linear picture of a granular chain with internal resonators: linearised about a static
//! (precompressed) state, the chain is a set of masses and springs, and this crate computes its
//! Bloch bands, normal modes (damped or not), modes localised at defects, and the transmission of
//! a defect region between uniform chains. Numbers in, numbers out: no IO, no printing.
//!
//! The pieces:
//! - [`chain`]: [`LinearChain`], the validated description every computation reads (masses,
//!   bonds with the two ends as springs to rigid supports, dashpots, linear resonators).
//! - [`linearise`](mod@linearise): a woodpile-sim [`woodpile_sim::Model`] and its static overlaps → a
//!   [`LinearChain`]; the only module that knows the simulator.
//! - [`bands`]: a periodic [`bands::Cell`]: ω_j(q), pass bands, gaps, and the complex
//!   wavenumber (attenuation per cell) in a gap.
//! - [`modes`]: every undamped mode of a chain up to [`modes::MAX_DENSE_ORDER`] degrees of
//!   freedom; [`damped`]: complex frequencies, decay rates and Q with the dashpots.
//! - [`localised`]: the modes inside given windows (a host's gaps) of a chain of any length,
//!   by Sturm bisection and inverse iteration in O(n); [`shape`]: participation and
//!   localisation length of a mode.
//! - [`transmission`]: t, r and the phase of a region between two uniform leads, O(n) per
//!   frequency; [`condense`]: the resonators' frequency-dependent effective mass it uses.
//!
//! # Conventions
//! - Frequencies are angular, ω in radians per unit time (the crate is unit-agnostic: SI or the
//!   simulator's dimensionless units alike); [`hz`] and [`angular`] convert for callers.
//! - Wavenumbers q are radians per cell (per site for a uniform chain), in [0, π].
//! - Harmonic quantities use u(t) = Re[u e^{−iωt}]: a dashpot c adds −iωc to a stiffness, a
//!   wave e^{iqn} runs towards +n, and lossy effective masses have Im m_eff > 0.
//! - Free decay is u(t) = v e^{λt}, λ = −γ + iω_d; the decay rate γ = −Re λ is positive for a
//!   decaying mode, and Q = |λ|/(2γ) ([`damped`]).
//! - Undamped mode shapes cover all degrees of freedom (sites, then resonators in the chain's
//!   order) and are mass-normalised, v^T M v = 1, largest entry positive.
//!
//! # Linear algebra: faer
//! Dense eigenproblems use [faer](https://docs.rs/faer) 0.24 (`default-features = false`,
//! features `std` and `linalg`: no rayon, no sparse, no rand/npy). It offers, maintained in one
//! crate, what the three problems need: the self-adjoint eigensolver for real symmetric and
//! complex Hermitian matrices (the reduced stiffness M^{-1/2} K M^{-1/2}, the Bloch matrix
//! D(q)), and a general non-symmetric eigendecomposition *with eigenvectors* (the state-space
//! companion of the damped problem), with blocked algorithms that decompose an order-2048
//! matrix in seconds. nalgebra was the alternative: its symmetric eigensolver covers Hermitian
//! matrices too, but for a general matrix it gives eigenvalues only (no damped mode shapes)
//! and its unblocked algorithms are slower at these orders. The price is compile time, measured
//! here on 2 shared cores from a clean target: about 2 min for the first release build of this
//! crate with faer's stack (gemm, pulp, …) against 21 s for nalgebra alone; incremental
//! rebuilds of this crate take about 10 s.
//!
//! # Long chains
//! Nothing dense is formed for [`localised`] or [`transmission`]. Each resonator couples only
//! to its host, so eliminating it first leaves a symmetric tridiagonal pencil over the sites
//! (no fill); its Sturm count (Sylvester's inertia) brackets every eigenvalue in a window, and
//! inverse iteration with a pivoted tridiagonal solve gives the shapes: standard numerics
//! (LAPACK's `dstebz`/`dstein` in spirit) in O(n) per step. The transfer matrices of
//! [`transmission`] are 2×2 per site for the same reason. Dense solves are refused above
//! [`modes::MAX_DENSE_ORDER`] with [`SpectrumError::TooLargeForDense`].
#![warn(missing_docs)]

pub mod analysis;
pub mod bands;
pub mod chain;
pub mod condense;
pub mod damped;
mod error;
pub mod host;
pub mod linearise;
pub mod localised;
mod matrices;
pub mod measured;
pub mod modes;
pub mod scene;
pub mod shape;
pub mod tables;
pub mod transmission;
mod tridiagonal;

pub use analysis::{analyse, Analysis, FrequencyGrid, Request};
pub use bands::{Bands, Cell, Interval, Wavenumber};
pub use chain::{ChainSpec, LinearChain, LinearResonator};
pub use condense::effective_mass;
pub use damped::{damped_modes, DampedMode};
pub use error::{RangeFault, SpectrumError};
pub use faer::c64;
pub use host::{HostCell, Scatterer};
pub use linearise::{linearise, linearise_precompressed, Linearised};
pub use localised::{count_below, localised_modes};
pub use modes::{normal_modes, Mode};
pub use shape::Localisation;
pub use transmission::{scatter, Lead, Scattering};

/// Frequency in Hz (cycles per unit time) of an angular frequency ω: ω / 2π.
pub fn hz(omega: f64) -> f64 {
    omega / std::f64::consts::TAU
}

/// Angular frequency 2π f of a frequency `f` in Hz.
pub fn angular(f: f64) -> f64 {
    f * std::f64::consts::TAU
}

#[cfg(test)]
mod tests {
    #[test]
    fn hz_and_angular_invert_each_other() {
        assert_eq!(super::hz(std::f64::consts::TAU), 1.0);
        assert_eq!(super::angular(0.5), std::f64::consts::PI);
    }
}
