//! Known answers: one-site defects (mass, resonator, damped resonator) in closed form
//! t = 1 / (1 − iβ), β = Δm ω² / (2K sin q), r = t − 1; energy balance; the decay of t through
//! a long region in its gap.

use super::*;
use crate::bands::Cell;
use crate::chain::{ChainSpec, LinearResonator};

fn resonator(site: usize, mass: f64, stiffness: f64, damping: f64) -> LinearResonator {
    LinearResonator {
        site,
        mass,
        stiffness,
        damping,
    }
}

/// Frequencies spread over the open band (0, cutoff).
fn band(lead: &Lead, count: usize) -> Vec<f64> {
    (1..=count)
        .map(|i| lead.cutoff() * i as f64 / (count + 1) as f64)
        .collect()
}

/// The closed form for one site of extra mass Δm(ω) between the leads.
fn one_site(lead: &Lead, omega: f64, extra: c64) -> (c64, c64) {
    let q = lead.wavenumber(omega).unwrap();
    let beta = extra * omega * omega / (2.0 * lead.stiffness * q.sin());
    let t = c64::new(1.0, 0.0) / (c64::new(1.0, 0.0) - c64::new(0.0, 1.0) * beta);
    (t, t - 1.0)
}

#[test]
fn the_host_itself_transmits_everything() {
    let lead = Lead::new(1.3, 0.8).unwrap();
    let region = LinearChain::new(ChainSpec::uniform(57, 1.3, 0.8)).unwrap();
    for s in scatter(&lead, &region, &band(&lead, 50)).unwrap() {
        assert!((s.transmission - 1.0).norm() < 1e-11, "ω {}", s.omega);
        assert!(s.reflection.norm() < 1e-11);
    }
}

#[test]
fn a_mass_defect() {
    let lead = Lead::new(1.0, 2.0).unwrap();
    let mut spec = ChainSpec::uniform(1, 1.0, 2.0);
    spec.masses[0] = 2.7;
    let region = LinearChain::new(spec).unwrap();
    for s in scatter(&lead, &region, &band(&lead, 40)).unwrap() {
        let (t, r) = one_site(&lead, s.omega, c64::new(1.7, 0.0));
        assert!(
            (s.transmission - t).norm() < 1e-10 * t.norm(),
            "ω {}",
            s.omega
        );
        assert!((s.reflection - r).norm() < 1e-10);
        let beta = 1.7 * s.omega.powi(2) / (2.0 * 2.0 * lead.wavenumber(s.omega).unwrap().sin());
        assert!((s.transmittance() - 1.0 / (1.0 + beta * beta)).abs() < 1e-10);
    }
}

/// Δm = m2 ω0² / (ω0² − ω²): |t|² = 1 / (1 + β²), exactly zero at ω0.
#[test]
fn a_resonator_defect_and_its_zero() {
    let lead = Lead::new(1.0, 2.0).unwrap();
    let (m2, k2): (f64, f64) = (0.5, 2.0);
    let omega0 = (k2 / m2).sqrt();
    let mut spec = ChainSpec::uniform(1, 1.0, 2.0);
    spec.resonators.push(resonator(0, m2, k2, 0.0));
    let region = LinearChain::new(spec).unwrap();
    let mut omegas = band(&lead, 60);
    omegas.retain(|&w| (w - omega0).abs() > 1e-6);
    for s in scatter(&lead, &region, &omegas).unwrap() {
        let extra = m2 * omega0 * omega0 / (omega0 * omega0 - s.omega * s.omega);
        let (t, r) = one_site(&lead, s.omega, c64::new(extra, 0.0));
        assert!(
            (s.transmission - t).norm() < 1e-10 * t.norm().max(1e-3),
            "ω {}",
            s.omega
        );
        assert!((s.reflection - r).norm() < 1e-10);
        assert!(s.absorbance().abs() < 1e-12);
    }
    let at = scatter(&lead, &region, &[omega0]).unwrap()[0];
    assert_eq!(at.transmission, c64::new(0.0, 0.0));
    assert_eq!(at.log_transmission, f64::NEG_INFINITY);
    assert!((at.reflection + 1.0).norm() < 1e-12);
}

