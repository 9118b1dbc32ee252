//! `[damping]` and each defect's `damping` or `quality_factor`: the dissipation of a chain
//! (woodpile_sim::damping). SI scenes give N·s/m (N·s/m^{3/2} for a Hertzian contact dashpot),
//! converted here; the converted values are listed in the JSON's `physical` block.

use woodpile_sim::model::{Coupling, Resonator};
use woodpile_sim::{Damping, DashpotLaw};

use woodpile_sim::restitution::{dashpot_for, Pair};

use super::chain::{Layout, Sites};
use super::check::{invalid, non_negative, positive, required, Invalid};
use super::physical::Si;
use crate::raw;

/// Values an SI scene converted, by name, for the JSON's `physical` block.
pub(super) type Listed = Vec<(String, f64)>;

/// An SI coefficient in the model's units.
pub(super) type Scale = fn(&Si, f64) -> f64;

/// The damping `file` declares, in the model's units, with the converted values an SI scene
/// lists; `None` when it declares none.
pub(crate) fn damping(
    file: &raw::SceneFile,
    resonators: &[Resonator],
    (sites, layout): (&Sites, &Layout),
    si: Option<&Si>,
) -> Result<Option<(Damping, Listed)>, Invalid> {
    let masses = &sites.masses;
    let table = file.damping.as_ref();
    let any_defect = file
        .defect
        .iter()
        .any(|d| d.damping.is_some() || d.quality_factor.is_some());
    if table.is_none() && !any_defect && !own_dashpots_declared(file) {
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
    let mut damping = Damping::new(contact, law, ground, per_resonator)
        .map_err(|e| invalid("damping", e.to_string()))?;
    let own = Own {
        law,
        si,
        contact,
        scale: contact_scale(law),
        exponent: file.chain.as_ref().and_then(|c| c.exponent).unwrap_or(1.5),
        tolerance: restitution_tolerance(file),
    };
    if let Some(each) = own.per_bond(file, sites, layout, &mut listed)? {
        damping = damping
            .with_contacts(each)
            .map_err(|e| invalid("damping", e.to_string()))?;
    }
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
    let contact_scale = contact_scale(law);
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
/// restitution's velocity part with its e.
fn calibrated(
    file: &raw::SceneFile,
    restitution: &raw::Restitution,
    law: DashpotLaw,
    si: Option<&Si>,
) -> Result<f64, Invalid> {
    let exponent = file.chain.as_ref().and_then(|c| c.exponent).unwrap_or(1.5);
    // Two regular sites through the regular contact: mass and coefficient 1 in the model's units.
    let pair = Pair::new(1.0, 1.0, 1.0, exponent, law);
    calibrated_pair(
        "damping.restitution",
        restitution,
        &pair,
        (restitution_tolerance(file), si),
    )
}

/// γ (model units) under which `pair`, meeting at the restitution's velocity, parts with its
/// e: the isolated pair's collision solved to `tolerance` ([`woodpile_sim::restitution`]).
/// `key` is the restitution table's, for messages.
pub(super) fn calibrated_pair(
    key: &str,
    restitution: &raw::Restitution,
    pair: &Pair,
    (tolerance, si): (f64, Option<&Si>),
) -> Result<f64, Invalid> {
    let e = required(&format!("{key}.e"), restitution.e)?;
    let velocity = required(&format!("{key}.velocity"), restitution.velocity.as_ref())?;
    let velocity = impact_velocity(&format!("{key}.velocity"), velocity, si)?;
    dashpot_for(pair, e, velocity, tolerance).map_err(|err| invalid(key, err.to_string()))
}

/// The tolerance a restitution is solved to: the scene's, within [1e-12, 1e-6].
fn restitution_tolerance(file: &raw::SceneFile) -> f64 {
    let tolerance = file.run.as_ref().and_then(|r| r.tolerance).unwrap_or(1e-8);
    tolerance.clamp(1e-12, 1e-6)
}

/// How an SI contact dashpot converts to the model's units, by its law.
pub(super) fn contact_scale(law: DashpotLaw) -> Scale {
    match law {
        DashpotLaw::Linear => |si, c| si.scales.dashpot(c),
        DashpotLaw::Hertzian => |si, c| si.scales.hertzian_dashpot(c),
    }
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
pub(super) fn converted(
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

/// Whether a segment or the striker gives its own contact dashpot.
fn own_dashpots_declared(file: &raw::SceneFile) -> bool {
    let segments = file
        .segment
        .iter()
        .any(|s| s.damping.is_some() || s.restitution.is_some());
    let striker = file
        .striker
        .as_ref()
        .is_some_and(|s| s.damping.is_some() || s.restitution.is_some());
    segments || striker
}

/// What a segment's or the striker's own dashpot is resolved with: the law, the SI scales, the
/// γ of every other contact, how an SI γ converts, the contacts' exponent and the tolerance a
/// restitution is solved to.
struct Own<'a> {
    law: DashpotLaw,
    si: Option<&'a Si>,
    contact: f64,
    scale: Scale,
    exponent: f64,
    tolerance: f64,
}

impl Own<'_> {
    /// Each bond's γ when a segment or the striker gives its own (`segment[i].damping` or
    /// `.restitution` on the contacts between its sites; `striker.damping` or `.restitution` on
    /// its contact with the first site), every other bond keeping `[damping] contact`; `None`
    /// when none does, so that the chain keeps one γ.
    fn per_bond(
        &self,
        file: &raw::SceneFile,
        sites: &Sites,
        layout: &Layout,
        listed: &mut Listed,
    ) -> Result<Option<Vec<f64>>, Invalid> {
        if !own_dashpots_declared(file) {
            return Ok(None);
        }
        let mut each = vec![self.contact; sites.contacts.len()];
        for (i, segment) in file.segment.iter().enumerate() {
            let key = format!("segment[{i}]");
            let Some([lo, hi]) = segment
                .sites
                .as_deref()
                .and_then(|s| <[i64; 2]>::try_from(s).ok())
            else {
                continue;
            };
            let (start, end) = (layout.index(&key, lo)?, layout.index(&key, hi)?);
            let own = (segment.damping, segment.restitution.as_ref());
            let Some(gamma) = self.gamma(&key, own, sites, start, listed)? else {
                continue;
            };
            if end == start {
                return Err(invalid(
                    format!("{key}.damping"),
                    "a segment of one site has no contact between its sites",
                ));
            }
            each[start + 1..=end].fill(gamma);
        }
        if let Some(striker) = &file.striker {
            let own = (striker.damping, striker.restitution.as_ref());
            if let Some(gamma) = self.gamma("striker", own, sites, 0, listed)? {
                each[1] = gamma;
            }
        }
        Ok(Some(each))
    }

    /// γ of `key`'s own dashpot, given as a coefficient or as a restitution of the pair of
    /// sites `first` and `first + 1` through their contact; `None` when it gives neither.
    fn gamma(
        &self,
        key: &str,
        (damping, restitution): (Option<f64>, Option<&raw::Restitution>),
        sites: &Sites,
        first: usize,
        listed: &mut Listed,
    ) -> Result<Option<f64>, Invalid> {
        match (damping, restitution) {
            (None, None) => Ok(None),
            (Some(_), Some(_)) => Err(invalid(
                format!("{key}.restitution"),
                "give damping or restitution, not both",
            )),
            (Some(c), None) => {
                let key = format!("{key}.damping");
                converted((&key, Some(c)), (self.si, self.scale), listed).map(Some)
            }
            (None, Some(restitution)) => {
                let masses = (
                    sites.masses[first],
                    sites.masses[(first + 1).min(sites.masses.len() - 1)],
                );
                let pair = Pair::new(
                    masses.0,
                    masses.1,
                    sites.contacts[first + 1],
                    self.exponent,
                    self.law,
                );
                let key = format!("{key}.restitution");
                let gamma = calibrated_pair(&key, restitution, &pair, (self.tolerance, self.si))?;
                if let Some(si) = self.si {
                    let name = key.replace(['.', '[', ']'], "_");
                    listed.push((format!("{name}_damping_si"), gamma / (self.scale)(si, 1.0)));
                }
                Ok(Some(gamma))
            }
        }
    }
}
