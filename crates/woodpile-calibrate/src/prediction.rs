//! What a scene predicts a probe would record: the simulated velocity of each traced rod at
//! each traced time, in m/s.

use woodpile_scene::Scene;
use woodpile_sim::integrate::{Method, MethodChoice};
use woodpile_sim::observe::SiteField;
use woodpile_sim::simulation::{check_field_size, simulate, Outcome};

use crate::trace::Trace;

/// Samples the run takes per gap of the probe's: a row between two samples is read by linear
/// interpolation, whose error is about (ω h)²/8 of the amplitude at a spacing h; at an eighth
/// of a 10 µs probe's spacing and a 50 µs period that is 0.3%, and 0.01% at 2 µs.
pub const SAMPLES_PER_SPACING: f64 = 8.0;

/// How the prediction steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stepping {
    /// The scene's own `run.method` and tolerance (`auto`: verified).
    AsWritten,
    /// One method at one fixed step (scaled time): the same step sequence for every parameter
    /// that leaves the time scale alone, so that the residuals are smooth in the parameters.
    Fixed {
        /// The method.
        method: Method,
        /// Its step, in the model's scaled time.
        dt: f64,
    },
}

/// Why a scene without `[physical]` cannot be fitted to a measured trace.
pub(crate) const NOT_PHYSICAL: &str =
    "the scene has no [physical] table: a measured trace is in s and m/s, so its scene must be in SI";

/// The velocities `scene` predicts at `trace`'s rows, and the run that made them. The run is
/// sampled [`SAMPLES_PER_SPACING`] times per `trace.spacing()` up to the trace's end, and each
/// row is read by linear interpolation between the two samples around it.
pub fn predict(
    scene: &Scene,
    trace: &Trace,
    stepping: Stepping,
) -> Result<(Vec<f64>, Outcome), String> {
    let physical = scene.physical.as_ref().ok_or(NOT_PHYSICAL)?;
    let (time_s, speed) = (physical.scales.time_s(), physical.scales.velocity);
    let (lo, hi) = trace.rods();
    let (first, last) = scene
        .site_range(lo, hi)
        .map_err(|reason| format!("the trace's rods {lo}..{hi}: {reason}"))?;
    let spacing = trace.spacing() / time_s / SAMPLES_PER_SPACING;
    let mut scenario = scene.scenario.clone();
    scenario.sample_every = spacing;
    scenario.t_end = (trace.end() / time_s / spacing).ceil().max(1.0) * spacing;
    if let Stepping::Fixed { method, dt } = stepping {
        scenario.method = MethodChoice::Named(method);
        scenario.accuracy.dt = Some(dt);
    }
    let width = last - first + 1;
    check_field_size(&scenario, width)?;
    let mut field = SiteField::new(&scenario.model, first, last);
    let outcome = simulate(&scenario, &mut field).map_err(|e| e.to_string())?;
    let samples = field.t.len();
    let at = |sample: usize, site: usize| field.velocity[sample.min(samples - 1) * width + site];
    let predicted = trace
        .t
        .iter()
        .zip(&trace.rod)
        .map(|(&t, &rod)| {
            let k = t / time_s / spacing;
            let (below, frac) = (k.floor(), k - k.floor());
            let site = (rod - scene.first_site) as usize - first;
            let below = below as usize;
            speed * ((1.0 - frac) * at(below, site) + frac * at(below + 1, site))
        })
        .collect();
    Ok((predicted, outcome))
}
