//! Known answers: the light-mass defect (Montroll–Potts) in a long chain, two distant identical
//! defects, a resonator missing from a mass-in-mass host; and agreement with the dense solver.

use super::*;
use crate::bands::Cell;
use crate::chain::{ChainSpec, LinearResonator};
use crate::modes::normal_modes;

fn close(got: f64, expected: f64, tol: f64) -> bool {
    (got - expected).abs() <= tol * expected.abs()
}

fn resonator(site: usize, mass: f64, stiffness: f64) -> LinearResonator {
    LinearResonator {
        site,
        mass,
        stiffness,
        damping: 0.0,
    }
}

fn everything(chain: &LinearChain) -> [Interval; 1] {
    [Interval {
        lower: 0.0,
        upper: chain.frequency_bound() * 1.01,
    }]
}

#[test]
fn agrees_with_the_dense_solver() {
    let mut spec = ChainSpec::uniform(30, 1.0, 1.0);
    spec.bond_stiffness[0] = 0.0;
    spec.bond_stiffness[30] = 0.4;
    spec.masses[7] = 2.5;
    spec.resonators = vec![
        resonator(3, 0.5, 0.7),
        resonator(3, 0.2, 1.9),
        resonator(20, 1.5, 0.3),
        resonator(29, 0.1, 3.0),
    ];
    let chain = LinearChain::new(spec).unwrap();
    let dense = normal_modes(&chain).unwrap();
    let sparse = localised_modes(&chain, &everything(&chain)).unwrap();
    assert_eq!(sparse.len(), chain.n_dof());
    for (j, (d, s)) in dense.iter().zip(&sparse).enumerate() {
        assert!(
            close(s.omega, d.omega, 1e-10),
            "mode {j}: {} vs {}",
            s.omega,
            d.omega
        );
        for (a, b) in d.shape.iter().zip(&s.shape) {
            assert!((a - b).abs() < 1e-8, "mode {j}");
        }
    }
}

/// A light mass m' at the centre of 20,001 sites of mass m: one mode above the cutoff,
/// ω² = 4Km/(m'(2m − m')), decaying as (m'/(2m − m'))^{|n|}.
#[test]
fn a_light_defect_in_a_long_chain() {
    let (n, centre, light) = (20_001, 10_000, 0.5);
    let mut spec = ChainSpec::uniform(n, 1.0, 1.0);
    spec.masses[centre] = light;
    let chain = LinearChain::new(spec).unwrap();
    let above = [Interval {
        lower: 2.0,
        upper: chain.frequency_bound() + 1.0,
    }];
    let modes = localised_modes(&chain, &above).unwrap();
    assert_eq!(modes.len(), 1);
    let expected = (4.0 / (light * (2.0 - light))).sqrt();
    assert!(close(modes[0].omega, expected, 1e-12), "{}", modes[0].omega);
    assert_eq!(modes[0].localisation.peak_site, centre);
    assert!(close(modes[0].localisation.length, 1.0 / 3f64.ln(), 1e-10));
    let ratio = modes[0].shape[centre + 3] / modes[0].shape[centre];
    assert!(close(ratio, -1.0 / 27.0, 1e-10));
    assert_eq!(count_below(&chain, 2.0), n - 1);
}

#[test]
fn two_distant_identical_defects_give_two_modes() {
    let (n, light) = (2001, 0.5);
    let mut spec = ChainSpec::uniform(n, 1.0, 1.0);
    spec.masses[500] = light;
    spec.masses[1500] = light;
    let chain = LinearChain::new(spec).unwrap();
    let above = [Interval {
        lower: 2.0,
        upper: 4.0,
    }];
    let modes = localised_modes(&chain, &above).unwrap();
    assert_eq!(modes.len(), 2);
    let expected = (4.0 / (light * (2.0 - light))).sqrt();
    let masses = chain.dof_masses();
    let dot: f64 = (0..n)
        .map(|i| masses[i] * modes[0].shape[i] * modes[1].shape[i])
        .sum();
    assert!(dot.abs() < 1e-8, "{dot}");
    let mut peaks = Vec::new();
    for mode in &modes {
        assert!(close(mode.omega, expected, 1e-12));
        // One mode per defect, each with the single defect's decay length.
        assert!(close(mode.localisation.length, 1.0 / 3f64.ln(), 1e-8));
        peaks.push(mode.localisation.peak_site);
    }
    peaks.sort_unstable();
    assert_eq!(peaks, [500, 1500]);
}

/// A mass-in-mass host (m1, resonator m2 on k2 at every site) with one resonator removed: the
/// bare site is a defect of mass m1 in a host of effective mass M(ω) = m1 + m2 k2/(k2 − m2ω²).
/// Below ω0, M > m1 and the mode is u_n = (−x)^{|n|}, x = m1/(2M − m1),
/// ω² = 4KM/(m1(2M − m1)); above ω0, M < 0 and u_n = x^{|n|}, x = m1/(m1 − 2M),
/// ω² = 2K(1 − x)/m1.
#[test]
fn a_missing_resonator_in_a_mass_in_mass_host() {
    let (n, centre, m1, m2, k2, k) = (401, 200, 1.0, 0.8, 1.0, 1.0);
    let mut spec = ChainSpec::uniform(n, m1, k);
    spec.resonators = (0..n)
        .filter(|&s| s != centre)
        .map(|s| resonator(s, m2, k2))
        .collect();
    let chain = LinearChain::new(spec).unwrap();
    let host = Cell::new(vec![m1], vec![k], vec![resonator(0, m2, k2)]).unwrap();
    let gaps = host.gaps().unwrap();
    let modes = localised_modes(&chain, &gaps).unwrap();
    assert!(!modes.is_empty());
    let omega0 = (k2 / m2).sqrt();
    for mode in &modes {
        let w2 = mode.omega * mode.omega;
        let big_m = m1 + m2 * k2 / (k2 - m2 * w2);
        let ratio = mode.shape[centre + 1] / mode.shape[centre];
        if mode.omega < omega0 {
            let x = m1 / (2.0 * big_m - m1);
            assert!(close(
                w2,
                4.0 * k * big_m / (m1 * (2.0 * big_m - m1)),
                1e-10
            ));
            assert!(close(ratio, -x, 1e-8), "{ratio} vs {}", -x);
        } else {
            let x = m1 / (m1 - 2.0 * big_m);
            assert!(close(w2, 2.0 * k * (1.0 - x) / m1, 1e-10));
            assert!(close(ratio, x, 1e-8), "{ratio} vs {x}");
        }
        assert_eq!(mode.localisation.peak_site, centre);
    }
}

#[test]
fn refuses_bad_windows_and_band_windows() {
    let chain = LinearChain::new(ChainSpec::uniform(1000, 1.0, 1.0)).unwrap();
    let bad = [Interval {
        lower: 1.0,
        upper: 0.5,
    }];
    assert!(matches!(
        localised_modes(&chain, &bad),
        Err(SpectrumError::BadWindow { .. })
    ));
    let band = [Interval {
        lower: 0.5,
        upper: 1.5,
    }];
    assert!(matches!(
        localised_modes(&chain, &band),
        Err(SpectrumError::TooManyModes {
            limit: MAX_LOCALISED,
            ..
        })
    ));
    assert_eq!(count_below(&chain, 3.0), 1000);
    assert_eq!(count_below(&chain, 0.0), 0);
}
