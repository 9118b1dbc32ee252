//! Known answers: the uniform chain between walls and with free ends, and the light-mass defect
//! (Montroll–Potts) with its exponentially localised mode.

use super::*;
use crate::chain::{ChainSpec, LinearResonator};
use std::f64::consts::PI;

fn close(got: f64, expected: f64, tol: f64) -> bool {
    (got - expected).abs() <= tol * expected.abs()
}

#[test]
fn uniform_chain_between_walls() {
    let (n, m, k) = (40, 1.3, 0.7);
    let chain = LinearChain::new(ChainSpec::uniform(n, m, k)).unwrap();
    let modes = normal_modes(&chain).unwrap();
    assert_eq!(modes.len(), n);
    let n1 = (n + 1) as f64;
    for (j, mode) in modes.iter().enumerate() {
        let kk = (j + 1) as f64;
        let expected = 2.0 * (k / m).sqrt() * (kk * PI / (2.0 * n1)).sin();
        assert!(
            close(mode.omega, expected, 1e-10),
            "mode {j}: {} vs {expected}",
            mode.omega
        );
        // v_n = ±sqrt(2 / (m (N + 1))) sin(k n π / (N + 1)), n = 1..N.
        let amplitude = (2.0 / (m * n1)).sqrt();
        let sign = mode.shape[0].signum() / (kk * PI / n1).sin().signum();
        for (site, &v) in mode.shape.iter().enumerate() {
            let expected = sign * amplitude * (kk * (site + 1) as f64 * PI / n1).sin();
            assert!((v - expected).abs() < 1e-10, "mode {j} site {site}");
        }
    }
}

#[test]
fn uniform_chain_with_free_ends() {
    let (n, m, k) = (25, 2.0, 3.0);
    let mut spec = ChainSpec::uniform(n, m, k);
    spec.bond_stiffness[0] = 0.0;
    spec.bond_stiffness[n] = 0.0;
    let modes = normal_modes(&LinearChain::new(spec).unwrap()).unwrap();
    assert!(modes[0].omega < 1e-7);
    for (j, mode) in modes.iter().enumerate().skip(1) {
        let expected = 2.0 * (k / m).sqrt() * (j as f64 * PI / (2.0 * n as f64)).sin();
        assert!(close(mode.omega, expected, 1e-10), "mode {j}");
    }
}

/// A light mass m' < m at the centre of a chain of masses m: above the cutoff a mode
/// u_n = (−x)^{|n|} with x = m'/(2m − m'), ω² = 4Km / (m'(2m − m')) (Montroll–Potts).
#[test]
fn light_mass_defect_is_localised() {
    let (n, m, k, light) = (81, 1.0, 1.0, 0.5);
    let mut spec = ChainSpec::uniform(n, m, k);
    spec.masses[40] = light;
    let modes = normal_modes(&LinearChain::new(spec).unwrap()).unwrap();
    let top = &modes[n - 1];
    let expected = (4.0 * k * m / (light * (2.0 * m - light))).sqrt();
    assert!(
        close(top.omega, expected, 1e-10),
        "{} vs {expected}",
        top.omega
    );
    assert!(top.omega > 2.0 * (k / m).sqrt());
    let x = light / (2.0 * m - light);
    assert_eq!(top.localisation.peak_site, 40);
    assert!(close(top.localisation.length, -1.0 / x.ln(), 1e-10));
    for offset in 1..8 {
        let ratio = top.shape[40 + offset] / top.shape[40];
        assert!(
            close(ratio, (-x).powi(offset as i32), 1e-9),
            "offset {offset}"
        );
    }
    // Every other mode lies in the host band.
    assert!(modes[..n - 1].iter().all(|mode| mode.omega < 2.0));
    let gap = [Interval {
        lower: 2.0,
        upper: 10.0,
    }];
    assert_eq!(modes.iter().filter(|mode| mode.in_any(&gap)).count(), 1);
}

#[test]
fn resonator_shapes_are_mass_normalised() {
    // Two sites between walls with one resonator: check v^T M v = 1 and K v = ω² M v.
    let mut spec = ChainSpec::uniform(2, 1.0, 1.0);
    spec.resonators.push(LinearResonator {
        site: 0,
        mass: 0.3,
        stiffness: 0.9,
        damping: 0.0,
    });
    let chain = LinearChain::new(spec).unwrap();
    let k = matrices::stiffness(&chain);
    let masses = chain.dof_masses();
    for mode in normal_modes(&chain).unwrap() {
        let norm: f64 = mode.shape.iter().zip(&masses).map(|(v, m)| m * v * v).sum();
        assert!((norm - 1.0).abs() < 1e-12);
        for i in 0..3 {
            let kv: f64 = (0..3).map(|j| k[(i, j)] * mode.shape[j]).sum();
            let mv = mode.omega * mode.omega * masses[i] * mode.shape[i];
            assert!((kv - mv).abs() < 1e-12, "row {i}");
        }
    }
}

#[test]
fn refuses_dense_problems_beyond_the_limit() {
    let chain = LinearChain::new(ChainSpec::uniform(MAX_DENSE_ORDER + 1, 1.0, 1.0)).unwrap();
    assert_eq!(
        normal_modes(&chain),
        Err(SpectrumError::TooLargeForDense {
            order: MAX_DENSE_ORDER + 1,
            limit: MAX_DENSE_ORDER
        })
    );
}

#[test]
fn distant_identical_defects_give_one_mode_each() {
    // Splitting ~ 3^{-300}: degenerate to rounding, so the eigensolver's basis is arbitrary
    // until rotated.
    let (n, light) = (401, 0.5);
    let mut spec = ChainSpec::uniform(n, 1.0, 1.0);
    spec.masses[50] = light;
    spec.masses[350] = light;
    let modes = normal_modes(&LinearChain::new(spec).unwrap()).unwrap();
    let mut peaks: Vec<usize> = modes[n - 2..]
        .iter()
        .map(|mode| {
            assert!(close(mode.localisation.length, 1.0 / 3f64.ln(), 1e-8));
            mode.localisation.peak_site
        })
        .collect();
    peaks.sort_unstable();
    assert_eq!(peaks, [50, 350]);
}
