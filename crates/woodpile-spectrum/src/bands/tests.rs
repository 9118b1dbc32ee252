//! Known answers: the monatomic, diatomic and mass-in-mass chains in closed form.

use super::*;
use std::f64::consts::PI;

fn close(got: f64, expected: f64, tol: f64) -> bool {
    (got - expected).abs() <= tol * expected.abs().max(1e-300) || (got - expected).abs() < 1e-14
}

fn resonator(site: usize, mass: f64, stiffness: f64) -> LinearResonator {
    LinearResonator {
        site,
        mass,
        stiffness,
        damping: 0.0,
    }
}

#[test]
fn monatomic_dispersion_and_cutoff() {
    let (m, k) = (1.7, 2.3);
    let cell = Cell::new(vec![m], vec![k], vec![]).unwrap();
    let bands = cell.bands(33).unwrap();
    for (q, omega) in bands.q.iter().zip(&bands.omega) {
        let expected = 2.0 * (k / m).sqrt() * (q / 2.0).sin().abs();
        assert!(
            close(omega[0], expected, 1e-10),
            "q {q}: {} vs {expected}",
            omega[0]
        );
    }
    let cutoff = 2.0 * (k / m).sqrt();
    let pass = cell.pass_bands().unwrap();
    assert_eq!(pass.len(), 1);
    assert!(pass[0].lower.abs() < 1e-7);
    assert!(close(pass[0].upper, cutoff, 1e-10));
    assert!(cell.gaps().unwrap().is_empty());
}

#[test]
fn diatomic_dispersion_and_gap_edges() {
    let (m1, m2, k) = (1.0, 3.0, 2.0);
    let cell = Cell::new(vec![m1, m2], vec![k, k], vec![]).unwrap();
    let s = 1.0 / m1 + 1.0 / m2;
    for i in 0..=20 {
        let q = PI * f64::from(i) / 20.0;
        let root = (s * s - 4.0 * (q / 2.0).sin().powi(2) / (m1 * m2)).sqrt();
        let omega = cell.frequencies(q).unwrap();
        assert!(
            close(omega[0], (k * (s - root)).max(0.0).sqrt(), 1e-10),
            "q {q}"
        );
        assert!(close(omega[1], (k * (s + root)).sqrt(), 1e-10), "q {q}");
    }
    let gaps = cell.gaps().unwrap();
    assert_eq!(gaps.len(), 1);
    assert!(close(gaps[0].lower, (2.0 * k / m2).sqrt(), 1e-10));
    assert!(close(gaps[0].upper, (2.0 * k / m1).sqrt(), 1e-10));
    let pass = cell.pass_bands().unwrap();
    assert!(close(pass[1].upper, (2.0 * k * s).sqrt(), 1e-10));
}

#[test]
fn equal_masses_leave_no_gap() {
    let cell = Cell::new(vec![1.0, 1.0], vec![1.0, 1.0], vec![]).unwrap();
    assert!(cell.gaps().unwrap().is_empty());
}

#[test]
fn mass_in_mass_dispersion_and_gap() {
    // (m1 ω² − 4K sin²(q/2) − k2)(m2 ω² − k2) = k2², from the two equations of motion
    // (4K s² + k2 − m1 ω²) U = k2 V and (k2 − m2 ω²) V = k2 U: the determinant is zero.
    let (m1, m2, k2, k) = (1.0, 0.5, 0.8, 1.3);
    let cell = Cell::new(vec![m1], vec![k], vec![resonator(0, m2, k2)]).unwrap();
    for i in 0..=16 {
        let q = PI * f64::from(i) / 16.0;
        let s2 = 4.0 * k * (q / 2.0).sin().powi(2);
        // m1 m2 x² − (m1 k2 + m2 k2 + m2 s2) x + s2 k2 = 0, x = ω².
        let (a, b, c) = (m1 * m2, m1 * k2 + m2 * k2 + m2 * s2, s2 * k2);
        let disc = (b * b - 4.0 * a * c).sqrt();
        let lower = 2.0 * c / (b + disc);
        let upper = (b + disc) / (2.0 * a);
        let omega = cell.frequencies(q).unwrap();
        assert!(
            close(omega[0], lower.sqrt(), 1e-10),
            "q {q}: {} vs {}",
            omega[0],
            lower.sqrt()
        );
        assert!(close(omega[1], upper.sqrt(), 1e-10), "q {q}");
    }
    let omega0 = (k2 / m2).sqrt();
    let gaps = cell.gaps().unwrap();
    assert_eq!(gaps.len(), 1);
    assert!(close(gaps[0].upper, omega0 * (1.0 + m2 / m1).sqrt(), 1e-10));
    let acoustic_top = cell.frequencies(PI).unwrap()[0];
    assert!(close(gaps[0].lower, acoustic_top, 1e-15));
    assert!(gaps[0].lower < omega0 && omega0 < gaps[0].upper);
}

