//! `[chain]` and `[[segment]]`: which sites there are, what lies beyond the ends, each site's
//! mass and each contact's coefficient, the exponent and the precompression.

use woodpile_sim::contact::LawParts;
use woodpile_sim::model::{Boundary, End};
use woodpile_sim::ContactLaw;

use super::check::{
    invalid, non_negative, number, number_text, only_keys, positive, positive_pattern, required,
    Invalid,
};
use super::gravity;
use super::physical::Si;
use crate::raw;

/// Default chain: sites -100..100.
const DEFAULT_N: i64 = 100;
/// Longest chain accepted: far beyond any paper scene, small enough to never exhaust memory.
pub(crate) const MAX_N: i64 = 5_000_000;

/// Where the paper's sites sit in the simulator's numbering. A striker, when there is one, is
/// index 0, one before the first paper site; the paper's sites follow it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    /// The first paper site.
    pub first: i64,
    /// The last paper site.
    pub last: i64,
    /// 1 with a striker, else 0.
    pub striker_sites: usize,
}

impl Layout {
    /// Sites in the simulator, the striker included.
    pub fn n_sites(&self) -> usize {
        (self.last - self.first + 1) as usize + self.striker_sites
    }

    /// The paper number the simulator's index 0 has (the striker's is first − 1).
    pub fn index_zero(&self) -> i64 {
        self.first - self.striker_sites as i64
    }

    /// The simulator's index of paper site `site`, or why it is not on the chain.
    pub fn index(&self, key: &str, site: i64) -> Result<usize, Invalid> {
        let (first, last) = (self.first, self.last);
        if (first..=last).contains(&site) {
            Ok((site - first) as usize + self.striker_sites)
        } else {
            Err(invalid(
                key,
                format!("site {site} is off the chain (sites run from {first} to {last})"),
            ))
        }
    }
}

/// A soft end `{ spring = k, damping = c }`: a linear spring and a dashpot on a rigid support
/// (both default to 0; an SI scene gives N/m and N·s/m).
fn soft_end(key: &str, table: &toml::Table, si: Option<&Si>) -> Result<End, Invalid> {
    only_keys(
        key,
        table,
        &["spring", "damping"],
        "a soft end has spring and damping",
    )?;
    let get = |name: &str| -> Result<f64, Invalid> {
        let full = format!("{key}.{name}");
        match table.get(name) {
            None => Ok(0.0),
            Some(v) => non_negative(&full, number(&full, v)?),
        }
    };
    let (spring, damping) = (get("spring")?, get("damping")?);
    Ok(match si {
        None => End::Soft { spring, damping },
        Some(si) => End::Soft {
            spring: si.scales.spring(spring),
            damping: si.scales.dashpot(damping),
        },
    })
}

/// The first and last paper sites: `chain.n` (sites -n..n) or `chain.sites = [first, last]`.
pub(crate) fn sites(chain: Option<&raw::Chain>) -> Result<(i64, i64), Invalid> {
    let (n, sites) = chain.map_or((None, None), |c| (c.n, c.sites.as_deref()));
    match (n, sites) {
        (Some(_), Some(_)) => Err(invalid(
            "chain.sites",
            "give either chain.n (sites -n..n) or chain.sites = [first, last], not both",
        )),
        (_, Some(&[first, last])) => {
            if first >= last || last.checked_sub(first).is_none_or(|w| w > 2 * MAX_N) {
                return Err(invalid(
                    "chain.sites",
                    format!("must be [first, last] with first < last and at most {} sites, got [{first}, {last}]", 2 * MAX_N + 1),
                ));
            }
            Ok((first, last))
        }
        (_, Some(other)) => Err(invalid(
            "chain.sites",
            format!("must be [first, last], got {} values", other.len()),
        )),
        (n, None) => {
            let n = n.unwrap_or(DEFAULT_N);
            if !(1..=MAX_N).contains(&n) {
                return Err(invalid(
                    "chain.n",
                    format!("must be an integer in 1..={MAX_N}, got {n}"),
                ));
            }
            Ok((-n, n))
        }
    }
}

