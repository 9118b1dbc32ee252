//! The whole picture against closed forms: the mass-in-mass gap, a resonator defect's
//! transmission zero, the defect mode of a light site; and the requests it refuses.

use super::*;
use crate::chain::{ChainSpec, LinearResonator};

const M1: f64 = 1.0;
const K: f64 = 1.0;
const M2: f64 = 0.5;
const K2: f64 = 0.3;

fn resonator(site: usize) -> LinearResonator {
    LinearResonator {
        site,
        mass: M2,
        stiffness: K2,
        damping: 0.0,
    }
}

#[test]
fn a_mass_in_mass_chain_has_the_closed_form_gap() {
    let chain = LinearChain::new(ChainSpec {
        resonators: (0..40).map(resonator).collect(),
        ..ChainSpec::uniform(40, M1, K)
    })
    .unwrap();
    let a = analyse(&chain, &Request::default()).unwrap();
    assert!(a.host.periodic);
    // Gap: from the acoustic branch at q = π, root of
    // (m1 ω² − 4K − k2)(m2 ω² − k2) = k2², to ω0 sqrt(1 + m2/m1).
    let (b, c) = (-(M1 * K2 + M2 * (4.0 * K + K2)), 4.0 * K * K2);
    let lower = ((-b - (b * b - 4.0 * M1 * M2 * c).sqrt()) / (2.0 * M1 * M2)).sqrt();
    let upper = (K2 / M2).sqrt() * (1.0 + M2 / M1).sqrt();
    assert_eq!(a.gaps.len(), 1);
    assert!(
        (a.gaps[0].lower - lower).abs() < 1e-10 * lower,
        "{:?}",
        a.gaps
    );
    assert!(
        (a.gaps[0].upper - upper).abs() < 1e-10 * upper,
        "{:?}",
        a.gaps
    );
    // Inside the gap the wavenumber is complex.
    let mid = 0.5 * (lower + upper);
    let inside = a
        .wavenumbers
        .iter()
        .find(|(w, _)| (w - mid).abs() < 0.01)
        .unwrap();
    assert!(inside.1.attenuation > 0.0);
    // Every resonator on site 0 leaves no lead: said, not an error.
    assert!(a.transmission.unwrap_err().contains("first site, 0,"));
    assert!(a.modes.complete && a.modes.undamped.len() == 80);
}

#[test]
fn a_resonator_defect_blocks_its_own_frequency() {
    let chain = LinearChain::new(ChainSpec {
        resonators: vec![resonator(30)],
        ..ChainSpec::uniform(60, M1, K)
    })
    .unwrap();
    let omega0 = (K2 / M2).sqrt();
    let request = Request {
        frequencies: Some(FrequencyGrid {
            lower: 0.5 * omega0,
            upper: 1.5 * omega0,
            points: 101,
        }),
        ..Request::default()
    };
    let a = analyse(&chain, &request).unwrap();
    let t = a.transmission.unwrap();
    assert_eq!(t.scatterer.sites, 30..31);
    for s in &t.scattering {
        let w = s.omega;
        let q = t.scatterer.lead.wavenumber(w).unwrap();
        let dm = M2 * omega0 * omega0 / (omega0 * omega0 - w * w);
        let closed = 1.0 / (1.0 + (dm * w * w / (2.0 * K * q.sin())).powi(2));
        assert!((s.transmittance() - closed).abs() < 1e-10, "ω {w}");
        assert!((s.transmittance() + s.reflectance() - 1.0).abs() < 1e-10);
    }
    let at_resonance = &t.scattering[50];
    assert!(at_resonance.transmittance() < 1e-20);
}

#[test]
fn a_light_site_has_one_mode_above_the_band() {
    let mut spec = ChainSpec::uniform(41, 1.0, 1.0);
    spec.masses[20] = 0.5;
    let a = analyse(&LinearChain::new(spec).unwrap(), &Request::default()).unwrap();
    let above: Vec<&Mode> = a
        .modes
        .undamped
        .iter()
        .filter(|m| m.in_any(&a.windows))
        .collect();
    assert_eq!(above.len(), 1);
    // Its tails decay as e^{−κ|n|}, κ the host's attenuation at its frequency: ξ = 1/κ.
    let mode = above[0];
    assert_eq!(mode.localisation.peak_site, 20);
    let kappa = a.host.cell.wavenumber(mode.omega).unwrap().attenuation;
    assert!((mode.localisation.length - 1.0 / kappa).abs() < 1e-6 * mode.localisation.length);
}

#[test]
fn requests_that_hold_no_frequency_or_leave_the_band_are_refused() {
    let chain = LinearChain::new(ChainSpec {
        resonators: vec![resonator(5)],
        ..ChainSpec::uniform(11, 1.0, 1.0)
    })
    .unwrap();
    let ask = |lower: f64, upper: f64, points: usize| {
        let frequencies = Some(FrequencyGrid {
            lower,
            upper,
            points,
        });
        analyse(
            &chain,
            &Request {
                frequencies,
                ..Request::default()
            },
        )
        .map(|_| ())
        .unwrap_err()
        .to_string()
    };
    assert!(ask(1.0, 0.5, 10).contains("holds no frequency"));
    assert!(ask(0.5, 1.0, 0).contains("holds no frequency"));
    assert!(ask(-0.1, 1.0, 10).contains("pass band"));
    assert!(ask(0.1, 2.5, 10).contains("pass band"));
    assert!(ask(f64::NAN, 1.0, 10).contains("finite"));
}
