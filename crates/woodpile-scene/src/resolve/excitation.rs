//! `[impulse]` or `[striker]`: how the energy enters the chain. An impulse gives one site a
//! velocity (the paper's Eq. 2); a striker is a body of its own, index 0 of the simulator,
//! that starts touching the first site and hits it through its own contact.

use woodpile_sim::model::{Boundary, End};
use woodpile_sim::rods;

use super::chain::{Layout, Sites};
use super::check::{self, invalid, positive, required, Invalid};
use super::physical::{material_of, Si};
use crate::raw;

/// The paper's impulse site.
const DEFAULT_IMPULSE_SITE: i64 = -25;

/// The site that starts moving (simulator index) and its velocity.
pub(crate) type Excitation = (usize, f64);

/// The `[impulse]`: a site and a velocity (dimensionless; an SI scene's is its velocity scale,
/// so 1).
pub(crate) fn impulse(
    impulse: Option<&raw::Impulse>,
    layout: &Layout,
    si: Option<&Si>,
) -> Result<Excitation, Invalid> {
    let (site, velocity) = impulse.map_or((None, None), |i| (i.site, i.velocity));
    let site = layout.index("impulse.site", site.unwrap_or(DEFAULT_IMPULSE_SITE))?;
    let velocity = match (velocity, si) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                "impulse.velocity",
                "is physical.velocity in a [physical] scene",
            ));
        }
        (Some(0.0), None) => {
            return Err(invalid(
                "impulse.velocity",
                "is 0: no wave enters the chain, so there is no energy to split and the fractions are undefined",
            ));
        }
        (Some(v), None) => check::velocity("impulse.velocity", v)?,
        (None, _) => 1.0,
    };
    Ok((site, velocity))
}

/// The `[striker]`: its mass and contact go into `sites` (index 0, bond 1), and it starts
/// with its velocity. Its chain's left end must be free, and it replaces `[impulse]`.
pub(crate) fn striker(
    striker: &raw::Striker,
    has_impulse: bool,
    boundary: Boundary,
    si: Option<&Si>,
    sites: &mut Sites,
) -> Result<Excitation, Invalid> {
    if has_impulse {
        return Err(invalid(
            "impulse",
            "a scene gives [impulse] or [striker], not both",
        ));
    }
    // A wall would hold the striker back; a soft end's spring and dashpot would act on the
    // striker itself (index 0 is the left end's body), which is no woodpile's.
    if !matches!(boundary.left(), End::Free) {
        return Err(invalid(
            "striker",
            "needs a free left end to strike (a wall or a soft end would act on the striker): set chain.boundary = { left = \"free\", right = \"fixed\" } (or \"free\", or a soft end)",
        ));
    }
    let (mass, contact, velocity) = match si {
        None => {
            if striker.sphere.is_some() {
                return Err(invalid(
                    "striker.sphere",
                    "is only allowed in a scene with a [physical] table",
                ));
            }
            let velocity = match striker.velocity {
                Some(0.0) => {
                    return Err(invalid(
                        "striker.velocity",
                        "is 0: the striker never reaches the chain",
                    ))
                }
                Some(v) => check::velocity("striker.velocity", positive("striker.velocity", v)?)?,
                None => 1.0,
            };
            let mass = positive("striker.mass", required("striker.mass", striker.mass)?)?;
            let contact = striker
                .contact
                .map(|a| positive("striker.contact", a))
                .transpose()?;
            (mass, contact, velocity)
        }
        Some(si) => {
            let (mass_kg, contact) = si_striker(striker, si)?;
            let contact = contact.map(|a| a / si.scales.hertz);
            (si.scales.mass_ratio(mass_kg), contact, 1.0)
        }
    };
    sites.masses[0] = mass;
    if let Some(a) = contact {
        sites.set_contact(1, a);
    }
    Ok((0, velocity))
}

/// An SI striker's mass (kg) and contact coefficient (N/m^{3/2}, `None` for the chain's own):
/// `contact` as given, or derived for `sphere = { diameter, material }` against the regular
/// rod; a sphere's mass defaults to ρ π D³/6.
fn si_striker(striker: &raw::Striker, si: &Si) -> Result<(f64, Option<f64>), Invalid> {
    let Some(sphere) = &striker.sphere else {
        let mass = positive("striker.mass", required("striker.mass", striker.mass)?)?;
        let contact = striker
            .contact
            .map(|a| positive("striker.contact", a))
            .transpose()?;
        return Ok((mass, contact));
    };
    if striker.contact.is_some() {
        return Err(invalid(
            "striker.contact",
            "is derived from striker.sphere: give one or the other",
        ));
    }
    let rod = si.rod.as_ref().ok_or_else(|| {
        invalid(
            "striker.sphere",
            "needs the rod it strikes: give physical.rod and physical.material",
        )
    })?;
    let diameter = positive(
        "striker.sphere.diameter",
        required("striker.sphere.diameter", sphere.diameter)?,
    )?;
    let material = material_of(
        "striker.sphere.material",
        required("striker.sphere.material", sphere.material.as_ref())?,
    )?;
    let mass = match striker.mass {
        Some(m) => positive("striker.mass", m)?,
        None => rods::sphere_mass(diameter, &material),
    };
    Ok((
        mass,
        Some(rods::sphere_on_rod_coefficient(diameter, &material, rod)),
    ))
}