/// `chain.boundary`: `"fixed"` (the default), `"free"`, or `{ left = .., right = .. }` (a side
/// left out is fixed), each end `"fixed"`, `"free"` or soft, `{ spring = k, damping = c }` (N/m and N·s/m in an SI
/// scene, converted with its scales).
pub(crate) fn boundary(chain: Option<&raw::Chain>, si: Option<&Si>) -> Result<Boundary, Invalid> {
    let end = |key: &str, value: &toml::Value| match value {
        toml::Value::String(s) if s == "fixed" => Ok(End::Fixed),
        toml::Value::String(s) if s == "free" => Ok(End::Free),
        toml::Value::Table(soft) => soft_end(key, soft, si),
        _ => Err(invalid(
            key,
            format!("must be \"fixed\", \"free\" or {{ spring = .., damping = .. }}, got {value}"),
        )),
    };
    match chain.and_then(|c| c.boundary.as_ref()) {
        None => Ok(Boundary::Fixed),
        Some(toml::Value::Table(ends)) if ends.contains_key("spring") || ends.contains_key("damping") => Err(invalid(
            "chain.boundary",
            "a soft end belongs to one side: boundary = { left = \"free\", right = { spring = .., damping = .. } }",
        )),
        Some(toml::Value::Table(ends)) => {
            only_keys("chain.boundary", ends, &["left", "right"], "the ends are left and right")?;
            // A side left out keeps the default end, a wall: `{ right = "free" }` frees one.
            let side = |name: &str| match ends.get(name) {
                Some(value) => end(&format!("chain.boundary.{name}"), value),
                None => Ok(End::Fixed),
            };
            Ok(Boundary::ends(side("left")?, side("right")?))
        }
        Some(value) => {
            let both = end("chain.boundary", value)?;
            Ok(Boundary::ends(both, both))
        }
    }
}

/// Each site's mass and each bond's coefficient (bond numbering of `woodpile_sim::contact`),
/// relative to the regular site's, as the sections of a scene set them.
#[derive(Debug, Clone)]
pub(crate) struct Sites {
    pub masses: Vec<f64>,
    pub contacts: Vec<f64>,
    /// Whether any key set a contact coefficient ([`Sites::set_contact`]): without one, every
    /// coefficient is 1 and needs no pass over a long chain to say so.
    pub contacts_set: bool,
    /// The defect whose SI `mass` set a site's mass, to refuse a segment that sets it too.
    pub mass_from_defect: Vec<Option<usize>>,
}

impl Sites {
    /// Unit masses and contacts for `layout`.
    pub fn regular(layout: &Layout) -> Sites {
        let n = layout.n_sites();
        Sites {
            masses: vec![1.0; n],
            contacts: vec![1.0; n + 1],
            contacts_set: false,
            mass_from_defect: vec![None; n],
        }
    }

    /// Sets the coefficient of `bond`.
    pub fn set_contact(&mut self, bond: usize, a: f64) {
        self.contacts[bond] = a;
        self.contacts_set = true;
    }
}

/// Applies every `[[segment]]`: masses over its sites, coefficients over the contacts between
/// them, each a number or a pattern repeated from the segment's start. SI scenes give kg and
/// N/m^{3/2}.
pub(crate) fn segments(
    segments: &[raw::Segment],
    layout: &Layout,
    si: Option<&Si>,
    sites: &mut Sites,
) -> Result<(), Invalid> {
    // Which segment set each site so far: an overlap is found where a segment meets a site
    // already set, in time linear in the chain (segments that do not overlap cover each site
    // at most once), however many segments there are.
    let mut covered: Vec<Option<usize>> = vec![None; sites.masses.len()];
    for (i, segment) in segments.iter().enumerate() {
        let key = |k: &str| format!("segment[{i}].{k}");
        let range = required(&key("sites"), segment.sites.as_deref())?;
        let &[lo, hi] = range else {
            return Err(invalid(
                key("sites"),
                format!("must be [first, last], got {} values", range.len()),
            ));
        };
        if lo > hi {
            return Err(invalid(
                key("sites"),
                format!("first {lo} is after last {hi}"),
            ));
        }
        let start = layout.index(&key("sites"), lo)?;
        let end = layout.index(&key("sites"), hi)?;
        if let Some(j) = (start..=end).find_map(|index| covered[index]) {
            let other = segments[j].sites.as_deref().unwrap_or_default();
            return Err(invalid(
                key("sites"),
                format!("[{lo}, {hi}] overlaps segment[{j}]'s {other:?}: segments may not overlap"),
            ));
        }
        covered[start..=end].fill(Some(i));
        if let Some(mass) = &segment.mass {
            let pattern = positive_pattern(&key("mass"), mass)?;
            fits(&key("mass"), pattern.len(), end - start + 1, "sites")?;
            for (k, index) in (start..=end).enumerate() {
                if let Some(d) = sites.mass_from_defect[index] {
                    return Err(invalid(
                        key("mass"),
                        format!(
                            "site {} has its mass from defect[{d}].mass: give it once",
                            lo + k as i64
                        ),
                    ));
                }
                let m = pattern[k % pattern.len()];
                sites.masses[index] = si.map_or(m, |si| si.scales.mass_ratio(m));
            }
        }
        if let Some(contact) = &segment.contact {
            let pattern = positive_pattern(&key("contact"), contact)?;
            fits(
                &key("contact"),
                pattern.len(),
                end - start,
                "contacts between its sites",
            )?;
            // The contact between index j and j + 1 is bond j + 1.
            for (k, bond) in (start + 1..=end).enumerate() {
                let a = pattern[k % pattern.len()];
                sites.set_contact(bond, si.map_or(a, |si| a / si.scales.hertz));
            }
        }
    }
    Ok(())
}

