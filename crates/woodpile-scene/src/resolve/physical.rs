//! `[physical]`: an SI scene's scales, from the regular site's mass and contact or from the
//! regular rods' material and geometry, and the SI values a defect rod or a striker derives
//! (woodpile_sim::rods).

use woodpile_sim::rods::{self, Material, Rod};
use woodpile_sim::units::Scales;

use super::check::{invalid, number_text, positive, reject_present, required, Invalid};
use crate::raw;

/// The paper's split of its 40 mm defect rod (M = 0.838 g, m = 0.894 g; Model section): the
/// share of a defect rod's mass its resonator carries when a scene gives no `resonator_share`.
pub const DEFAULT_RESONATOR_SHARE: f64 = 0.894 / (0.838 + 0.894);

/// The slenderness L/d a defect rod may have: below 3 a "rod" is a stub whose first mode is
/// no longer a beam's bending mode (Timoshenko's theory, and with it f1, then errs by more than
/// a few per cent against three-dimensional elasticity), and beyond 100 it is a wire that bends
/// under its own contacts, which a two-mass resonator of one mode cannot stand for. The paper's
/// defect rods have 8 (40 mm × 5 mm).
pub const DEFECT_ROD_SLENDERNESS: std::ops::RangeInclusive<f64> = 3.0..=100.0;

/// What `[physical]` fixes: the rescaling, and the regular rods when given by geometry.
#[derive(Debug, Clone)]
pub(crate) struct Si {
    pub scales: Scales,
    /// The regular rod, when `[physical]` gives `material` and `rod`.
    pub rod: Option<Rod>,
    /// Values derived from SI input, for the JSON's `physical` block.
    pub derived: Vec<(String, f64)>,
}

/// The scales of an SI scene, or `None` for a dimensionless one. With a striker, its velocity
/// is the velocity scale, and `physical.velocity` must be absent.
pub(crate) fn si(
    physical: Option<&raw::Physical>,
    striker: Option<&raw::Striker>,
) -> Result<Option<Si>, Invalid> {
    let Some(p) = physical else {
        return Ok(None);
    };
    let mut derived = Vec::new();
    let (mass, contact, rod) = match (&p.material, &p.rod) {
        (None, None) => (
            positive("physical.mass", required("physical.mass", p.mass)?)?,
            positive("physical.contact", required("physical.contact", p.contact)?)?,
            None,
        ),
        (Some(material), Some(rod)) => {
            let key = |k: &str| format!("physical.{k}");
            reject_present(
                &key,
                &[("mass", p.mass.is_some()), ("contact", p.contact.is_some())],
                "is derived from physical.material and physical.rod: give one or the other",
            )?;
            let rod = Rod {
                length: positive(
                    "physical.rod.length",
                    required("physical.rod.length", rod.length)?,
                )?,
                diameter: positive(
                    "physical.rod.diameter",
                    required("physical.rod.diameter", rod.diameter)?,
                )?,
                material: material_of("physical.material", material)?,
            };
            let (mass, contact) = (rod.mass(), rods::crossed_rods_coefficient(&rod, &rod));
            derived.push(("rod_mass_kg".into(), mass));
            derived.push(("contact_N_per_m1.5".into(), contact));
            if let Some(f1) = rods::free_free_bending_frequency(&rod) {
                derived.push(("rod_bending_f1_hz".into(), f1));
            }
            (mass, contact, Some(rod))
        }
        (Some(_), None) => {
            return Err(invalid(
                "physical.rod",
                "is required with physical.material",
            ))
        }
        (None, Some(_)) => {
            return Err(invalid(
                "physical.material",
                "is required with physical.rod",
            ))
        }
    };
    let velocity = match (striker, p.velocity) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                "physical.velocity",
                "is the striker's: give striker.velocity (m/s) instead",
            ))
        }
        (Some(s), None) => positive(
            "striker.velocity",
            required("striker.velocity", s.velocity)?,
        )?,
        (None, v) => positive("physical.velocity", required("physical.velocity", v)?)?,
    };
    let scales =
        Scales::new(mass, contact, velocity).map_err(|e| invalid("physical", e.to_string()))?;
    Ok(Some(Si {
        scales,
        rod,
        derived,
    }))
}