/// With a dashpot the same closed form holds with the complex Δm = m2 k~/(k~ − m2 ω²),
/// k~ = k2 − iωc2, and the difference 1 − |r|² − |t|² is absorbed.
#[test]
fn a_damped_resonator_absorbs() {
    let lead = Lead::new(1.0, 2.0).unwrap();
    let (m2, k2, c2) = (0.5, 2.0, 0.05);
    let mut spec = ChainSpec::uniform(1, 1.0, 2.0);
    spec.resonators.push(resonator(0, m2, k2, c2));
    let region = LinearChain::new(spec).unwrap();
    for s in scatter(&lead, &region, &band(&lead, 40)).unwrap() {
        let k = c64::new(k2, -s.omega * c2);
        let extra = m2 * k / (k - m2 * s.omega * s.omega);
        let (t, r) = one_site(&lead, s.omega, extra);
        assert!(
            (s.transmission - t).norm() < 1e-10 * t.norm(),
            "ω {}",
            s.omega
        );
        assert!((s.reflection - r).norm() < 1e-10);
        assert!(s.absorbance() > 0.0);
        assert!((s.log_transmission - t.norm().ln()).abs() < 1e-10);
    }
}

#[test]
fn energy_is_conserved_without_damping() {
    let lead = Lead::new(1.0, 1.0).unwrap();
    let mut spec = ChainSpec::uniform(40, 1.0, 1.0);
    for site in 0..40 {
        spec.masses[site] = 1.0 + 0.6 * (site as f64 * 1.3).sin();
        spec.bond_stiffness[site] = 1.0 + 0.4 * (site as f64 * 0.7).cos();
    }
    spec.resonators = vec![
        resonator(5, 0.3, 0.5, 0.0),
        resonator(5, 0.2, 1.5, 0.0),
        resonator(30, 2.0, 0.2, 0.0),
    ];
    let region = LinearChain::new(spec).unwrap();
    for s in scatter(&lead, &region, &band(&lead, 300)).unwrap() {
        assert!(
            s.absorbance().abs() < 1e-10,
            "ω {}: {}",
            s.omega,
            s.absorbance()
        );
    }
}

/// Deep in a region's gap |t| falls by the cell attenuation e^{−κ} per cell: the difference of
/// ln|t| between two lengths is κ times their difference, without overflow on the way.
#[test]
fn transmission_through_a_long_region_decays_at_the_gap_rate() {
    let (m1, m2, k2, k) = (1.0, 0.8, 1.0, 1.0);
    let lead = Lead::new(m1, k).unwrap();
    let host = Cell::new(vec![m1], vec![k], vec![resonator(0, m2, k2, 0.0)]).unwrap();
    let gap = host.gaps().unwrap()[0];
    let omega = 0.5 * (gap.lower + gap.upper);
    assert!(omega < lead.cutoff());
    let kappa = host.wavenumber(omega).unwrap().attenuation;
    let log_t = |n: usize| {
        let mut spec = ChainSpec::uniform(n, m1, k);
        spec.resonators = (0..n).map(|s| resonator(s, m2, k2, 0.0)).collect();
        let region = LinearChain::new(spec).unwrap();
        let s = scatter(&lead, &region, &[omega]).unwrap()[0];
        assert!((s.reflectance() - 1.0).abs() < 1e-10);
        s.log_transmission
    };
    let (short, long) = (log_t(200), log_t(700));
    assert!(long < -1000.0, "{long}: below what f64 holds of |t| itself");
    assert!(
        ((short - long) / 500.0 - kappa).abs() < 1e-10 * kappa,
        "{short} {long} {kappa}"
    );
}

#[test]
fn refuses_frequencies_outside_the_band_and_detached_regions() {
    let lead = Lead::new(1.0, 1.0).unwrap();
    let region = LinearChain::new(ChainSpec::uniform(3, 1.0, 1.0)).unwrap();
    for omega in [0.0, 2.0, 2.5, f64::NAN] {
        assert!(matches!(
            scatter(&lead, &region, &[omega]),
            Err(SpectrumError::OutsideLeadBand { .. })
        ));
    }
    let mut spec = ChainSpec::uniform(3, 1.0, 1.0);
    spec.bond_stiffness[3] = 0.0;
    assert_eq!(
        scatter(&lead, &LinearChain::new(spec).unwrap(), &[1.0]),
        Err(SpectrumError::Detached { side: "right" })
    );
    assert!(Lead::new(0.0, 1.0).is_err());
}
