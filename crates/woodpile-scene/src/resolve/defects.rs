//! `[[defect]]`: the resonators. Dimensionless scenes give eps and kappa; SI scenes give the
//! host and resonator masses and the spring, or the defect rod's geometry, whose first bending
//! mode sets them (woodpile_sim::rods).

use std::collections::HashMap;

use woodpile_sim::model::{Coupling, Resonator};
use woodpile_sim::rods;

use super::chain::{Layout, Sites};
use super::check::{
    finite, invalid, non_negative, number, only_keys, positive, reject_present, required, Invalid,
};
use super::physical::{rod_resonator, Si};
use super::DerivedDefect;
use crate::raw;

/// The resonators of `defects`, with the host masses SI defects set in `sites`, and what each
/// SI defect derived.
pub(crate) fn resonators(
    defects: &[raw::Defect],
    layout: &Layout,
    si: Option<&Si>,
    sites: &mut Sites,
) -> Result<(Vec<Resonator>, Vec<DerivedDefect>), Invalid> {
    let n_sites = layout.n_sites();
    if defects.len() > n_sites.min(crate::MAX_DEFECTS) {
        return Err(invalid(
            "defect",
            format!(
                "{} defects on a chain of {n_sites} sites: at most one resonator per site, and at most {} in a scene",
                defects.len(),
                crate::MAX_DEFECTS
            ),
        ));
    }
    let mut resonators = Vec::with_capacity(defects.len());
    let mut derived = Vec::new();
    let mut taken = HashMap::new();
    for (i, d) in defects.iter().enumerate() {
        let key = |k: &str| format!("defect[{i}].{k}");
        let site_paper = required(&key("site"), d.site)?;
        let site = layout.index(&key("site"), site_paper)?;
        if let Some(first) = taken.insert(site_paper, i) {
            return Err(invalid(
                key("site"),
                format!(
                    "site {site_paper} already has defect[{first}]: at most one resonator per site"
                ),
            ));
        }
        let p = d.p.unwrap_or(1);
        if !(p == 1 || (p >= 3 && p % 2 == 1 && p <= 99)) {
            return Err(invalid(
                key("p"),
                format!("must be 1 or an odd integer from 3 to 99, got {p}"),
            ));
        }
        let p = p as u32;
        let (eps, coupling) = match si {
            None => dimensionless(&key, d)?,
            Some(si) => {
                let found = physical(&SiDefect {
                    key: &key,
                    d,
                    p,
                    si,
                    site: site_paper,
                })?;
                if found.host_mass_kg.is_some() || d.mass.is_some() {
                    sites.mass_from_defect[site] = Some(i);
                }
                sites.masses[site] = found.host_mass_ratio;
                if let Some(a) = found.contact_ratio {
                    // The defect rod's own contacts with its two neighbours.
                    sites.set_contact(site, a);
                    sites.set_contact(site + 1, a);
                }
                derived.push(found);
                (found.eps, Coupling::Constant(found.kappa))
            }
        };
        resonators.push(Resonator {
            site,
            eps,
            coupling,
            p,
        });
    }
    Ok((resonators, derived))
}

fn dimensionless(
    key: &dyn Fn(&str) -> String,
    d: &raw::Defect,
) -> Result<(f64, Coupling), Invalid> {
    reject_present(
        key,
        &[
            ("mass", d.mass.is_some()),
            ("resonator_mass", d.resonator_mass.is_some()),
            ("stiffness", d.stiffness.is_some()),
            ("rod", d.rod.is_some()),
            ("resonator_share", d.resonator_share.is_some()),
        ],
        "is only allowed in a scene with a [physical] table",
    )?;
    let eps = positive(&key("eps"), required(&key("eps"), d.eps)?)?;
    let coupling = match &d.kappa {
        None => Coupling::Constant(1.0),
        Some(v) => coupling(&key("kappa"), v)?,
    };
    Ok((eps, coupling))
}

/// One defect of a [physical] scene being resolved: the keys of its messages, its table, its
/// exponent, the scene's scales and its paper site.
struct SiDefect<'a> {
    key: &'a dyn Fn(&str) -> String,
    d: &'a raw::Defect,
    p: u32,
    si: &'a Si,
    site: i64,
}

