//! A sweep's scene template: a scene in the `woodpile simulate` format (docs/scene.md)
//! where any value may be a placeholder `"$name"` for an axis, plus one pipeline-only key,
//! `defect[i].through`, which repeats a defect on every site from `site` to `through`
//! (the paper's block of adjacent defects 0..L is `site = 0, through = "$L"`).
//!
//! Instantiating the template at a grid point gives an ordinary scene table, validated by
//! `woodpile_scene` exactly as a scene file would be: a sweep point is always a scene a user
//! could write by hand and run with `woodpile simulate`.

use std::collections::BTreeSet;

use crate::grid::{Axis, AxisValue};

/// A validated template.
#[derive(Debug, Clone, PartialEq)]
pub struct Template {
    table: toml::Table,
}

/// `(dotted key, reason)`: the caller knows the file.
pub type TemplateError = (String, String);

impl Template {
    /// Checks that every placeholder names an axis and every axis is used.
    pub fn new(table: toml::Table, axes: &[Axis]) -> Result<Self, TemplateError> {
        let mut used = BTreeSet::new();
        collect_placeholders("scene", &toml::Value::Table(table.clone()), &mut used)?;
        for (name, path) in &used {
            if !axes.iter().any(|a| &a.name == name) {
                return Err((path.clone(), format!("placeholder `${name}` names no axis")));
            }
        }
        for axis in axes {
            if !used.iter().any(|(name, _)| name == &axis.name) {
                return Err((
                    format!("axes.{}", axis.name),
                    "axis is never used: put \"$".to_string() + &axis.name + "\" in [scene]",
                ));
            }
        }
        Ok(Self { table })
    }

    /// Whether the scene declares dissipation (a `[damping]` table, a defect's `damping` or
    /// `quality_factor`, or a soft end's `damping`), whatever values its axes take: the
    /// sweep's table then has the dissipated share `D` on every row (0 where the values
    /// dissipate nothing).
    pub fn declares_dissipation(&self) -> bool {
        let has = |value: Option<&toml::Value>, keys: &[&str]| {
            value
                .and_then(toml::Value::as_table)
                .is_some_and(|t| keys.iter().any(|k| t.contains_key(*k)))
        };
        let defects = self.table.get("defect").and_then(toml::Value::as_array);
        let boundary = self
            .table
            .get("chain")
            .and_then(|c| c.get("boundary"))
            .and_then(toml::Value::as_table);
        self.table.contains_key("damping")
            || defects.is_some_and(|list| {
                list.iter()
                    .any(|d| has(Some(d), &["damping", "quality_factor"]))
            })
            || boundary.is_some_and(|ends| ends.values().any(|end| has(Some(end), &["damping"])))
    }

    /// The scene table at the grid point `values` (one per axis, in `axes` order).
    pub fn instantiate(
        &self,
        axes: &[Axis],
        values: &[AxisValue],
    ) -> Result<toml::Table, TemplateError> {
        let mut value = toml::Value::Table(self.table.clone());
        substitute(&mut value, axes, values);
        let toml::Value::Table(mut table) = value else {
            unreachable!("a table stays a table")
        };
        expand_blocks(&mut table)?;
        Ok(table)
    }
}

fn placeholder(s: &str) -> Option<&str> {
    s.strip_prefix('$')
}

fn collect_placeholders(
    path: &str,
    value: &toml::Value,
    out: &mut BTreeSet<(String, String)>,
) -> Result<(), TemplateError> {
    match value {
        toml::Value::String(s) => {
            if let Some(name) = placeholder(s) {
                out.insert((name.to_string(), path.to_string()));
            }
        }
        toml::Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                collect_placeholders(&format!("{path}[{i}]"), v, out)?;
            }
        }
        toml::Value::Table(t) => {
            for (k, v) in t {
                if k == "through" && !is_defect_entry(path) {
                    return Err((
                        format!("{path}.{k}"),
                        "`through` belongs in a [[scene.defect]] entry".into(),
                    ));
                }
                collect_placeholders(&format!("{path}.{k}"), v, out)?;
            }
        }
        _ => {}
    }
    Ok(())
}

fn is_defect_entry(path: &str) -> bool {
    path.strip_prefix("scene.defect[")
        .is_some_and(|rest| rest.ends_with(']') && !rest.contains('.'))
}

fn substitute(value: &mut toml::Value, axes: &[Axis], values: &[AxisValue]) {
    match value {
        toml::Value::String(s) => {
            if let Some(i) = placeholder(s).and_then(|n| axes.iter().position(|a| a.name == n)) {
                *value = values[i].to_toml();
            }
        }
        toml::Value::Array(items) => items.iter_mut().for_each(|v| substitute(v, axes, values)),
        toml::Value::Table(t) => t.iter_mut().for_each(|(_, v)| substitute(v, axes, values)),
        _ => {}
    }
}

