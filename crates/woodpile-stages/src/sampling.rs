//! Scenes drawn from the pipeline's own sweeps by a fixed seed: the scenes of accuracy surveys
//! and of the tests that `auto` meets its tolerance on scenes no calibration chose. The grids
//! are read from the stage files, so a survey follows the sweeps as they are defined.

use woodpile_sim::simulation::Scenario;
use woodpile_sim::testing::Lcg;

use crate::grid::AxisValue;
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::pipeline::Pipeline;

use crate::sweep::Sweep;

/// The sweeps a survey draws from, with their labels: one of each kind of the paper's scenes.
pub const SURVEY_SWEEPS: &[(&str, &str)] = &[
    ("f4_sweep", "F4"),
    ("f5_sweep", "F5"),
    ("f6_sweep", "F6"),
    ("f7_coarse_sweep", "F7 coarse"),
    ("f7_fine_sweep", "F7 fine"),
];

/// `per_sweep` scenes of each of [`SURVEY_SWEEPS`], each axis value drawn uniformly from the
/// sweep's grid, in rounds (one scene of every sweep per round), labelled by the sweep and the
/// values. The scenario is the sweep's own (its run settings); callers set the method and
/// accuracy they survey.
pub fn sampled_sweep_scenes(
    pipeline: &Pipeline,
    per_sweep: usize,
) -> Result<Vec<(String, Scenario)>> {
    sampled_scenes(pipeline, SURVEY_SWEEPS, per_sweep, 20_261_123)
}

/// [`sampled_sweep_scenes`] from the given `(stage, label)` sweeps with the given `seed`.
pub fn sampled_scenes(
    pipeline: &Pipeline,
    sweeps: &[(&str, &str)],
    per_sweep: usize,
    seed: u64,
) -> Result<Vec<(String, Scenario)>> {
    drawn(pipeline, sweeps, per_sweep, seed, |sweep, values| {
        Ok(sweep.scene_with(values, None)?.scenario)
    })
}

/// The scenes of [`sampled_scenes`] as scene files' tables (what `woodpile simulate` reads),
/// for benchmarks that run a binary rather than the library.
pub fn sampled_scene_tables(
    pipeline: &Pipeline,
    sweeps: &[(&str, &str)],
    per_sweep: usize,
    seed: u64,
) -> Result<Vec<(String, toml::Table)>> {
    drawn(pipeline, sweeps, per_sweep, seed, |sweep, values| {
        sweep.table_with(values, None)
    })
}

/// `per_sweep` rounds of one point of each sweep, drawn with `seed`, each given to `make` and
/// labelled by the sweep and the values.
fn drawn<T>(
    pipeline: &Pipeline,
    sweeps: &[(&str, &str)],
    per_sweep: usize,
    seed: u64,
    make: impl Fn(&Sweep, &[AxisValue]) -> Result<T>,
) -> Result<Vec<(String, T)>> {
    let mut rng = Lcg(seed);
    let mut scenes = Vec::with_capacity(per_sweep * sweeps.len());
    for _ in 0..per_sweep {
        for &(stage, label) in sweeps {
            let sweep = pipeline
                .stage(stage)
                .ok()
                .and_then(|s| s.get::<Sweep>())
                .ok_or_else(|| {
                    PipelineError::stage(stage, "a survey draws from this sweep, which is missing")
                })?;
            let values: Vec<_> = sweep
                .grid
                .axes
                .iter()
                .map(|a| rng.pick(&a.values))
                .collect();
            let named = woodpile_scene::grid::named_values(&sweep.grid.axes, &values, "=");
            scenes.push((
                format!("{label} {}", named.join(" ")),
                make(sweep, &values)?,
            ));
        }
    }
    Ok(scenes)
}
