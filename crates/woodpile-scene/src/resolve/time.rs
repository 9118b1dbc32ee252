//! Times in a `[physical]` scene may be written with a unit, `t_end = "1.5 ms"`: they are
//! seconds, turned here into the model's scaled time (t' = t V / L, `physical.time_scale_s`).
//! A bare number keeps the meaning it always had, scaled time, so no scene changes.

use super::check::{invalid, Invalid};
use super::physical::Si;
use crate::raw::Time;

/// The units a time may carry, and seconds per unit.
const UNITS: [(&str, f64); 5] = [
    ("s", 1.0),
    ("ms", 1e-3),
    ("us", 1e-6),
    ("µs", 1e-6),
    ("ns", 1e-9),
];

/// Seconds in `text`, a number and a time unit (`"1.5 ms"`, `"2us"`, `"40 µs"`).
pub fn seconds(text: &str) -> Result<f64, String> {
    let text = text.trim();
    let split = text
        .char_indices()
        .find(|&(_, c)| c.is_alphabetic() && c != 'e' && c != 'E')
        .map_or(text.len(), |(i, _)| i);
    let (number, unit) = (text[..split].trim(), text[split..].trim());
    let names: Vec<&str> = UNITS.iter().map(|(name, _)| *name).collect();
    let Some(&(_, scale)) = UNITS.iter().find(|(name, _)| *name == unit) else {
        return Err(match unit {
            "" => format!(
                "`{text}` has no unit: write a time such as \"1.5 ms\" ({})",
                names.join(", ")
            ),
            _ => format!("`{unit}` is not a unit of time ({})", names.join(", ")),
        });
    };
    let value: f64 = number
        .parse()
        .map_err(|_| format!("`{text}`: `{number}` is not a number"))?;
    Ok(value * scale)
}

/// `value` in the model's scaled time: a number as it is, text with a unit converted with an
/// SI scene's time scale (text in a scaled scene has no scale to convert with).
pub(crate) fn scaled(key: &str, value: &Time, si: Option<&Si>) -> Result<f64, Invalid> {
    match value {
        Time::Scaled(x) => Ok(*x),
        Time::Text(text) => {
            let Some(si) = si else {
                return Err(invalid(
                    key,
                    format!("`{text}`: a time with a unit needs a [physical] scene, whose time scale converts it; give a number in scaled time"),
                ));
            };
            let s = seconds(text).map_err(|reason| invalid(key, reason))?;
            Ok(s / si.scales.time_s())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::seconds;

    #[test]
    fn times_are_read_in_every_unit() {
        let close = |text: &str, s: f64| (seconds(text).unwrap() - s).abs() <= 1e-15 * s;
        assert!(close("1.5 ms", 1.5e-3));
        assert!(close("2us", 2e-6));
        assert!(close("40 µs", 40e-6));
        assert!(close("3e2 ns", 3e-7));
        assert!(close("0.25 s", 0.25));
        assert!(seconds("1.5 kg")
            .unwrap_err()
            .contains("not a unit of time"));
        assert!(seconds("1.5").unwrap_err().contains("no unit"));
        assert!(seconds("1.2.3 ms").unwrap_err().contains("not a number"));
    }
}
