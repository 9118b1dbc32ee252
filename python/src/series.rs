//! `series`: which fractions a run records at its samples, as the pipeline's sweep stages name
//! them: the shares of the total energy, or the kinetic energy over the impact energy (the
//! woodpile experiment's measure, paper Fig. 2).

use pyo3::prelude::*;
use woodpile_points::Shares;

use crate::SceneError;

/// The [`Shares`] a `series` argument asks for: `"energy"` or `"kinetic"`; with `switch`, also
/// `True` (energy) and `False` (none).
pub(crate) fn parse(value: &Bound<'_, PyAny>, switch: bool) -> PyResult<Option<Shares>> {
    if switch {
        if let Ok(on) = value.extract::<bool>() {
            return Ok(on.then_some(Shares::Energy));
        }
    }
    match value.extract::<String>().as_deref() {
        Ok("energy") => Ok(Some(Shares::Energy)),
        Ok("kinetic") => Ok(Some(Shares::Kinetic)),
        _ => {
            let allowed = match switch {
                true => "True, False, \"energy\" or \"kinetic\"",
                false => "\"energy\" or \"kinetic\"",
            };
            Err(SceneError::new_err(format!(
                "series: must be {allowed}, got {}",
                value.repr().map_or_else(|_| "?".into(), |r| r.to_string())
            )))
        }
    }
}