/// The number of sites of the scene's chain (`chain.n` or `chain.sites`, else the default
/// 2 * 100 + 1), saturating; a value of the wrong type counts as the largest chain a scene
/// accepts (the scene's own validation reports it).
fn chain_sites(table: &toml::Table) -> i64 {
    const LARGEST: i64 = 10_000_001;
    let chain = table.get("chain").and_then(|c| c.as_table());
    match (
        chain.and_then(|c| c.get("n")),
        chain.and_then(|c| c.get("sites")),
    ) {
        (Some(toml::Value::Integer(n)), _) => n.saturating_mul(2).saturating_add(1).min(LARGEST),
        (None, Some(toml::Value::Array(ends))) => match ends.as_slice() {
            [toml::Value::Integer(a), toml::Value::Integer(b)] => {
                b.saturating_sub(*a).saturating_add(1).min(LARGEST)
            }
            _ => LARGEST,
        },
        (None, None) => 201,
        _ => LARGEST,
    }
}

/// Replaces each defect entry carrying `through` by one entry per site `site..=through`.
fn expand_blocks(table: &mut toml::Table) -> Result<(), TemplateError> {
    let sites = chain_sites(table);
    let Some(toml::Value::Array(entries)) = table.get_mut("defect") else {
        return Ok(());
    };
    let mut expanded = Vec::with_capacity(entries.len());
    for (i, entry) in entries.drain(..).enumerate() {
        let toml::Value::Table(mut defect) = entry else {
            expanded.push(entry);
            continue;
        };
        let Some(through) = defect.remove("through") else {
            expanded.push(toml::Value::Table(defect));
            continue;
        };
        let key = |k: &str| format!("scene.defect[{i}].{k}");
        let site = match defect.get("site") {
            Some(toml::Value::Integer(s)) => *s,
            _ => {
                return Err((
                    key("site"),
                    "a block with `through` needs an integer `site`".into(),
                ))
            }
        };
        let last = match through {
            toml::Value::Integer(l) if l >= site => l,
            _ => {
                return Err((
                    key("through"),
                    format!("expected an integer >= site ({site})"),
                ))
            }
        };
        // Never build more defects than the chain has sites (the scene would refuse them
        // anyway): `through = 99999999` must not allocate a hundred million tables first.
        let block = last.saturating_sub(site).saturating_add(1);
        let most = sites.min(crate::MAX_DEFECTS as i64);
        if block.saturating_add(expanded.len() as i64) > most {
            return Err((
                key("through"),
                format!(
                    "a block of {block} defects on a chain of {sites} sites (a scene may have at most {} defects)",
                    crate::MAX_DEFECTS
                ),
            ));
        }
        for s in site..=last {
            let mut one = defect.clone();
            one.insert("site".into(), toml::Value::Integer(s));
            expanded.push(toml::Value::Table(one));
        }
    }
    *entries = expanded;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes() -> Vec<Axis> {
        vec![
            Axis {
                name: "L".into(),
                values: vec![AxisValue::Int(2)],
            },
            Axis {
                name: "eps".into(),
                values: vec![AxisValue::Float(0.5)],
            },
        ]
    }

    fn template(text: &str) -> Result<Template, TemplateError> {
        Template::new(toml::from_str(text).unwrap(), &axes())
    }

    #[test]
    fn blocks_expand_and_placeholders_substitute() {
        let t = template("[[defect]]\nsite = 0\nthrough = \"$L\"\neps = \"$eps\"\n").unwrap();
        let scene = t
            .instantiate(&axes(), &[AxisValue::Int(2), AxisValue::Float(0.5)])
            .unwrap();
        let defects = scene["defect"].as_array().unwrap();
        assert_eq!(defects.len(), 3);
        assert_eq!(defects[2]["site"].as_integer(), Some(2));
        assert_eq!(defects[1]["eps"].as_float(), Some(0.5));
        assert!(defects[0].get("through").is_none());
    }

    #[test]
    fn unknown_placeholders_and_unused_axes_are_errors() {
        let (key, reason) =
            template("[[defect]]\nsite = 0\nthrough = \"$L\"\neps = \"$e\"").unwrap_err();
        assert_eq!(key, "scene.defect[0].eps");
        assert!(reason.contains("$e"));
        let (key, _) = template("[[defect]]\nsite = 0\neps = \"$eps\"").unwrap_err();
        assert_eq!(key, "axes.L");
    }

    #[test]
    fn through_outside_a_defect_and_backwards_blocks_are_errors() {
        let (key, _) = template("[run]\nthrough = \"$L\"\n[[defect]]\neps = \"$eps\"").unwrap_err();
        assert_eq!(key, "scene.run.through");
        let t = template("[[defect]]\nsite = 5\nthrough = \"$L\"\neps = \"$eps\"").unwrap();
        let (key, _) = t
            .instantiate(&axes(), &[AxisValue::Int(2), AxisValue::Float(0.5)])
            .unwrap_err();
        assert_eq!(key, "scene.defect[0].through");
    }
}
