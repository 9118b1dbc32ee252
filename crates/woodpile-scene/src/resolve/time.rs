//! Times in a `[physical]` scene may be written with a unit, `t_end = "1.5 ms"`: they are
//! seconds, turned here into the model's scaled time (t' = t V / L, `physical.time_scale_s`).
//! A bare number keeps the meaning it always had, scaled time, so no scene changes.

use super::check::{invalid, Invalid};
use super::physical::Si;
use crate::raw::Time;

/// Seconds in `text`, a number and a time unit (`"1.5 ms"`, `"2us"`, `"40 µs"`).
pub fn seconds(text: &str) -> Result<f64, String> {
    crate::quantity::parse(text, "time")
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
