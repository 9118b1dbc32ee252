//! `kind = "spacetime"`: site velocities over time for a few scenes, as the paper's space-time
//! maps show them (Figs. 3 and 8). The scene grid is a sweep's (`[axes]`, `[scene]` with
//! placeholders); the field is sampled every `run.sample_every` and kept for the paper sites
//! `field.sites = [lo, hi]`, so files and figures stay small.
//!
//! ```toml
//! kind = "spacetime"
//! [axes]
//! L = [2, 6]
//! [scene]
//! run = { t_end = 150.0, method = "auto", tolerance = 1e-6, sample_every = 1.0 }
//! [[scene.defect]]
//! site = 0
//! through = "$L"
//! eps = 10.0
//! [field]
//! sites = [-50, 50]
//! ```
//!
//! Output: one row per point, sample and site: `point`, the axes, `t`, `site` (paper
//! numbering), `velocity`; in the model's scaled units, or with `units = "SI"` (scenes with
//! `[physical]`) `t` in s and `velocity` in m/s. The manifest's `column_units` says which, and
//! a figure that labels a scaled axis in µs or m/s is refused. A scene whose simulation fails stops the stage with its reason.
//!
//! Instead of a grid, `design = "stage"` (with `inputs = ["stage"]` and `field.sites`) maps
//! the best scene a `design` or `optimize` stage found, from its `results/<stage>.best.toml`.

use rayon::prelude::*;
use serde_json::json;
use woodpile_scene::units_out::{SiFactors, Units};
use woodpile_scene::Scene;
use woodpile_sim::integrate::MethodChoice;
use woodpile_sim::observe::SpaceTimeField;
use woodpile_sim::simulation::simulate;

