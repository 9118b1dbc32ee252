//! The audit's scenes beyond the plain ones ([`super::audit_scene`]): the experiment's chain,
//! a chain standing in gravity, a chain with gaps between its beads, and chains that lose
//! energy, with every kind of damping or with the linear losses alone.

use super::{audit_scene, linear_audit_scene, Lcg};
use crate::energy::Region;
use crate::model::{Boundary, Coupling, Model, Resonator};
use crate::simulation::Scenario;

/// One scene of the audit of the experiment's chain (`auto_audit --chain`): an audit scene
/// ([`audit_scene`]) given, with further draws, every feature of a [`crate::ContactLaw`] and a
/// striker: an exponent from 1 to 3, a repeated pattern of two masses (ratio 0.3 to 3) and two
/// contact coefficients (0.5 to 2), wall contacts (0.5 to 2), and either a precompression
/// (F0 from 1e-3 to 0.5, on a walled chain) or, on a third of the rest, a striker (mass 0.3 to
/// 10, contact 0.5 to 2) at a free left end in place of the impulse.
pub fn chain_audit_scene(rng: &mut Lcg) -> Scenario {
    let base = audit_scene(rng);
    let exponent = 1.0 + 2.0 * rng.uniform();
    let masses = [1.0, rng.log_uniform(0.3, 3.0)];
    let contacts = [rng.log_uniform(0.5, 2.0), rng.log_uniform(0.5, 2.0)];
    let wall = rng.log_uniform(0.5, 2.0);
    let precompress = rng.uniform() < 0.5;
    let f0 = rng.log_uniform(1e-3, 0.5);
    let strike = !precompress && rng.uniform() < 1.0 / 3.0;
    let (striker_mass, striker_contact) = (rng.log_uniform(0.3, 10.0), rng.log_uniform(0.5, 2.0));

    let old = &base.model;
    let shift = usize::from(strike);
    let n_sites = old.n_sites() + shift;
    let boundary = match (strike, precompress) {
        (true, _) => Boundary::ends(crate::End::Free, old.boundary().right()),
        (false, true) => Boundary::Fixed,
        (false, false) => old.boundary(),
    };
    let mut site_masses: Vec<f64> = (0..n_sites).map(|i| masses[i % 2]).collect();
    let mut coefficients: Vec<f64> = (0..=n_sites).map(|b| contacts[b % 2]).collect();
    (coefficients[0], coefficients[n_sites]) = (wall, wall);
    if strike {
        site_masses[0] = striker_mass;
        coefficients[1] = striker_contact;
    }
    let resonators = old
        .resonators()
        .iter()
        .map(|r| Resonator {
            site: r.site + shift,
            ..*r
        })
        .collect();
    let law = crate::ContactLaw::new(coefficients, exponent, if precompress { f0 } else { 0.0 })
        .expect("a valid survey contact law");
    let model = Model::with_masses(n_sites, boundary, resonators, Some(site_masses))
        .and_then(|m| m.with_contacts(law))
        .expect("a valid survey model");
    let region = Region::new(
        (base.region.lo() + shift) as i64,
        (base.region.hi() + shift) as i64,
        n_sites,
    )
    .expect("a valid survey region");
    Scenario {
        model,
        impulse_site: if strike { 0 } else { base.impulse_site },
        region: if strike {
            region
                .with_striker()
                .expect("a region right of the striker")
        } else {
            region
        },
        ..base
    }
}

/// One scene of the audit of gravity (`auto_audit --gravity`): a linear audit scene
/// ([`linear_audit_scene`]) stood upright, top (left) end free and bottom (right) end fixed,
/// in gravity g from 1e-4 to 0.3 (a weight per site from far below to about half of a
/// unit-velocity solitary wave's peak contact force), every contact carrying the weight above
/// it; half the time a dimer of masses 1 and up to 3 with alternating contact coefficients.
pub fn gravity_audit_scene(rng: &mut Lcg) -> Scenario {
    let base = linear_audit_scene(rng);
    let g = rng.log_uniform(1e-4, 0.3);
    let dimer = rng.uniform() < 0.5;
    let (heavy, contact) = (rng.log_uniform(1.0, 3.0), rng.log_uniform(0.5, 2.0));
    let n_sites = base.model.n_sites();
    let site_masses: Vec<f64> = (0..n_sites)
        .map(|i| if dimer && i % 2 == 1 { heavy } else { 1.0 })
        .collect();
    let coefficients: Vec<f64> = (0..=n_sites)
        .map(|b| if dimer && b % 2 == 1 { contact } else { 1.0 })
        .collect();
    let resonators = base.model.resonators().to_vec();
    let mut carried = site_masses.clone();
    for r in &resonators {
        carried[r.site] += r.eps;
    }
    let law = crate::ContactLaw::under_gravity(coefficients, 1.5, &carried, g)
        .expect("a valid survey contact law");
    let boundary = Boundary::ends(crate::End::Free, crate::End::Fixed);
    let model = Model::with_masses(n_sites, boundary, resonators, Some(site_masses))
        .and_then(|m| m.with_contacts(law))
        .expect("a valid survey model");
    Scenario { model, ..base }
}

