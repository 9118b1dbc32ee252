//! Resonators folded into their host: at one frequency a resonator is only a frequency-dependent
//! addition to its host's mass. The band wavenumbers and the transmission both propagate
//! waves site by site and need nothing more of a resonator than this.
//!
//! ```text
//! m_eff(ω) = m1 + sum_r m_r k~_r / (k~_r − m_r ω²),    k~_r = k_r − i ω c_r
//! ```
//!
//! With ω0² = k/m2 and no dashpot, each term is m2 ω0² / (ω0² − ω²): heavier than m2 below ω0,
//! negative above, infinite at ω0, where the resonator pins its host. The complex form follows
//! the crate's convention u(t) = Re[u e^{−iωt}], so a dashpot of rate c adds −iωc to a stiffness.

use faer::c64;

use crate::chain::LinearResonator;

/// The effective mass of a site of mass `host_mass` carrying `resonators` (their `site` field is
/// not read), at angular frequency `omega`, dashpots included (see the module documentation).
/// `None` exactly at an undamped resonance, where the mass is infinite and the host is pinned.
pub fn effective_mass(
    host_mass: f64,
    resonators: impl IntoIterator<Item = LinearResonator>,
    omega: f64,
) -> Option<c64> {
    let mut mass = c64::new(host_mass, 0.0);
    for r in resonators {
        let k = c64::new(r.stiffness, -omega * r.damping);
        let den = k - r.mass * omega * omega;
        if den == c64::new(0.0, 0.0) {
            return None;
        }
        mass += r.mass * k / den;
    }
    Some(mass)
}

/// The undamped effective mass (dashpots ignored), `None` at a resonance.
pub(crate) fn effective_mass_real(
    host_mass: f64,
    resonators: impl IntoIterator<Item = LinearResonator>,
    omega: f64,
) -> Option<f64> {
    let mut mass = host_mass;
    for r in resonators {
        let den = r.stiffness - r.mass * omega * omega;
        if den == 0.0 {
            return None;
        }
        mass += r.mass * r.stiffness / den;
    }
    Some(mass)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_effective_mass_of_one_resonator() {
        // m1 = 1, m2 = 0.5, k2 = 2: ω0² = 4.
        let r = LinearResonator {
            site: 0,
            mass: 0.5,
            stiffness: 2.0,
            damping: 0.0,
        };
        for omega in [0.0, 0.7, 1.9, 2.1, 5.0] {
            let expected = 1.0 + 0.5 * 4.0 / (4.0 - omega * omega);
            let got = effective_mass(1.0, [r], omega).unwrap();
            assert!((got.re - expected).abs() < 1e-14 * expected.abs());
            assert_eq!(got.im, 0.0);
            let real = effective_mass_real(1.0, [r], omega).unwrap();
            assert!((real - expected).abs() < 1e-14 * expected.abs());
        }
        assert_eq!(effective_mass(1.0, [r], 2.0), None);
        // With a dashpot the resonance is finite and lossy: Im m_eff > 0 means a force in phase
        // with the velocity −iωu, against the motion, with e^{−iωt}.
        let damped = LinearResonator { damping: 0.1, ..r };
        let m = effective_mass(1.0, [damped], 2.0).unwrap();
        // k~ = 2 − 0.2i, den = −0.2i: m = 1 + 0.5 (2 − 0.2i)/(−0.2i) = 1 + 0.5 + 5i.
        assert!((m - c64::new(1.5, 5.0)).norm() < 1e-13);
    }
}
