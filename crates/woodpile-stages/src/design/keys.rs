//! The design stage's keys, parsed: its search space (`[space]`: how many resonators, on which
//! sites, with which eps, kappa and p), its budget, objective, refinement, robustness and
//! verification, and the keys laid on every resonator it places (`each_resonator`).

use woodpile_pipeline::error::Result;
use woodpile_pipeline::fields::Fields;

use super::space::{Range, Sites, Space, Values};
use super::{Design, POPULATION};
use crate::schema::Fraction;

impl Design {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Design> {
        let positive_int = |fields: &mut Fields<'_>, key: &str, default: Option<i64>| {
            let value = match (fields.optional::<i64>(key)?, default) {
                (Some(v), _) => v,
                (None, Some(d)) => d,
                (None, None) => return Err(fields.error(key, "is required")),
            };
            if !(0..=1_000_000).contains(&value) {
                return Err(fields.error(key, "expected an integer from 0 to 1000000"));
            }
            Ok(value as usize)
        };
        let seed = fields.required::<i64>("seed")? as u64;
        let budget = positive_int(fields, "budget", None)?;
        if budget < POPULATION {
            return Err(fields.error("budget", format!("at least {POPULATION} evaluations")));
        }
        let refine = positive_int(fields, "refine", Some(0))?;
        let objective = fields.choice("objective", &Fraction::OPTIONS, None)?;
        let maximise = fields.choice("goal", &[("max", true), ("min", false)], Some(true))?;
        let verify_tolerance = fields.optional::<f64>("verify_tolerance")?.unwrap_or(1e-8);
        let robustness = match fields.optional::<toml::Table>("robustness")? {
            None => None,
            Some(table) => {
                let mut f = fields.nested("robustness", table);
                let samples = positive_int(&mut f, "samples", None)?;
                let spreads: Vec<f64> = f.required("spreads")?;
                if spreads.iter().any(|s| !(0.0..1.0).contains(s)) {
                    return Err(f.error("spreads", "expected fractions in [0, 1)"));
                }
                f.finish()?;
                Some((samples, spreads))
            }
        };
        let Some(space) = fields.optional::<toml::Table>("space")? else {
            return Err(fields.error("space", "is required"));
        };
        let space = parse_space(fields.nested("space", space))?;
        let each_resonator = parse_each_resonator(fields)?;
        let template: toml::Table = fields.required("scene")?;
        if template.contains_key("defect") {
            return Err(fields.error(
                "scene.defect",
                "the design places the defects: leave them out",
            ));
        }
        let region = template
            .get("fractions")
            .and_then(|f| f.get("region"))
            .is_some();
        if !region {
            return Err(fields.error(
                "scene.fractions.region",
                "is required: the trap's region must not move with the design",
            ));
        }
        let design = Design {
            seed,
            budget,
            refine,
            objective,
            maximise,
            verify_tolerance,
            robustness,
            space,
            template,
            each_resonator,
            file: fields.file().to_path_buf(),
        };
        // The extremes of the space must make valid scenes: catch a bad template now.
        let dimension = design.space.dimension();
        for corner in [0.0, 1.0 - 1e-12] {
            design.scene(&design.space.decode(&vec![corner; dimension]), None)?;
        }
        Ok(design)
    }
}

/// `each_resonator`: defect keys laid on every resonator the design places, but none of the
/// keys the design sets itself.
fn parse_each_resonator(fields: &mut Fields<'_>) -> Result<toml::Table> {
    let each: toml::Table = fields.optional("each_resonator")?.unwrap_or_default();
    match ["site", "eps", "kappa", "p", "rod"]
        .into_iter()
        .find(|k| each.contains_key(*k))
    {
        Some(placed) => Err(fields.error(
            &format!("each_resonator.{placed}"),
            "the design sets each resonator's site, eps, kappa and p (or its rod)",
        )),
        None => Ok(each),
    }
}

