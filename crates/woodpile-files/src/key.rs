//! Cache keys: a blake3 hash of a canonical JSON text, never `std::hash` (which may change
//! between Rust versions and would silently invalidate, or worse alias, cached results).
//!
//! Canonical means: object keys sorted (serde_json's map is a `BTreeMap` here), numbers in
//! their shortest round-trip form, no whitespace. What a key hashes is its owner's business:
//! a stage hashes its file's parameters, a point its resolved scene (`woodpile_points::canonical`).

use std::collections::BTreeMap;
use std::fmt;

use serde_json::{json, Map, Value};

/// The version every cache key includes. Bump [`NUMERICS_REVISION`] whenever a change can alter
/// a computed number without changing a stage file: every cached result then goes stale.
pub fn code_version() -> String {
    format!(
        "woodpile {} r{NUMERICS_REVISION}",
        env!("CARGO_PKG_VERSION")
    )
}

/// Revision of the numerics and reductions (see [`code_version`]).
pub const NUMERICS_REVISION: u32 = 17;

/// A 256-bit content hash, shown as 64 lowercase hex digits.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Key(String);

impl Key {
    /// The key of `value`'s canonical JSON text.
    pub fn of(value: &Value) -> Key {
        let text = value.to_string();
        Key(blake3::hash(text.as_bytes()).to_hex().to_string())
    }

    /// Wraps a stored hex key (as read back from a manifest).
    pub fn from_hex(hex: &str) -> Key {
        Key(hex.to_string())
    }

    /// The hex digits.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// The first 12 hex digits, for messages.
    pub fn short(&self) -> &str {
        &self.0[..12.min(self.0.len())]
    }
}

impl fmt::Display for Key {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// A TOML value as JSON (for hashing and for manifests). TOML datetimes become strings.
pub fn toml_to_json(value: &toml::Value) -> Value {
    match value {
        toml::Value::String(s) => Value::String(s.clone()),
        toml::Value::Integer(i) => json!(i),
        toml::Value::Float(x) => json!(x),
        toml::Value::Boolean(b) => json!(b),
        toml::Value::Datetime(d) => Value::String(d.to_string()),
        toml::Value::Array(items) => Value::Array(items.iter().map(toml_to_json).collect()),
        toml::Value::Table(table) => Value::Object(
            table
                .iter()
                .map(|(k, v)| (k.clone(), toml_to_json(v)))
                .collect::<Map<_, _>>(),
        ),
    }
}

/// The dotted paths whose values differ between `old` and `new` (added, removed or changed),
/// each as `path: old -> new`. A list of numbers or strings that changed in its length or in
/// more than three places is summarised in one line (`axes.eps: 50 values -> 150 values, 100
/// added`) rather than listed value by value.
pub fn changed_paths(old: &Value, new: &Value) -> Vec<String> {
    let mut out = Vec::new();
    changes("", Some(old), Some(new), &mut out);
    out
}

fn changes(path: &str, a: Option<&Value>, b: Option<&Value>, out: &mut Vec<String>) {
    let child = |key: &str| {
        if path.is_empty() {
            key.to_string()
        } else {
            format!("{path}.{key}")
        }
    };
    match (a, b) {
        (Some(Value::Object(x)), Some(Value::Object(y))) => {
            let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
            keys.sort();
            keys.dedup();
            for k in keys {
                changes(&child(k), x.get(k), y.get(k), out);
            }
        }
        (Some(Value::Array(x)), Some(Value::Array(y))) => {
            let scalars = |v: &[Value]| v.iter().all(|e| !e.is_array() && !e.is_object());
            let differing = (0..x.len().max(y.len()))
                .filter(|&i| x.get(i) != y.get(i))
                .count();
            if scalars(x) && scalars(y) && (x.len() != y.len() || differing > 3) {
                out.push(format!("{path}: {}", list_change(x, y)));
            } else {
                for i in 0..x.len().max(y.len()) {
                    changes(&format!("{path}[{i}]"), x.get(i), y.get(i), out);
                }
            }
        }
        (a, b) if a != b => {
            let show = |v: Option<&Value>| v.map_or_else(|| "(absent)".into(), Value::to_string);
            out.push(format!("{path}: {} -> {}", show(a), show(b)));
        }
        _ => {}
    }
}

/// `50 values -> 150 values, 100 added, 0 removed` for two lists of scalars.
fn list_change(old: &[Value], new: &[Value]) -> String {
    let count = |v: &[Value]| {
        let mut m: BTreeMap<String, i64> = BTreeMap::new();
        for e in v {
            *m.entry(e.to_string()).or_default() += 1;
        }
        m
    };
    let (a, b) = (count(old), count(new));
    let only = |x: &BTreeMap<String, i64>, y: &BTreeMap<String, i64>| -> i64 {
        x.iter()
            .map(|(k, n)| (n - y.get(k).copied().unwrap_or(0)).max(0))
            .sum()
    };
    let (added, removed) = (only(&b, &a), only(&a, &b));
    let mut text = format!("{} values -> {} values", old.len(), new.len());
    if added > 0 {
        text += &format!(", {added} added");
    }
    if removed > 0 {
        text += &format!(", {removed} removed");
    }
    if added == 0 && removed == 0 {
        text += ", reordered";
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_ignores_key_order_and_sees_every_value() {
        let a: Value = serde_json::from_str(r#"{"b": 1, "a": [1.5, "x"]}"#).unwrap();
        let b: Value = serde_json::from_str(r#"{"a": [1.5, "x"], "b": 1}"#).unwrap();
        let c: Value = serde_json::from_str(r#"{"a": [1.5, "x"], "b": 2}"#).unwrap();
        assert_eq!(Key::of(&a), Key::of(&b));
        assert_ne!(Key::of(&a), Key::of(&c));
        assert_eq!(Key::of(&a).as_str().len(), 64);
    }

    #[test]
    fn changed_paths_names_each_difference() {
        let old = json!({"axes": {"L": [0, 2]}, "scene": {"run": {"tolerance": 1e-6}}});
        let new = json!({"axes": {"L": [0, 3]}, "scene": {"run": {"tolerance": 1e-6, "dt": 0.1}}});
        assert_eq!(
            changed_paths(&old, &new),
            vec![
                "axes.L[1]: 2 -> 3".to_string(),
                "scene.run.dt: (absent) -> 0.1".to_string()
            ]
        );
    }

    #[test]
    fn long_list_changes_are_summarised() {
        let old = json!({"axes": {"eps": (1..=50).collect::<Vec<_>>()}, "at": 150.0});
        let new = json!({"axes": {"eps": (1..=150).collect::<Vec<_>>()}, "at": 120.0});
        assert_eq!(
            changed_paths(&old, &new),
            [
                "at: 150.0 -> 120.0",
                "axes.eps: 50 values -> 150 values, 100 added"
            ]
        );
        let short = changed_paths(&json!({"L": [0, 2, 5]}), &json!({"L": [0, 3, 5]}));
        assert_eq!(short, ["L[1]: 2 -> 3"]);
    }
}
