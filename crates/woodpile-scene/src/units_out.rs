//! The units a scene's outputs are given in. The simulator works in the paper's scaled units
//! (`woodpile_sim::units`): t' = t V / L, u' = u / L, energies over M V². A `[physical]` scene's
//! outputs can be turned back into SI units (`woodpile simulate --si`, Python's
//! `units="SI"`): times in s, displacements in m, velocities in m/s, energies in J. Shares
//! (R, T, E_tr, S, D) have no unit and are never converted.

use serde_json::{json, Value};
use woodpile_sim::observe::{FractionSeries, SiteField, SpaceTimeField};

use crate::Scene;

/// What a table's `column_units` says of a column in the model's own scaled units.
pub const SCALED: &str = "scaled";

/// The units asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// The model's own (paper Eq. 1 rescaled): what every output is by default.
    Scaled,
    /// SI, for a `[physical]` scene.
    Si,
}

impl Units {
    /// `"scaled"` or `"SI"`.
    pub fn parse(text: &str) -> Result<Units, String> {
        match text {
            "scaled" => Ok(Units::Scaled),
            "SI" => Ok(Units::Si),
            other => Err(format!("expected \"scaled\" or \"SI\", got \"{other}\"")),
        }
    }

    /// The name the outputs give.
    pub fn name(self) -> &'static str {
        match self {
            Units::Scaled => "scaled",
            Units::Si => "SI",
        }
    }
}

/// What multiplies a scaled output to give it in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiFactors {
    /// Seconds per unit of scaled time (L / V).
    pub time_s: f64,
    /// Metres per unit of scaled displacement (L).
    pub length_m: f64,
    /// Metres per second per unit of scaled velocity (V).
    pub velocity_m_per_s: f64,
    /// Joules per unit of scaled energy (M V²).
    pub energy_j: f64,
}

impl SiFactors {
    /// The factors of `scene` for `units`: `None` for scaled outputs, an error naming the
    /// reason when SI is asked of a scene without `[physical]` scales.
    pub fn of(scene: &Scene, units: Units) -> Result<Option<SiFactors>, String> {
        if units == Units::Scaled {
            return Ok(None);
        }
        let Some(physical) = &scene.physical else {
            return Err(
                "SI outputs need a [physical] scene: a dimensionless scene has no scales to convert with"
                    .into(),
            );
        };
        let s = physical.scales;
        Ok(Some(SiFactors {
            time_s: s.time_s(),
            length_m: s.length_m(),
            velocity_m_per_s: s.velocity,
            energy_j: s.mass_kg * s.velocity * s.velocity,
        }))
    }

    /// `woodpile simulate`'s JSON object with its times (`t_end`, `dt`, `dt_requested`,
    /// `end_reached_at`) in s and its energies (`E_initial`, `E_final`) in J, and `units`
    /// saying so.
    pub fn report(&self, report: &mut Value) {
        let scale = |report: &mut Value, key: &str, factor: f64| {
            if let Some(x) = report.get(key).and_then(Value::as_f64) {
                report[key] = json!(x * factor);
            }
        };
        for key in ["t_end", "dt", "dt_requested", "end_reached_at"] {
            scale(report, key, self.time_s);
        }
        for key in ["E_initial", "E_final"] {
            scale(report, key, self.energy_j);
        }
        report["units"] = json!(Units::Si.name());
    }

    /// A space-time field with its times in s and its velocities in m/s.
    pub fn space_time(&self, field: &mut SpaceTimeField) {
        times(&mut field.t, self.time_s);
        for v in &mut field.velocity {
            *v = (f64::from(*v) * self.velocity_m_per_s) as f32;
        }
    }

    /// A recorded series with its times in s and, unless it is a kinetic series (whose `E` is a
    /// share of the impact energy), its energies in J.
    pub fn series(&self, series: &mut FractionSeries, kinetic: bool) {
        times(&mut series.t, self.time_s);
        if !kinetic {
            times(&mut series.energy, self.energy_j);
        }
    }

    /// A recorded field in SI units.
    pub fn field(&self, field: &mut SiteField) {
        times(&mut field.t, self.time_s);
        times(&mut field.displacement, self.length_m);
        times(&mut field.velocity, self.velocity_m_per_s);
        times(&mut field.energy, self.energy_j);
        times(&mut field.kinetic, self.energy_j);
        times(&mut field.resonator_displacement, self.length_m);
        times(&mut field.resonator_velocity, self.velocity_m_per_s);
    }
}

fn times(values: &mut [f64], factor: f64) {
    values.iter_mut().for_each(|x| *x *= factor);
}