/// A defect of a [physical] scene: what it derives (its eps and kappa, its host mass, its own
/// contact when its rod differs from the regular one), as the JSON lists it.
fn physical(x: &SiDefect<'_>) -> Result<DerivedDefect, Invalid> {
    let SiDefect { key, d, .. } = *x;
    reject_present(
        key,
        &[("eps", d.eps.is_some()), ("kappa", d.kappa.is_some())],
        "is derived in a [physical] scene: give resonator_mass (kg) and stiffness (N/m^p), or rod",
    )?;
    match &d.rod {
        None => physical_masses(x),
        Some(rod) => physical_rod(x, rod),
    }
}

/// A defect of a [physical] scene given by its resonator's mass and stiffness.
fn physical_masses(x: &SiDefect<'_>) -> Result<DerivedDefect, Invalid> {
    let (key, d, sc) = (x.key, x.d, x.si.scales);
    if d.resonator_share.is_some() {
        return Err(invalid(key("resonator_share"), "needs rod = { length }"));
    }
    let m = positive(
        &key("resonator_mass"),
        d.resonator_mass
            .ok_or_else(|| invalid(key("resonator_mass"), "is required in a [physical] scene"))?,
    )?;
    let k = non_negative(
        &key("stiffness"),
        d.stiffness
            .ok_or_else(|| invalid(key("stiffness"), "is required in a [physical] scene"))?,
    )?;
    let host = positive(&key("mass"), d.mass.unwrap_or(sc.mass_kg))?;
    let (eps, kappa) = (sc.mass_ratio(m), sc.kappa(k, x.p));
    let host_mass_ratio = sc.mass_ratio(host);
    Ok(DerivedDefect {
        site: x.site,
        host_mass_ratio,
        eps,
        kappa,
        ..DerivedDefect::default()
    })
}

/// A defect of a [physical] scene whose resonator is its rod's bending mode.
fn physical_rod(x: &SiDefect<'_>, rod: &raw::DefectRod) -> Result<DerivedDefect, Invalid> {
    let SiDefect {
        key,
        d,
        p,
        si,
        site,
    } = *x;
    let sc = si.scales;
    reject_present(
        key,
        &[
            ("mass", d.mass.is_some()),
            ("resonator_mass", d.resonator_mass.is_some()),
            ("stiffness", d.stiffness.is_some()),
        ],
        "is derived from the defect's rod: give one or the other",
    )?;
    if p != 1 {
        return Err(invalid(
            key("p"),
            "a rod's bending mode is a linear resonator: p must be 1 with rod",
        ));
    }
    let found = rod_resonator(key, rod, d.resonator_share, si.rod.as_ref())?;
    let (eps, kappa) = (
        sc.mass_ratio(found.resonator_kg),
        sc.kappa(found.stiffness, 1),
    );
    let host_mass_ratio = sc.mass_ratio(found.host_kg);
    let own_contact = (rod.diameter.is_some() || rod.material.is_some())
        .then_some(si.rod.as_ref())
        .flatten()
        .map(|regular| rods::crossed_rods_coefficient(&found.rod, regular) / sc.hertz);
    Ok(DerivedDefect {
        site,
        host_mass_ratio,
        eps,
        kappa,
        host_mass_kg: Some(found.host_kg),
        resonator_mass_kg: Some(found.resonator_kg),
        stiffness_n_per_m: Some(found.stiffness),
        bending_f1_hz: Some(found.f1_hz),
        contact_ratio: own_contact,
    })
}

fn coupling(key: &str, value: &toml::Value) -> Result<Coupling, Invalid> {
    match value {
        toml::Value::Table(t) => {
            only_keys(
                key,
                t,
                &["k1", "k2", "t0", "tau"],
                "a ramp has k1, k2, t0, tau",
            )?;
            let get = |k: &str| -> Result<f64, Invalid> {
                let full = format!("{key}.{k}");
                let v = t
                    .get(k)
                    .ok_or_else(|| invalid(&full, "is required in a ramp { k1, k2, t0, tau }"))?;
                number(&full, v)
            };
            Ok(Coupling::Ramp {
                k1: non_negative(&format!("{key}.k1"), get("k1")?)?,
                k2: non_negative(&format!("{key}.k2"), get("k2")?)?,
                t0: finite(&format!("{key}.t0"), get("t0")?)?,
                tau: positive(&format!("{key}.tau"), get("tau")?)?,
            })
        }
        v => Ok(Coupling::Constant(non_negative(key, number(key, v)?)?)),
    }
}