fn parse_space(mut f: Fields<'_>) -> Result<Space> {
    let sites = parse_sites(&mut f)?;
    let (lo, hi) = match (&sites, f.optional::<toml::Value>("resonators")?) {
        (Sites::Fixed(list), None) => (list.len() as i64, list.len() as i64),
        (_, None) => return Err(f.error("resonators", "is required: [fewest, most]")),
        (_, Some(toml::Value::Array(items))) => match items.as_slice() {
            [toml::Value::Integer(a), toml::Value::Integer(b)] if a <= b => (*a, *b),
            _ => {
                return Err(f.error(
                    "resonators",
                    "expected [fewest, most], integers with fewest <= most",
                ))
            }
        },
        (_, Some(_)) => return Err(f.error("resonators", "expected [fewest, most]")),
    };
    if lo < 0 || !(1..=64).contains(&hi) {
        return Err(f.error(
            "resonators",
            "expected counts from 0 to 64, at least one resonator possible",
        ));
    }
    if let Sites::Fixed(list) = &sites {
        if (lo, hi) != (list.len() as i64, list.len() as i64) {
            return Err(f.error(
                "resonators",
                format!(
                    "with fixed sites there is one resonator per site: [{0}, {0}] (or leave it out)",
                    list.len()
                ),
            ));
        }
    }
    if (sites.count() as i64) < lo {
        return Err(f.error("sites", "fewer sites than the fewest resonators"));
    }
    let length = parse_lengths(&mut f)?;
    if length.is_some() {
        return rod_space(f, sites, (lo as usize, hi as usize), length);
    }
    let eps = parse_values(&mut f, "eps")?;
    let kappa = parse_values(&mut f, "kappa")?;
    let p: Vec<i64> = match f.optional::<toml::Value>("p")? {
        None => vec![1],
        Some(toml::Value::Array(items)) if !items.is_empty() => items
            .iter()
            .map(|v| {
                v.as_integer()
                    .ok_or_else(|| f.error("p", "expected integers"))
            })
            .collect::<Result<_>>()?,
        Some(_) => return Err(f.error("p", "expected a list of exponents")),
    };
    let max_total_eps = f.optional::<f64>("max_total_eps")?;
    f.finish()?;
    Ok(Space {
        resonators: (lo as usize, hi as usize),
        sites,
        eps,
        kappa,
        p,
        max_total_eps,
        length: None,
    })
}

/// A space of defect rods (`length`): eps, kappa and p follow from each rod, so they may not
/// be given, nor a bound on the added eps.
fn rod_space(
    mut f: Fields<'_>,
    sites: Sites,
    resonators: (usize, usize),
    length: Option<Values>,
) -> Result<Space> {
    for key in ["eps", "kappa", "p", "max_total_eps"] {
        if f.take(key).is_some() {
            return Err(f.error(
                key,
                "a space of rod lengths derives each rod's eps and kappa from its bending mode (p = 1): leave it out",
            ));
        }
    }
    f.finish()?;
    Ok(Space {
        resonators,
        sites,
        eps: Values::List(Vec::new()),
        kappa: Values::List(Vec::new()),
        p: vec![1],
        max_total_eps: None,
        length,
    })
}

/// `length`: the defect rods' lengths, `{ min = "20 mm", max = "80 mm", log = false }` or a
/// list of the lengths a lab has (`["20 mm", "40 mm"]`); a bare number is metres.
fn parse_lengths(f: &mut Fields<'_>) -> Result<Option<Values>> {
    let metres = |f: &Fields<'_>, key: &str, v: &toml::Value| -> Result<f64> {
        let x = match v {
            toml::Value::String(text) => woodpile_scene::quantity::parse(text, "length")
                .map_err(|reason| f.error(key, reason))?,
            toml::Value::Float(x) => *x,
            toml::Value::Integer(i) => *i as f64,
            _ => return Err(f.error(key, "expected a length, \"40 mm\" or metres")),
        };
        match x.is_finite() && x > 0.0 {
            true => Ok(x),
            false => Err(f.error(key, "expected a positive length")),
        }
    };
    match f.take("length") {
        None => Ok(None),
        Some(toml::Value::Array(items)) if !items.is_empty() => {
            let list = items
                .iter()
                .map(|v| metres(f, "length", v))
                .collect::<Result<Vec<f64>>>()?;
            Ok(Some(Values::List(list)))
        }
        Some(toml::Value::Table(table)) => {
            let mut r = f.nested("length", table);
            let (Some(min), Some(max)) = (r.take("min"), r.take("max")) else {
                return Err(r.error("min", "expected { min, max } lengths"));
            };
            let (min, max) = (metres(&r, "min", &min)?, metres(&r, "max", &max)?);
            let log = match r.take("log") {
                None => false,
                Some(toml::Value::Boolean(b)) => b,
                Some(_) => return Err(r.error("log", "expected true or false")),
            };
            if min > max {
                return Err(r.error("min", "expected min <= max"));
            }
            r.finish()?;
            Ok(Some(Values::Range(Range { min, max, log })))
        }
        Some(_) => Err(f.error("length", "expected { min, max } or a list of lengths")),
    }
}