/// A material table with all three keys, each in its physical range.
pub(crate) fn material_of(key: &str, m: &raw::Material) -> Result<Material, Invalid> {
    let at = |k: &str| format!("{key}.{k}");
    let poisson = required(&at("poisson_ratio"), m.poisson_ratio)?;
    if !(poisson.is_finite() && poisson > -1.0 && poisson < 0.5) {
        return Err(invalid(
            at("poisson_ratio"),
            format!(
                "must be a number in (-1, 0.5), got {}",
                number_text(poisson)
            ),
        ));
    }
    Ok(Material {
        youngs_modulus: positive(
            &at("youngs_modulus"),
            required(&at("youngs_modulus"), m.youngs_modulus)?,
        )?,
        poisson_ratio: poisson,
        density: positive(&at("density"), required(&at("density"), m.density)?)?,
    })
}

/// A defect rod's host mass M, resonator mass m and spring K (SI), from its first free-free
/// bending mode f1: M + m is the rod's mass, m its `share`, K = (2π f1)² M m / (M + m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RodResonator {
    pub rod: Rod,
    pub host_kg: f64,
    pub resonator_kg: f64,
    pub stiffness: f64,
    pub f1_hz: f64,
}

pub(crate) fn rod_resonator(
    key: &dyn Fn(&str) -> String,
    defect_rod: &raw::DefectRod,
    share: Option<f64>,
    regular: Option<&Rod>,
) -> Result<RodResonator, Invalid> {
    let length = positive(
        &key("rod.length"),
        required(&key("rod.length"), defect_rod.length)?,
    )?;
    let needs_regular = |what: &str| {
        invalid(
            key(&format!("rod.{what}")),
            format!("is required unless [physical] gives the regular rods' {what} (physical.rod and physical.material)"),
        )
    };
    let diameter = match (defect_rod.diameter, regular) {
        (Some(d), _) => positive(&key("rod.diameter"), d)?,
        (None, Some(r)) => r.diameter,
        (None, None) => return Err(needs_regular("diameter")),
    };
    let material = match (&defect_rod.material, regular) {
        (Some(m), _) => material_of(&key("rod.material"), m)?,
        (None, Some(r)) => r.material,
        (None, None) => return Err(needs_regular("material")),
    };
    let slenderness = length / diameter;
    if !DEFECT_ROD_SLENDERNESS.contains(&slenderness) {
        return Err(invalid(
            key("rod.length"),
            format!(
                "a rod {length} m long and {diameter} m across has L/d = {slenderness:.3}, outside the {}..{} in which its first bending mode (Timoshenko) and the two-mass resonator stand for it",
                DEFECT_ROD_SLENDERNESS.start(),
                DEFECT_ROD_SLENDERNESS.end()
            ),
        ));
    }
    let share = share.unwrap_or(DEFAULT_RESONATOR_SHARE);
    if !(share.is_finite() && share > 0.0 && share < 1.0) {
        return Err(invalid(
            key("resonator_share"),
            format!("must be a number in (0, 1), got {}", number_text(share)),
        ));
    }
    let rod = Rod {
        length,
        diameter,
        material,
    };
    let f1_hz = rods::free_free_bending_frequency(&rod).ok_or_else(|| {
        invalid(
            key("rod"),
            "its first bending mode cannot be computed (Timoshenko beam theory found no mode)",
        )
    })?;
    let total = rod.mass();
    let (host_kg, resonator_kg) = ((1.0 - share) * total, share * total);
    let omega = 2.0 * std::f64::consts::PI * f1_hz;
    Ok(RodResonator {
        rod,
        host_kg,
        resonator_kg,
        stiffness: omega * omega * host_kg * resonator_kg / total,
        f1_hz,
    })
}