use crate::grid::{Axis, AxisValue};
use crate::sweep::Sweep;
use crate::table_units;
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{no_inputs, wrong_inputs, Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::Columns;
use woodpile_pipeline::Output;

/// A parsed spacetime stage.
#[derive(Debug, Clone)]
pub struct SpaceTime {
    /// The scenes: a grid, or the best design of a `design` stage.
    pub source: Source,
    /// Paper sites kept, inclusive (for a design: checked when its scene is known).
    pub sites: [i64; 2],
    /// `units = "SI"`: `t` in s and `velocity` in m/s (physical scenes only); else the
    /// model's scaled units.
    pub units: Units,
}

/// Where a spacetime stage's scenes come from.
#[derive(Debug, Clone)]
pub enum Source {
    /// A sweep's grid of scenes (`[axes]`, `[scene]`).
    Grid(Sweep),
    /// `design = "stage"`: the best design that stage found (its `<stage>.best.toml`), which
    /// must be the spacetime stage's one input.
    Design(String),
}

/// Most field values a spacetime stage may keep as table rows (about 40 bytes each in memory).
const MAX_FIELD_ROWS: u64 = 20_000_000;
/// Most velocities its scenes may record in all, before the field is cut to its sites (f32).
const MAX_RECORDED: u64 = 250_000_000;

/// Refuses a field too large to hold: `count` scenes like `scene`, kept on `sites`.
fn field_size(scene: &Scene, count: usize, sites: [i64; 2]) -> std::result::Result<(), String> {
    let s = &scene.scenario;
    let samples = woodpile_sim::integrate::intervals(s.t_end, s.sample_every) + 1;
    let width = (sites[1] - sites[0] + 1).max(0) as u64;
    let rows = (count as u64).saturating_mul(samples).saturating_mul(width);
    let recorded = (count as u64)
        .saturating_mul(samples)
        .saturating_mul(s.model.n_sites() as u64);
    if rows > MAX_FIELD_ROWS || recorded > MAX_RECORDED {
        return Err(format!(
            "{count} scene(s) of {samples} samples on {width} sites ({} of the chain's {}) would keep {rows} field values, more than the {MAX_FIELD_ROWS} a spacetime stage may keep; keep fewer sites or sample less often",
            width,
            s.model.n_sites()
        ));
    }
    Ok(())
}

impl SpaceTime {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<SpaceTime> {
        let units = table_units::parse(fields)?;
        if let Some(design) = fields.optional::<String>("design")? {
            let table: toml::Table = fields.optional("field")?.unwrap_or_default();
            let mut f = fields.nested("field", table);
            let sites = field_sites(&mut f)?.ok_or_else(|| {
                f.error("sites", "is required with `design`: [lo, hi] paper sites")
            })?;
            f.finish()?;
            return Ok(SpaceTime {
                source: Source::Design(design),
                sites,
                units,
            });
        }
        let sweep = Sweep::parse(fields)?;
        let table: toml::Table = fields.optional("field")?.unwrap_or_default();
        let mut f = fields.nested("field", table);
        let sites = field_sites(&mut f)?;
        f.finish()?;
        let scene = sweep.scene_at(0)?;
        let (first, last) = (scene.first_site, scene.last_site);
        let sites = sites.unwrap_or([first, last]);
        if sites[0] < first || sites[1] > last {
            return Err(fields.error("field.sites", format!("sites must lie in {first}..{last}")));
        }
        // The largest scene of the grid (its last point) bounds every point's field.
        let largest = sweep.scene_at(sweep.count() - 1)?;
        field_size(&largest, sweep.count(), sites)
            .map_err(|reason| fields.error("field.sites", reason))?;
        SiFactors::of(&scene, units).map_err(|reason| fields.error("units", reason))?;
        Ok(SpaceTime {
            source: Source::Grid(sweep),
            sites,
            units,
        })
    }

    /// Simulates the stage's scenes and keeps each one's field on the stage's sites.
    pub(crate) fn compute(&self, ctx: &Context<'_>) -> Result<Output> {
        let stage = ctx.name();
        let (scenes, axes) = self.scenes(ctx)?;
        // The accuracy asked for (a scene's tolerance, or its fixed step's) and the largest
        // error estimate `auto` reported, for the manifest.
        let tolerance = scenes.first().and_then(|(_, scene)| {
            let s = &scene.scenario;
            let asked = s.method == MethodChoice::Auto || s.accuracy.tolerance_explicit;
            asked.then_some(s.accuracy.tolerance)
        });
        let fields: Vec<SimulatedField> = scenes
            .into_par_iter()
            .enumerate()
            .map(|(i, (values, scene))| {
                let model = &scene.scenario.model;
                let mut field = SpaceTimeField::new(model, 1, 1);
                let outcome = simulate(&scene.scenario, &mut field).map_err(|e| {
                    PipelineError::stage(stage, format!("point {i}: simulation failed: {e}"))
                })?;
                let si = SiFactors::of(&scene, self.units)
                    .map_err(|reason| PipelineError::stage(stage, format!("units: {reason}")))?;
                if let Some(si) = si {
                    si.space_time(&mut field);
                }
                Ok((values, field, scene.first_site, outcome.error_estimate))
            })
            .collect::<Result<_>>()?;
        let max_error_estimate = fields
            .iter()
            .filter_map(|f| f.3)
            .fold(None, |m: Option<f64>, e| Some(m.map_or(e, |m| m.max(e))));
        let (columns, points) = self.columns(&fields, axes);
        let simulated = fields.len();
        let mut summary = json!({
            "points": points,
            "sites": self.sites,
            "tolerance": tolerance,
            "max_error_estimate": max_error_estimate,
        });
        // What a figure may call its axes: seconds and metres per second, or the model's own.
        table_units::declare(&mut summary, self.units, &[("t", "s"), ("velocity", "m/s")]);
        Ok(Output::table(columns.into_frame()?, summary).with_simulated(simulated))
    }

    /// The scenes to map, each with its axis values, and the axes: the grid's, or a design
    /// stage's best scene (whose field is bounded only now that it is known).
    fn scenes(&self, ctx: &Context<'_>) -> Result<(Vec<Mapped>, &[Axis])> {
        let stage = ctx.name();
        Ok(match &self.source {
            Source::Grid(sweep) => (
                (0..sweep.count())
                    .map(|i| Ok((sweep.values(i), sweep.scene_at(i)?)))
                    .collect::<Result<_>>()?,
                &sweep.grid.axes,
            ),
            Source::Design(design) => {
                let path = ctx.best_scene(design)?;
                let scene = woodpile_scene::load(&path)
                    .map_err(|e| PipelineError::stage(stage, e.to_string()))?;
                if self.sites[0] < scene.first_site || self.sites[1] > scene.last_site {
                    return Err(PipelineError::stage(
                        stage,
                        format!(
                            "field.sites must lie in {}..{}",
                            scene.first_site, scene.last_site
                        ),
                    ));
                }
                // A design's scene is known only now: bound its field before simulating it.
                field_size(&scene, 1, self.sites).map_err(|reason| {
                    PipelineError::stage(stage, format!("field.sites: {reason}"))
                })?;
                (vec![(Vec::new(), scene)], &[])
            }
        })
    }

    /// The table's columns from the simulated `fields` (each with its axis values and first
    /// paper site), kept on the stage's sites, and how many points there were.
    fn columns(&self, fields: &[SimulatedField], axes: &[Axis]) -> (Columns, usize) {
        let mut point = Vec::new();
        let points = fields.len();
        let mut axis_values: Vec<Vec<AxisValue>> = vec![Vec::new(); axes.len()];
        let (mut t, mut site, mut velocity) = (Vec::new(), Vec::new(), Vec::new());
        for (i, (values, field, first, _)) in fields.iter().enumerate() {
            let n_sites = field.sites.len();
            for (k, &time) in field.t.iter().enumerate() {
                for (j, &s) in field.sites.iter().enumerate() {
                    let paper = s as i64 + *first;
                    if paper < self.sites[0] || paper > self.sites[1] {
                        continue;
                    }
                    point.push(Some(i as i64));
                    for (column, v) in axis_values.iter_mut().zip(values) {
                        column.push(*v);
                    }
                    t.push(Some(time));
                    site.push(Some(paper));
                    velocity.push(Some(f64::from(field.velocity[k * n_sites + j])));
                }
            }
        }
        let mut columns = Columns::new();
        columns.i64("point", point);
        for (axis, values) in axes.iter().zip(axis_values) {
            if axis.is_integer() {
                columns.i64(
                    &axis.name,
                    values.iter().map(|v| Some(v.as_f64() as i64)).collect(),
                );
            } else {
                columns.f64(
                    &axis.name,
                    values.iter().map(|v| Some(v.as_f64())).collect(),
                );
            }
        }
        columns
            .f64("t", t)
            .i64("site", site)
            .f64("velocity", velocity);
        (columns, points)
    }
}

/// A scene to map, with its axis values.
type Mapped = (Vec<AxisValue>, Scene);

/// One simulated scene's field: its axis values, the field, its first paper site and `auto`'s
/// error estimate.
type SimulatedField = (Vec<AxisValue>, SpaceTimeField, i64, Option<f64>);

/// `field.sites = [lo, hi]`, if given.
fn field_sites(f: &mut Fields<'_>) -> Result<Option<[i64; 2]>> {
    match f.take("sites") {
        None => Ok(None),
        Some(v) => {
            let pair: Option<Vec<i64>> = v
                .as_array()
                .map(|a| a.iter().filter_map(|x| x.as_integer()).collect());
            match pair.as_deref() {
                Some(&[lo, hi]) if lo <= hi => Ok(Some([lo, hi])),
                _ => Err(f.error("sites", "expected [lo, hi] paper sites with lo <= hi")),
            }
        }
    }
}

impl Kind for SpaceTime {
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck {
        let Source::Design(design) = &self.source else {
            return no_inputs(stage);
        };
        let searches = ["design", "optimize"];
        match stage.inputs.as_slice() {
            [input] if input == design && searches.contains(&inputs.kind_of(input)) => Ok(()),
            [input] if input == design => wrong_inputs(format!(
                "`design = \"{design}\"` names a {} stage; a spacetime stage maps the best scene of a design or optimize stage",
                inputs.kind_of(input)
            )),
            _ => wrong_inputs(format!(
                "a spacetime stage of `design = \"{design}\"` maps that stage's best scene, so it must be its one input: inputs = [\"{design}\"]"
            )),
        }
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        self.compute(ctx)
    }
}
