//! `series`: which fractions a run records at its samples, as the pipeline's sweep stages name
//! them: the shares of the total energy, or the kinetic energy over the impact energy (the
//! woodpile experiment's measure, paper Fig. 2).

use pyo3::prelude::*;
use woodpile_sim::observe::FractionSeries;
use woodpile_sim::run::Scenario;

use crate::SceneError;

/// What a `series` argument asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SeriesKind {
    /// Shares of the total energy.
    Energy,
    /// Kinetic energy over the impact energy.
    Kinetic,
}

impl SeriesKind {
    /// `"energy"` or `"kinetic"`; with `switch`, also `True` (energy) and `False` (none).
    pub(crate) fn parse(value: &Bound<'_, PyAny>, switch: bool) -> PyResult<Option<SeriesKind>> {
        if switch {
            if let Ok(on) = value.extract::<bool>() {
                return Ok(on.then_some(SeriesKind::Energy));
            }
        }
        match value.extract::<String>().as_deref() {
            Ok("energy") => Ok(Some(SeriesKind::Energy)),
            Ok("kinetic") => Ok(Some(SeriesKind::Kinetic)),
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

    /// An empty series of this kind for `scenario`, or why it cannot be recorded.
    pub(crate) fn recorder(self, scenario: &Scenario) -> Result<FractionSeries, String> {
        let (model, region) = (&scenario.model, scenario.region);
        match self {
            SeriesKind::Energy => Ok(FractionSeries::new(model, region)),
            SeriesKind::Kinetic => {
                let impact = scenario.impact_energy();
                if impact.is_nan() || impact <= 0.0 {
                    return Err(
                        "a kinetic series is divided by the impact energy, which is zero".into(),
                    );
                }
                Ok(FractionSeries::kinetic(model, region, impact))
            }
        }
    }
}
