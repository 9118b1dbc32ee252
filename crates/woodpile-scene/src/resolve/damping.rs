//! `[damping]` and each defect's `damping` or `quality_factor`: the dissipation of a chain
//! (woodpile_sim::damping). SI scenes give N·s/m (N·s/m^{3/2} for a Hertzian contact dashpot),
//! converted here; the converted values are listed in the JSON's `physical` block.

use woodpile_sim::model::{Coupling, Resonator};
use woodpile_sim::{Damping, DashpotLaw};

use woodpile_sim::restitution::{dashpot_for, Pair};

use super::check::{invalid, non_negative, positive, required, Invalid};
use super::physical::Si;
use crate::raw;

/// Values an SI scene converted, by name, for the JSON's `physical` block.
type Listed = Vec<(String, f64)>;

/// An SI coefficient in the model's units.
type Scale = fn(&Si, f64) -> f64;

/// The damping `file` declares, in the model's units, with the converted values an SI scene
/// lists; `None` when it declares none.
pub(crate) fn damping(
    file: &raw::SceneFile,
    resonators: &[Resonator],
    masses: &[f64],
    si: Option<&Si>,
) -> Result<Option<(Damping, Listed)>, Invalid> {
    let table = file.damping.as_ref();
    let any_defect = file
        .defect
        .iter()
        .any(|d| d.damping.is_some() || d.quality_factor.is_some());
    if table.is_none() && !any_defect {
        return Ok(None);
    }
    let law = match table.and_then(|t| t.law.as_deref()) {
        None | Some("linear") => DashpotLaw::Linear,
        Some("hertzian") => DashpotLaw::Hertzian,
        Some(other) => {
            return Err(invalid(
                "damping.law",
                format!("must be \"linear\" or \"hertzian\", got \"{other}\""),
            ))
        }
    };
    let mut listed = Listed::new();
    let dashpot: Scale = |si, c| si.scales.dashpot(c);
    let contact = contact_dashpot(file, law, si, &mut listed)?;
    let ground = converted(
        ("damping.ground", table.and_then(|t| t.ground)),
        (si, dashpot),
        &mut listed,
    )?;
    let mut per_resonator = Vec::with_capacity(resonators.len());
    for (j, (d, r)) in file.defect.iter().zip(resonators).enumerate() {
        let c = match (d.damping, d.quality_factor) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    format!("defect[{j}].quality_factor"),
                    "give damping or quality_factor, not both",
                ))
            }
            (Some(c), None) => converted(
                (&format!("defect[{j}].damping"), Some(c)),
                (si, dashpot),
                &mut listed,
            )?,
            (None, Some(q)) => {
                let c = from_quality_factor(&format!("defect[{j}].quality_factor"), q, r, masses)?;
                if si.is_some() {
                    listed.push((format!("defect_{j}__damping"), c));
                }
                c
            }
            (None, None) => 0.0,
        };
        per_resonator.push(c);
    }
    let damping = Damping::new(contact, law, ground, per_resonator)
        .map_err(|e| invalid("damping", e.to_string()))?;
    Ok(Some((damping, listed)))
}

/// γ of every contact: `damping.contact` (converted), or calibrated from
/// `damping.restitution`, listed in an SI scene both ways.
fn contact_dashpot(
    file: &raw::SceneFile,
    law: DashpotLaw,
    si: Option<&Si>,
    listed: &mut Listed,
) -> Result<f64, Invalid> {
    let table = file.damping.as_ref();
    let contact_scale: Scale = match law {
        DashpotLaw::Linear => |si, c| si.scales.dashpot(c),
        DashpotLaw::Hertzian => |si, c| si.scales.hertzian_dashpot(c),
    };
    Ok(match table.and_then(|t| t.restitution.as_ref()) {
        None => converted(
            ("damping.contact", table.and_then(|t| t.contact)),
            (si, contact_scale),
            listed,
        )?,
        Some(_) if table.and_then(|t| t.contact).is_some() => {
            return Err(invalid(
                "damping.restitution",
                "give damping.contact or damping.restitution, not both",
            ))
        }
        Some(restitution) => {
            let gamma = calibrated(file, restitution, law, si)?;
            if let Some(si) = si {
                listed.push(("damping_contact".into(), gamma));
                listed.push(("damping_contact_si".into(), gamma / contact_scale(si, 1.0)));
            }
            gamma
        }
    })
}