#[test]
fn wavenumbers_in_bands_and_gaps() {
    // Monatomic: cos q = 1 − ω² m / (2K), beyond the cutoff q = π + iκ, cosh κ = ω² m/(2K) − 1.
    let (m, k) = (1.7, 2.3);
    let cell = Cell::new(vec![m], vec![k], vec![]).unwrap();
    let inside = cell.wavenumber(1.1).unwrap();
    assert!(close(
        inside.q,
        (1.0 - 1.1f64.powi(2) * m / (2.0 * k)).acos(),
        1e-12
    ));
    assert_eq!(inside.attenuation, 0.0);
    let above = cell.wavenumber(3.0).unwrap();
    assert_eq!(above.q, PI);
    assert!(close(
        above.attenuation,
        (9.0 * m / (2.0 * k) - 1.0).acosh(),
        1e-12
    ));

    // Diatomic: cos q = (2K − m1 ω²)(2K − m2 ω²)/(2K²) − 1, below −1 in the gap.
    let (m1, m2, k) = (1.0, 3.0, 2.0);
    let cell = Cell::new(vec![m1, m2], vec![k, k], vec![]).unwrap();
    let omega = 1.5;
    let h = (2.0 * k - m1 * omega * omega) * (2.0 * k - m2 * omega * omega) / (2.0 * k * k) - 1.0;
    assert!(h < -1.0);
    let gap = cell.wavenumber(omega).unwrap();
    assert_eq!(gap.q, PI);
    assert!(close(gap.attenuation, (-h).acosh(), 1e-12));

    // Mass-in-mass: cos q = 1 − ω² m_eff(ω)/(2K); at ω0 the host is pinned.
    let (m1, m2, k2, k) = (1.0, 0.5, 2.0, 1.3);
    let cell = Cell::new(vec![m1], vec![k], vec![resonator(0, m2, k2)]).unwrap();
    for omega in [1.8, 2.05, 2.4] {
        let m_eff = m1 + m2 * k2 / (k2 - m2 * omega * omega);
        let h = 1.0 - omega * omega * m_eff / (2.0 * k);
        let w = cell.wavenumber(omega).unwrap();
        assert!(h.abs() > 1.0, "ω {omega} should be in the gap");
        assert!(close(w.attenuation, h.abs().acosh(), 1e-12), "ω {omega}");
        assert_eq!(w.q, if h > 0.0 { 0.0 } else { PI });
    }
    assert_eq!(cell.wavenumber(2.0).unwrap().attenuation, f64::INFINITY);
}

#[test]
fn refuses_bad_cells() {
    assert_eq!(
        Cell::new(vec![], vec![], vec![]),
        Err(SpectrumError::EmptyChain)
    );
    assert!(matches!(
        Cell::new(vec![1.0], vec![1.0, 1.0], vec![]),
        Err(SpectrumError::Length { .. })
    ));
    let damped = LinearResonator {
        damping: 0.1,
        ..resonator(0, 1.0, 1.0)
    };
    assert_eq!(
        Cell::new(vec![1.0], vec![1.0], vec![damped]),
        Err(SpectrumError::DampedCell { resonator: 0 })
    );
    let cell = Cell::new(vec![1.0], vec![1.0], vec![]).unwrap();
    assert_eq!(
        cell.bands(1),
        Err(SpectrumError::TooFewWavenumbers { n_q: 1 })
    );
    assert!(cell.wavenumber(-1.0).is_err());
}

#[test]
fn stop_bands_add_the_range_above_the_top_band() {
    let (m1, m2, k) = (1.0, 3.0, 2.0);
    let cell = Cell::new(vec![m1, m2], vec![k, k], vec![]).unwrap();
    let windows = cell.stop_bands(10.0).unwrap();
    assert_eq!(windows.len(), 2);
    assert!(close(
        windows[1].lower,
        (2.0 * k * (1.0 / m1 + 1.0 / m2)).sqrt(),
        1e-10
    ));
    assert_eq!(windows[1].upper, 10.0);
    assert_eq!(cell.stop_bands(1.0).unwrap().len(), 1);
}
