//! The checks every section of a scene shares: an invalid key is `(key, reason)`, and numbers
//! are finite, positive or non-negative, or one of a list.

/// A key the model cannot accept, and why: the caller adds the file.
pub(crate) type Invalid = (String, String);

pub(crate) fn invalid(key: impl Into<String>, reason: impl Into<String>) -> Invalid {
    (key.into(), reason.into())
}

/// `x` for a message: as written for everyday sizes, in scientific notation when very small or
/// large (`1e-308`, not a 300-digit decimal).
pub(crate) fn number_text(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A velocity whose energy, v², is a normal double: neither zero by underflow (1e-308) nor
/// infinite (1e200), either of which leaves fractions of no energy.
pub(crate) fn velocity(key: &str, v: f64) -> Result<f64, Invalid> {
    let v = finite(key, v)?;
    if (v * v).is_normal() && (v * v) < 1e300 {
        Ok(v)
    } else {
        Err(invalid(
            key,
            format!("{} cannot carry an impact: its energy, v², is not a number double precision holds (use |v| from 1e-150 to 1e150)", number_text(v)),
        ))
    }
}

pub(crate) fn finite(key: &str, x: f64) -> Result<f64, Invalid> {
    within(key, x, x.is_finite(), "must be a finite number")
}

pub(crate) fn positive(key: &str, x: f64) -> Result<f64, Invalid> {
    within(key, x, x.is_finite() && x > 0.0, "must be finite and > 0")
}

pub(crate) fn non_negative(key: &str, x: f64) -> Result<f64, Invalid> {
    within(key, x, x.is_finite() && x >= 0.0, "must be finite and >= 0")
}

/// `x` where `ok`, else the reason `rule` with the value it got.
fn within(key: &str, x: f64, ok: bool, rule: &str) -> Result<f64, Invalid> {
    ok.then_some(x)
        .ok_or_else(|| invalid(key, format!("{rule}, got {}", number_text(x))))
}

/// Refuses a key of `table` (at `key`) that is not one of `known`: the reason says what the
/// table takes (`"a soft end has spring and damping"`).
pub(crate) fn only_keys(
    key: &str,
    table: &toml::Table,
    known: &[&str],
    takes: &str,
) -> Result<(), Invalid> {
    match table.keys().find(|k| !known.contains(&k.as_str())) {
        Some(other) => Err(invalid(
            format!("{key}.{other}"),
            format!("unknown key; {takes}"),
        )),
        None => Ok(()),
    }
}

/// `value`, which is required at `key`.
pub(crate) fn required<T>(key: &str, value: Option<T>) -> Result<T, Invalid> {
    value.ok_or_else(|| invalid(key, "is required"))
}

/// A TOML number (an integer is taken as a float).
pub(crate) fn number(key: &str, value: &toml::Value) -> Result<f64, Invalid> {
    match value {
        toml::Value::Float(x) => Ok(*x),
        toml::Value::Integer(i) => Ok(*i as f64),
        other => Err(invalid(
            key,
            format!("must be a number, got {}", other.type_str()),
        )),
    }
}

/// A number or a non-empty list of numbers (a pattern repeated along a segment), each > 0.
pub(crate) fn positive_pattern(key: &str, value: &toml::Value) -> Result<Vec<f64>, Invalid> {
    let values = match value {
        toml::Value::Array(items) if items.is_empty() => {
            return Err(invalid(
                key,
                "must be a number or a non-empty list of numbers",
            ))
        }
        toml::Value::Array(items) => items
            .iter()
            .enumerate()
            .map(|(i, v)| number(&format!("{key}[{i}]"), v))
            .collect::<Result<Vec<_>, _>>()?,
        v => vec![number(key, v)?],
    };
    for (i, &x) in values.iter().enumerate() {
        let at = match values.len() {
            1 => key.to_string(),
            _ => format!("{key}[{i}]"),
        };
        positive(&at, x)?;
    }
    Ok(values)
}

/// Rejects the first of `keys` that is present: those keys do not belong in this kind of scene.
pub(crate) fn reject_present(
    key: &dyn Fn(&str) -> String,
    keys: &[(&str, bool)],
    reason: &str,
) -> Result<(), Invalid> {
    match keys.iter().find(|(_, present)| *present) {
        Some((name, _)) => Err(invalid(key(name), reason)),
        None => Ok(()),
    }
}