/// One scene of the audit of gapped contacts (`auto_audit --gap`): an audit scene
/// ([`audit_scene`]) whose contacts are one-sided linear springs across gaps
/// ([`crate::contact::LinearGap`]): stiffness from 0.5 to 2 and gap from 1e-3 to 0.3, each
/// drawn once for the inner contacts and once for the walls.
pub fn gap_audit_scene(rng: &mut Lcg) -> Scenario {
    let base = audit_scene(rng);
    let (inner, wall) = (rng.log_uniform(0.5, 2.0), rng.log_uniform(0.5, 2.0));
    let (inner_gap, wall_gap) = (rng.log_uniform(1e-3, 0.3), rng.log_uniform(1e-3, 0.3));
    let n_sites = base.model.n_sites();
    let at_wall = |b: usize| b == 0 || b == n_sites;
    let bonds = 0..=n_sites;
    let stiffness = bonds.clone().map(|b| if at_wall(b) { wall } else { inner });
    let gap = bonds.map(|b| if at_wall(b) { wall_gap } else { inner_gap });
    let law = crate::contact::LinearGap::new(stiffness.collect(), gap.collect())
        .expect("a valid survey contact law");
    let model = base
        .model
        .clone()
        .with_law(law)
        .expect("a valid survey model");
    Scenario { model, ..base }
}

/// One scene of the audit of losses `auto` splits from its step (`auto_audit --linear-losses`):
/// a damped audit scene ([`damped_audit_scene`]) without its contact dashpot, so that every
/// loss acts on velocities alone: ground damping, resonator dashpots and soft ends. Those
/// slow enough run `rkn6-split`, the others `rk4-contact`.
pub fn linear_losses_audit_scene(rng: &mut Lcg) -> Scenario {
    let scene = damped_audit_scene(rng);
    let old = &scene.model;
    let d = old.damping().expect("a damped audit scene has damping");
    let damping =
        crate::Damping::new(0.0, d.law, d.ground, d.resonator.clone()).expect("valid damping");
    let n = old.n_sites();
    let masses = (0..n).map(|i| old.site_mass(i)).collect();
    let model = Model::with_masses(n, old.boundary(), old.resonators().to_vec(), Some(masses))
        .and_then(|m| m.with_law(old.law().clone()))
        .expect("a valid survey model");
    Scenario {
        model: model.with_damping(damping).expect("a valid damped model"),
        ..scene
    }
}

/// One scene of the audit of dissipation (`auto_audit --damped`): an audit scene, or half the
/// time one of the experiment's chain ([`chain_audit_scene`]), given every kind of damping a
/// scene can declare: a contact dashpot (γ from 1e-4 to 0.3, linear or Hertzian law, equally
/// likely), on half the scenes ground damping (g from 1e-4 to 1e-2), on each resonator with
/// probability one half a dashpot (c from 1e-3 to 1), and on half the chains with a free right
/// end a soft end there (spring up to 0.1, dashpot from 0.05 to 2). A resonator the base
/// scene ramps is held at its final κ: a scene file refuses a ramp with losses, whose work
/// the ledger has no place for.
pub fn damped_audit_scene(rng: &mut Lcg) -> Scenario {
    let base = match rng.uniform() < 0.5 {
        true => chain_audit_scene(rng),
        false => audit_scene(rng),
    };
    let law = match rng.uniform() < 0.5 {
        true => crate::DashpotLaw::Linear,
        false => crate::DashpotLaw::Hertzian,
    };
    let contact = rng.log_uniform(1e-4, 0.3);
    let ground = match rng.uniform() < 0.5 {
        true => rng.log_uniform(1e-4, 1e-2),
        false => 0.0,
    };
    let old = &base.model;
    let resonator: Vec<f64> = old
        .resonators()
        .iter()
        .map(|_| match rng.uniform() < 0.5 {
            true => rng.log_uniform(1e-3, 1.0),
            false => 0.0,
        })
        .collect();
    let soft = crate::End::Soft {
        spring: 0.1 * rng.uniform(),
        damping: rng.log_uniform(0.05, 2.0),
    };
    let boundary = match (old.boundary().right(), rng.uniform() < 0.5) {
        (crate::End::Free, true) => Boundary::ends(old.boundary().left(), soft),
        _ => old.boundary(),
    };
    let n = old.n_sites();
    let masses = (0..n).map(|i| old.site_mass(i)).collect();
    let resonators = old
        .resonators()
        .iter()
        .map(|r| Resonator {
            coupling: Coupling::Constant(r.coupling.at(f64::INFINITY)),
            ..*r
        })
        .collect();
    let model = Model::with_masses(n, boundary, resonators, Some(masses))
        .and_then(|m| m.with_law(old.law().clone()))
        .expect("a valid survey model");
    let damping = crate::Damping::new(contact, law, ground, resonator).expect("valid damping");
    Scenario {
        model: model.with_damping(damping).expect("a valid damped model"),
        ..base
    }
}
