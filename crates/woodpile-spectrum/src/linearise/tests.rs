//! The Hertzian stiffness of a precompressed chain in closed form, the sonic vacuum refused,
//! resonators, dashpots and soft ends carried over.

use super::*;
use woodpile_sim::DashpotLaw;
use woodpile_sim::{Boundary, ContactLaw, Coupling, Damping, Resonator};

fn close(got: f64, expected: f64) -> bool {
    (got - expected).abs() <= 1e-12 * expected.abs()
}

/// With static force F0 every contact has δ_b = (F0/a_b)^{2/3}, so
/// K_b = (3/2) a_b δ_b^{1/2} = (3/2) a_b^{2/3} F0^{1/3}.
#[test]
fn precompressed_hertz_contacts() {
    let coefficients = vec![0.7, 1.0, 2.3, 0.4, 1.1];
    let f0 = 0.8;
    let model = Model::new(4, Boundary::Fixed, vec![])
        .unwrap()
        .with_contacts(ContactLaw::new(coefficients.clone(), 1.5, f0).unwrap())
        .unwrap();
    let chain = linearise_precompressed(&model, 0.0).unwrap().chain;
    for (bond, a) in coefficients.iter().enumerate() {
        let expected = 1.5 * a.powf(2.0 / 3.0) * f0.powf(1.0 / 3.0);
        assert!(close(chain.stiffness(bond), expected), "bond {bond}");
    }
    assert!(!chain.is_damped());
}

#[test]
fn the_papers_chain_from_given_overlaps() {
    let masses = Some(vec![1.0, 2.0, 0.5]);
    let boundary = Boundary::ends(End::Free, End::Fixed);
    let model = Model::with_masses(3, boundary, vec![], masses).unwrap();
    let chain = linearise(&model, &[0.3, 0.04, 0.09, 0.16], 0.0)
        .unwrap()
        .chain;
    assert_eq!(chain.stiffness(0), 0.0);
    assert!(close(chain.stiffness(1), 1.5 * 0.2));
    assert!(close(chain.stiffness(2), 1.5 * 0.3));
    assert!(close(chain.stiffness(3), 1.5 * 0.4));
    assert_eq!(chain.mass(1), 2.0);
}

#[test]
fn a_sonic_vacuum_is_refused_with_its_reason() {
    let model = Model::new(5, Boundary::Fixed, vec![]).unwrap();
    let error = linearise_precompressed(&model, 0.0).unwrap_err();
    assert_eq!(
        error,
        SpectrumError::NoStaticLoad {
            bond: 1,
            overlap: 0.0
        }
    );
    let message = error.to_string();
    assert!(message.contains("no static load"));
    assert!(message.contains("chain.precompression") && message.contains("chain.gravity"));
    let single = Model::new(1, Boundary::Fixed, vec![]).unwrap();
    assert!(matches!(
        linearise(&single, &[0.0, 0.0], 0.0),
        Err(SpectrumError::NoStaticLoad { .. })
    ));
}

#[test]
fn resonators_dashpots_and_soft_ends() {
    let resonators = vec![
        Resonator::constant(1, 0.5, 2.0, 1),
        Resonator::constant(2, 0.3, 1.0, 3),
        Resonator {
            site: 0,
            eps: 0.2,
            coupling: Coupling::Ramp {
                k1: 0.0,
                k2: 4.0,
                t0: 10.0,
                tau: 1.0,
            },
            p: 1,
        },
    ];
    let soft = End::Soft {
        spring: 0.6,
        damping: 0.05,
    };
    let model = Model::new(3, Boundary::ends(soft, End::Free), resonators)
        .unwrap()
        .with_damping(Damping::new(0.2, DashpotLaw::Hertzian, 0.01, vec![0.1, 0.0, 0.3]).unwrap())
        .unwrap();
    let overlaps = [0.0, 0.25, 0.16, 0.0];
    let lin = linearise(&model, &overlaps, 10.0).unwrap();
    assert_eq!(lin.detached, vec![1]);
    let chain = lin.chain;
    assert_eq!((chain.stiffness(0), chain.bond_damping(0)), (0.6, 0.05));
    assert!(close(chain.stiffness(1), 1.5 * 0.5));
    assert!(close(chain.bond_damping(1), 0.2 * 0.5));
    assert!(close(chain.bond_damping(2), 0.2 * 0.4));
    assert_eq!((chain.stiffness(3), chain.bond_damping(3)), (0.0, 0.0));
    assert_eq!(chain.ground_damping(2), 0.01);
    let r = chain.resonators();
    assert_eq!(r.len(), 2);
    assert_eq!(
        (r[0].site, r[0].mass, r[0].stiffness, r[0].damping),
        (1, 0.5, 2.0, 0.1)
    );
    // The ramp is at its midpoint at t0.
    assert!(close(r[1].stiffness, 2.0));
    assert_eq!(r[1].damping, 0.3);
}

#[test]
fn refuses_bad_overlaps() {
    let model = Model::new(3, Boundary::Fixed, vec![]).unwrap();
    assert!(matches!(
        linearise(&model, &[0.1; 3], 0.0),
        Err(SpectrumError::Length { .. })
    ));
    assert!(matches!(
        linearise(&model, &[0.1, -0.1, 0.1, 0.1], 0.0),
        Err(SpectrumError::Negative { .. })
    ));
}