/// `sites`: `[first, last]`, a list of three or more sites, `{ among = [...] }` or
/// `{ fixed = [...] }` (paper sites, distinct).
/// The widest `sites = [first, last]` a design may search: far more sites than any trap, and
/// few enough to list.
const MAX_RANGE_SITES: usize = 10_000;

fn parse_sites(f: &mut Fields<'_>) -> Result<Sites> {
    const FORMS: &str =
        "expected [first, last], a list of sites, { among = [...] } or { fixed = [...] }";
    let integers = |f: &Fields<'_>, key: &str, items: &[toml::Value]| -> Result<Vec<i64>> {
        let list: Vec<i64> = items
            .iter()
            .map(toml::Value::as_integer)
            .collect::<Option<_>>()
            .ok_or_else(|| f.error(key, "expected integer paper sites"))?;
        let mut sorted = list.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() != list.len() || list.is_empty() || list.len() > 64 {
            return Err(f.error(key, "expected 1 to 64 distinct sites"));
        }
        Ok(sorted)
    };
    match f.required::<toml::Value>("sites")? {
        toml::Value::Array(items) => match items.as_slice() {
            [toml::Value::Integer(a), toml::Value::Integer(b)] if a <= b => {
                // The span is counted in i128: [i64::MIN, i64::MAX] must not overflow, and a
                // range is listed site by site when a genome is decoded.
                if i128::from(*b) - i128::from(*a) >= MAX_RANGE_SITES as i128 {
                    return Err(f.error(
                        "sites",
                        format!("a range of at most {MAX_RANGE_SITES} sites"),
                    ));
                }
                Ok(Sites::Range(*a, *b))
            }
            [_, _] => Err(f.error("sites", "expected [first, last] with first <= last (for two separate sites: { among = [a, b] })")),
            _ => Ok(Sites::Among(integers(f, "sites", &items)?)),
        },
        toml::Value::Table(table) => {
            let mut t = f.nested("sites", table);
            let form = match (t.take("among"), t.take("fixed")) {
                (Some(toml::Value::Array(items)), None) => Sites::Among(integers(&t, "among", &items)?),
                (None, Some(toml::Value::Array(items))) => Sites::Fixed(integers(&t, "fixed", &items)?),
                _ => return Err(f.error("sites", FORMS)),
            };
            t.finish()?;
            Ok(form)
        }
        _ => Err(f.error("sites", FORMS)),
    }
}

/// `eps` or `kappa`: `{ min, max, log }`, or a list of the values allowed.
fn parse_values(f: &mut Fields<'_>, key: &str) -> Result<Values> {
    match f.optional::<toml::Value>(key)? {
        Some(toml::Value::Array(items)) => {
            let list: Option<Vec<f64>> = items
                .iter()
                .map(|v| match v {
                    toml::Value::Float(x) if x.is_finite() && *x > 0.0 => Some(*x),
                    toml::Value::Integer(i) if *i > 0 => Some(*i as f64),
                    _ => None,
                })
                .collect();
            match list {
                Some(list) if !list.is_empty() => Ok(Values::List(list)),
                _ => Err(f.error(
                    key,
                    "expected a list of positive numbers, or { min, max, log }",
                )),
            }
        }
        Some(toml::Value::Table(table)) => {
            let mut r = f.nested(key, table);
            let min: f64 = r.required("min")?;
            let max: f64 = r.required("max")?;
            let log = match r.take("log") {
                None => false,
                Some(toml::Value::Boolean(b)) => b,
                Some(_) => return Err(r.error("log", "expected true or false")),
            };
            if !(min.is_finite() && max.is_finite() && min > 0.0 && min <= max) {
                return Err(r.error("min", "expected 0 < min <= max"));
            }
            r.finish()?;
            Ok(Values::Range(Range { min, max, log }))
        }
        Some(_) => Err(f.error(key, "expected { min, max, log } or a list of values")),
        None => Err(f.error(key, "is required: { min, max, log } or a list of values")),
    }
}