/// Refuses a pattern of `len` values for a segment with only `room` places for them: the
/// values past the segment's end would be dropped without a word.
fn fits(key: &str, len: usize, room: usize, what: &str) -> Result<(), Invalid> {
    match len <= room.max(1) {
        true => Ok(()),
        false => Err(invalid(
            key,
            format!("{len} values for a segment with {room} {what}: a list may be as long as the segment, or shorter to repeat"),
        )),
    }
}

/// The contact law a scene declares, or `None` when its keys leave the paper's law (then the
/// chain is the paper's and keeps its bits). Walls carry `chain.wall_contact`.
pub(crate) fn contact_law(
    chain: Option<&raw::Chain>,
    (boundary, has_striker): (Boundary, bool),
    si: Option<&Si>,
    sites: &mut Sites,
    carried: &[f64],
) -> Result<Option<ContactLaw>, Invalid> {
    let gravity = gravity::gravity(chain, boundary, si)?;
    let (exponent, precompression, wall_contact) = chain.map_or((None, None, None), |c| {
        (c.exponent, c.precompression, c.wall_contact)
    });
    let exponent = match exponent {
        None => 1.5,
        Some(alpha) if !(1.0..=5.0).contains(&alpha) => {
            return Err(invalid(
                "chain.exponent",
                format!("must be a number from 1 to 5, got {}", number_text(alpha)),
            ))
        }
        Some(alpha) if si.is_some() && alpha != 1.5 => {
            return Err(invalid(
                "chain.exponent",
                format!("is {alpha}, but an SI ([physical]) scene is scaled by the Hertz law's 3/2: give other exponents in a dimensionless scene"),
            ))
        }
        Some(alpha) => alpha,
    };
    let force_scale = si.map_or(1.0, |si| {
        si.scales.mass_kg * si.scales.velocity * si.scales.velocity / si.scales.length_m()
    });
    let precompression = match precompression {
        None => 0.0,
        Some(f0) => non_negative("chain.precompression", f0)? / force_scale,
    };
    if precompression > 0.0 {
        if boundary != Boundary::Fixed {
            return Err(invalid(
                "chain.precompression",
                "needs fixed walls at both ends to hold it (chain.boundary = \"fixed\")",
            ));
        }
        if has_striker {
            return Err(invalid(
                "chain.precompression",
                "cannot be combined with a [striker], whose chain has a free left end",
            ));
        }
    }
    if let Some(a) = wall_contact {
        let a = positive("chain.wall_contact", a)?;
        let a = si.map_or(a, |si| a / si.scales.hertz);
        let last = sites.contacts.len() - 1;
        sites.set_contact(0, a);
        sites.set_contact(last, a);
    }
    // Keys spelling out the paper's law (no keys at all, or α = 3/2, unit coefficients and no
    // static force written out) build the paper's chain: its code path, its bits and its cache
    // key, however they are written. Asked of the parts, before a law of a million sites is
    // built for nothing.
    let parts = LawParts {
        coefficients: if sites.contacts_set {
            &sites.contacts
        } else {
            &[]
        },
        exponent,
        precompression,
        gravity: gravity.unwrap_or(0.0),
    };
    if parts.is_papers() {
        return Ok(None);
    }
    let law = match gravity {
        None => ContactLaw::new(sites.contacts.clone(), exponent, precompression),
        Some(g) => ContactLaw::under_gravity(sites.contacts.clone(), exponent, carried, g),
    };
    law.map(Some).map_err(|e| invalid("chain", e.to_string()))
}
