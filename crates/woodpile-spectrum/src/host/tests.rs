//! Cells found and refused, leads and regions read off chains built by hand.

use super::*;
use crate::chain::ChainSpec;

fn resonator(site: usize) -> LinearResonator {
    LinearResonator {
        site,
        mass: 0.4,
        stiffness: 0.9,
        damping: 0.0,
    }
}

/// A uniform chain of `n` sites (mass 1.5, bonds 2) with resonators on `hosts`.
fn chain_with(n: usize, hosts: &[usize]) -> LinearChain {
    LinearChain::new(ChainSpec {
        resonators: hosts.iter().map(|&s| resonator(s)).collect(),
        ..ChainSpec::uniform(n, 1.5, 2.0)
    })
    .unwrap()
}

#[test]
fn a_uniform_chain_is_its_own_one_site_cell_and_scatters_nothing() {
    let chain = chain_with(12, &[]);
    let host = detect_cell(&chain, 0).unwrap();
    assert_eq!((host.sites, host.periodic), (0..1, true));
    let s = scatterer(&chain, 0).unwrap();
    assert_eq!((s.lead.mass(), s.lead.stiffness()), (1.5, 2.0));
    assert_eq!(s.region.n_sites(), 1);
}

#[test]
fn the_shortest_period_is_found_with_its_resonators() {
    // A resonator on every third site: period 3, starting at site 0.
    let hosts: Vec<usize> = (0..15).filter(|s| s % 3 == 1).collect();
    let host = detect_cell(&chain_with(15, &hosts), 0).unwrap();
    assert_eq!((host.sites, host.periodic), (0..3, true));
    assert_eq!((host.cell.n_sites(), host.cell.n_dof()), (3, 4));
}

#[test]
fn a_chain_with_a_defect_falls_back_on_its_lead_and_scatters_from_the_defect() {
    let chain = chain_with(20, &[8, 11]);
    let host = detect_cell(&chain, 0).unwrap();
    assert!(!host.periodic);
    assert_eq!(host.cell.n_dof(), 1);
    let s = scatterer(&chain, 0).unwrap();
    assert_eq!(s.sites, 8..12);
    assert_eq!(s.region.resonators().len(), 2);
    assert_eq!(s.region.stiffness(0), 2.0);
}

#[test]
fn a_changed_bond_is_part_of_the_region() {
    let mut spec = ChainSpec::uniform(10, 1.0, 1.0);
    spec.bond_stiffness[5] = 3.0;
    let s = scatterer(&LinearChain::new(spec).unwrap(), 0).unwrap();
    assert_eq!(s.sites, 4..6);
}

#[test]
fn a_cell_that_does_not_repeat_names_the_site_that_breaks_it() {
    let chain = chain_with(12, &[1, 3, 5, 8]);
    let err = cell_of(&chain, 0..2, 0).unwrap_err().to_string();
    assert!(err.contains("site 7 differs from site 5"), "{err}");
    let err = cell_of(&chain, 0..7, 0).unwrap_err().to_string();
    assert!(err.contains("two copies"), "{err}");
}

#[test]
fn a_resonator_on_the_first_site_or_a_defect_at_the_end_leaves_no_lead() {
    let err = scatterer(&chain_with(8, &[0]), 0).unwrap_err().to_string();
    assert!(
        err.contains("its first site, 0, carries a resonator"),
        "{err}"
    );
    let err = scatterer(&chain_with(8, &[7]), 0).unwrap_err().to_string();
    assert!(err.contains("reach the chain's end"), "{err}");
    let mut spec = ChainSpec::uniform(8, 1.0, 1.0);
    spec.ground_damping = vec![0.1; 8];
    let err = scatterer(&LinearChain::new(spec).unwrap(), 0)
        .unwrap_err()
        .to_string();
    assert!(err.contains("ground damping"), "{err}");
}

#[test]
fn a_periodic_cell_starting_at_site_0_takes_its_first_bond_from_inside_the_chain() {
    // Walls of a different stiffness must not enter the cell.
    let mut spec = ChainSpec::uniform(6, 1.0, 2.0);
    spec.bond_stiffness[0] = 7.0;
    spec.bond_stiffness[6] = 7.0;
    let host = detect_cell(&LinearChain::new(spec).unwrap(), 0).unwrap();
    let top = host.cell.pass_bands().unwrap()[0].upper;
    assert!((top - 2.0 * 2.0_f64.sqrt()).abs() < 1e-12, "{top}");
}