/// γ (model units) of the contact dashpot under which two regular sites meeting at the
/// restitution's velocity part with its e: the isolated pair's collision solved to the
/// scene's tolerance ([`woodpile_sim::restitution`]).
fn calibrated(
    file: &raw::SceneFile,
    restitution: &raw::Restitution,
    law: DashpotLaw,
    si: Option<&Si>,
) -> Result<f64, Invalid> {
    let e = required("damping.restitution.e", restitution.e)?;
    let velocity = required(
        "damping.restitution.velocity",
        restitution.velocity.as_ref(),
    )?;
    let velocity = impact_velocity("damping.restitution.velocity", velocity, si)?;
    let exponent = file.chain.as_ref().and_then(|c| c.exponent).unwrap_or(1.5);
    // Two regular sites through the regular contact: mass and coefficient 1 in the model's units.
    let pair = Pair::new(1.0, 1.0, 1.0, exponent, law);
    let tolerance = file.run.as_ref().and_then(|r| r.tolerance).unwrap_or(1e-8);
    dashpot_for(&pair, e, velocity, tolerance.clamp(1e-12, 1e-6))
        .map_err(|err| invalid("damping.restitution", err.to_string()))
}

/// A velocity in the model's units: a scaled scene's number as it is; a physical scene's in
/// m/s, a number or text such as "1 m/s" or "20 mm/s", over its velocity scale.
fn impact_velocity(key: &str, value: &toml::Value, si: Option<&Si>) -> Result<f64, Invalid> {
    let number = |v: &toml::Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
    let metres_per_second = match (value, si) {
        (toml::Value::String(text), Some(_)) => {
            crate::quantity::parse(text, "velocity").map_err(|reason| invalid(key, reason))?
        }
        (toml::Value::String(text), None) => {
            return Err(invalid(
                key,
                format!("`{text}`: a velocity with a unit needs a [physical] scene; give a number in the model's units"),
            ))
        }
        (v, _) => number(v).ok_or_else(|| invalid(key, "expected a number, or text such as \"1 m/s\""))?,
    };
    let v = positive(key, metres_per_second)?;
    Ok(si.map_or(v, |si| v / si.scales.velocity))
}

/// The coefficient at `key` (default 0, checked ≥ 0), in the model's units: an SI scene's
/// value converted by `scale` and listed under the key's name (dots and brackets made `_`).
fn converted(
    (key, value): (&str, Option<f64>),
    (si, scale): (Option<&Si>, Scale),
    listed: &mut Listed,
) -> Result<f64, Invalid> {
    let value = non_negative(key, value.unwrap_or(0.0))?;
    Ok(match si {
        Some(si) if value > 0.0 => {
            let scaled = scale(si, value);
            listed.push((key.replace(['.', '[', ']'], "_"), scaled));
            scaled
        }
        _ => value,
    })
}

/// c_j of a linear resonator with quality factor `q`: the pair vibrates against each other
/// with reduced mass μ = m_host ε / (m_host + ε) at ω = sqrt(κ / μ), and Q = μ ω / c.
fn from_quality_factor(key: &str, q: f64, r: &Resonator, masses: &[f64]) -> Result<f64, Invalid> {
    let q = positive(key, q)?;
    let kappa = match r.coupling {
        Coupling::Constant(k) if r.p == 1 && k > 0.0 => k,
        _ => {
            return Err(invalid(
                key,
                "a quality factor needs a linear resonator (p = 1) with a constant kappa > 0; give damping instead",
            ))
        }
    };
    let host = masses[r.site];
    let reduced = host * r.eps / (host + r.eps);
    Ok(reduced * (kappa / reduced).sqrt() / q)
}
