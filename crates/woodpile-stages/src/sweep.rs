//! `kind = "sweep"`: simulate every scene of a parameter grid and output its fraction time
//! series, one row per point and sample.
//!
//! ```toml
//! kind = "sweep"
//! [axes]                                   # optional: none means a single scene
//! L = [0, 2, 5, 6]
//! eps = { from = 0.1, to = 60.0, step = 0.1 }   # or { from = 0.1, to = 100.0, count = 31, log = true }
//! [scene]                                  # a scene file, with "$axis" placeholders
//! run = { t_end = 150.0, method = "auto", tolerance = 1e-6, sample_every = 1.0 }
//! [[scene.defect]]
//! site = 0
//! through = "$L"                           # defects on sites 0..=L
//! eps = "$eps"
//! ```
//!
//! An optional `units = "SI"` (scenes with `[physical]` only) gives the table's times (`t`,
//! `dt`, `end_reached_at`) in s and its energy `E` in J, each point by its own scales; the
//! manifest's `column_units` says which units the table is in, and `render` takes its axis
//! units from it.
//!
//! An optional `series = "kinetic"` records kinetic-energy shares divided by the impact energy
//! (what the woodpile experiment measures, paper Fig. 2 c, f) instead of total-energy fractions;
//! the columns keep their names (`R`, `T`, `E_tr`, `E`). Scenes with a `[striker]` add the
//! striker's share `S` after `E_tr` (R + T + E_tr + S = 1). Every row says `end_reached_at`,
//! when the point's wave first reached an end of the chain (null: not before `t_end`): from
//! then on its R and T include what that end sent back.
//!
//! Points are cached one by one in the [`PointStore`] under the key of their resolved scene,
//! so a sweep resumes after a kill and sweeps that share scenes share the work. Points are
//! simulated in parallel (rayon) and assembled in grid order: the output is bitwise the same
//! for any number of threads. A point whose simulation fails gets one row with null fractions
//! and the reason in `failure`: a failure is reported, never written as a number.

use std::collections::HashMap;

use polars::prelude::DataFrame;
use rayon::prelude::*;
use serde_json::{json, Value};
use woodpile_scene::columns;
use woodpile_scene::sweep_grid::{GridError, SceneGrid};
use woodpile_scene::units_out::{SiFactors, Units};
use woodpile_scene::Scene;
use woodpile_sim::integrate::MethodChoice;
use woodpile_sim::simulation::batch_size;
use woodpile_sim::ShareSet;

use crate::grid::{parse_axes, Axis, AxisValue};
use crate::table_units;
use woodpile_files::key::Key;
use woodpile_files::{PointStats, PointsDir};
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::events::Events;
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{Context, Kind, PointGrid, PointsAt};
use woodpile_pipeline::table::rows_frame;
use woodpile_pipeline::Output;
use woodpile_points::rows::{SweepPoint, SweepShape};
use woodpile_points::{point_key, Fetched, PointResult, PointStore, Shares};
use woodpile_scene::template::Template;

/// A parsed sweep stage.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The grid of scenes: the axes, sorted by name (the last varies fastest), and the
    /// template.
    pub grid: SceneGrid,
    /// Which energy the recorded fractions split.
    pub series: Shares,
    /// The shares its table has: `S` when its scenes have a striker, `D` when its scene
    /// declares dissipation (on every row, a point that loses nothing showing 0).
    shares: ShareSet,
    /// The units of its table: scaled, or SI by each point's own scales.
    units: Units,
}

impl Sweep {
    /// A `kind = "sweep"` stage: the grid ([`Sweep::parse`]) and the units of its table.
    pub(crate) fn parse_stage(fields: &mut Fields<'_>) -> Result<Sweep> {
        let units = table_units::parse(fields)?;
        Sweep::parse(fields)?
            .in_units(units)
            .map_err(|reason| fields.error("units", reason))
    }

    /// The sweep with its table in `units`: SI needs `[physical]` scenes.
    pub(crate) fn in_units(self, units: Units) -> std::result::Result<Sweep, String> {
        let scene = self.scene_at(0).map_err(|e| e.to_string())?;
        SiFactors::of(&scene, units)?;
        Ok(Sweep { units, ..self })
    }

    /// The grid of a stage over scenes: its `axes`, `series` and `scene`.
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Sweep> {
        let axes = match fields.optional::<toml::Table>("axes")? {
            Some(table) => parse_axes(fields.nested("axes", table))?,
            None => Vec::new(),
        };
        let series = fields.choice(
            "series",
            &[("energy", Shares::Energy), ("kinetic", Shares::Kinetic)],
            Some(Shares::Energy),
        )?;
        let scene: toml::Table = fields.required("scene")?;
        Sweep::over(axes, series, scene, fields.file())
    }

    /// The sweep of `scene` (a scene table with "$axis" placeholders, from `file`) over
    /// `axes`, checked at the corners of the grid and for the memory its points will hold
    /// ([`SceneGrid::checked`]).
    pub fn over(
        axes: Vec<Axis>,
        series: Shares,
        scene: toml::Table,
        file: &std::path::Path,
    ) -> Result<Sweep> {
        let template =
            Template::new(scene, &axes).map_err(|(key, reason)| PipelineError::Definition {
                file: file.to_path_buf(),
                key,
                reason,
                source: None,
            })?;
        let dissipative = template.declares_dissipation();
        let (grid, first) =
            SceneGrid::checked(axes, template, file).map_err(|e| grid_error(file, e))?;
        // A placeholder cannot add or remove a table, so the first scene says whether every
        // scene has a striker.
        let striker = first.scenario.region.has_striker();
        Ok(Sweep {
            grid,
            series,
            shares: ShareSet {
                striker,
                dissipative,
            },
            units: Units::Scaled,
        })
    }

    /// The units of its table.
    pub fn units(&self) -> Units {
        self.units
    }

    /// Number of grid points.
    pub fn count(&self) -> usize {
        self.grid.count()
    }

    /// The axis values of point `index`.
    pub fn values(&self, index: usize) -> Vec<AxisValue> {
        self.grid.values(index)
    }

    /// The validated scene of point `index`.
    pub fn scene_at(&self, index: usize) -> Result<Scene> {
        self.scene_with(&self.values(index), None)
    }

    /// The validated scene at arbitrary axis `values` (one per axis, in order), optionally with
    /// `run.tolerance` replaced (an optimiser's refinement runs between grid points, tighter).
    pub fn scene_with(&self, values: &[AxisValue], tolerance: Option<f64>) -> Result<Scene> {
        self.grid
            .scene_with(values, tolerance)
            .map_err(|e| grid_error(self.grid.file(), e))
    }

    /// The scene table at `values` (a scene file's content), before validation.
    pub fn table_with(&self, values: &[AxisValue], tolerance: Option<f64>) -> Result<toml::Table> {
        self.grid
            .table_with(values, tolerance)
            .map_err(|e| grid_error(self.grid.file(), e))
    }

    /// Every point's scene and cache key, in grid order.
    pub fn points(&self) -> Result<Vec<(Key, Scene)>> {
        (0..self.count())
            .into_par_iter()
            .map(|i| {
                let scene = self.scene_at(i)?;
                Ok((point_key(&scene, self.series), scene))
            })
            .collect()
    }

    /// The cache keys of the points `indices`. Only the keys are kept: a scene holds its
    /// chain (a few floats a site), so thousands of points of a long chain held at once would
    /// fill the memory; a point's scene is made again when it is simulated.
    pub fn keys_at(&self, indices: &[usize]) -> Result<Vec<Key>> {
        indices
            .par_iter()
            .map(|&i| Ok(point_key(&self.scene_at(i)?, self.series)))
            .collect()
    }

    /// Simulates what `points` lacks and assembles the whole output.
    pub(crate) fn compute(
        &self,
        stage: &str,
        points: &PointsDir,
        events: &dyn Events,
    ) -> Result<Output> {
        let all: Vec<usize> = (0..self.count()).collect();
        let at = PointsAt {
            stage,
            points,
            events,
        };
        let (frame, stats) = self.run_points(at, &all)?;
        Ok(Output::table(frame, self.summary(&stats)?).with_points(stats))
    }

    /// The output rows of the points `indices`: one per sample of each point, or one with the
    /// reason for a point that failed.
    fn table(&self, indices: &[usize], keys: &[Key], results: &[PointResult]) -> Result<DataFrame> {
        let values: Vec<Vec<AxisValue>> = indices.iter().map(|&i| self.values(i)).collect();
        let points: Vec<SweepPoint<'_>> = indices
            .iter()
            .zip(&values)
            .zip(keys.iter().zip(results))
            .map(|((&index, values), (key, result))| {
                Ok(SweepPoint {
                    index,
                    values,
                    key,
                    result,
                    si: self.si_factors(index)?,
                })
            })
            .collect::<Result<_>>()?;
        rows_frame(&self.shape().rows(&points))
    }

    /// Point `index`'s SI factors when the table is in SI (each point by its own scales:
    /// an axis may change the striker's speed, and so the time scale).
    fn si_factors(&self, index: usize) -> Result<Option<SiFactors>> {
        if self.units == Units::Scaled {
            return Ok(None);
        }
        SiFactors::of(&self.scene_at(index)?, self.units).map_err(|reason| {
            PipelineError::Definition {
                file: self.grid.file().to_path_buf(),
                key: "units".into(),
                reason: reason + &self.grid.at(&self.values(index)),
                source: None,
            }
        })
    }

    /// Writes its table's `units` and `column_units` into `summary`.
    pub(crate) fn declare_units(&self, summary: &mut Value) {
        // A kinetic series' `E` is a share of the impact energy, with no unit.
        let energy: &[(&str, &str)] = match self.series {
            Shares::Energy => &[(columns::ENERGY, "J")],
            Shares::Kinetic => &[],
        };
        let times = [
            (columns::TIME, "s"),
            (columns::DT, "s"),
            (columns::END_REACHED_AT, "s"),
        ];
        table_units::declare(summary, self.units, &[&times[..], energy].concat());
    }

    /// What every row of its table shares.
    fn shape(&self) -> SweepShape<'_> {
        SweepShape {
            axes: &self.grid.axes,
            shares: self.shares,
            kinetic: self.series == Shares::Kinetic,
        }
    }
}

/// A grid's error as the pipeline words it, naming the stage `file`: a scene's key under
/// `scene.`, a template's key as written, the memory against `axes`.
fn grid_error(file: &std::path::Path, e: GridError) -> PipelineError {
    let definition = |key: String, reason: String| PipelineError::Definition {
        file: file.to_path_buf(),
        key,
        reason,
        source: None,
    };
    match e {
        GridError::Template { key, reason } => definition(key, reason),
        GridError::Scene { error, at } => crate::grid::scene_error(file, "scene", error, &at),
        GridError::Memory(reason) => definition("axes".into(), reason),
    }
}

impl PointGrid for Sweep {
    fn count(&self) -> usize {
        self.count()
    }

    /// How many of the points are already in `points`.
    fn cached(&self, points: &PointsDir) -> Result<usize> {
        // One scene at a time per thread: a dry run of a large grid holds no list of scenes.
        (0..self.count())
            .into_par_iter()
            .map(|i| {
                let key = point_key(&self.scene_at(i)?, self.series);
                Ok(usize::from(points.path(&key).exists()))
            })
            .sum()
    }

    /// Simulates what `at`'s points lack among the points `indices` (increasing) and
    /// assembles their rows: the whole output, or one shard's part of it.
    fn run_points(&self, at: PointsAt<'_>, indices: &[usize]) -> Result<(DataFrame, PointStats)> {
        let PointsAt {
            stage,
            points,
            events,
        } = at;
        let store = PointStore::from(points);
        let keys = self.keys_at(indices)?;
        let mut results: Vec<Option<PointResult>> =
            keys.par_iter().map(|k| store.load(k)).collect();
        // A scene listed twice (an axis value repeated) is simulated once: its first point.
        let mut first_of: HashMap<&Key, usize> = HashMap::new();
        let todo: Vec<usize> = (0..keys.len())
            .filter(|&i| results[i].is_none() && *first_of.entry(&keys[i]).or_insert(i) == i)
            .collect();
        events.simulating(stage, todo.len(), keys.len() - todo.len());
        // Neighbouring points in batches of groups of four, which run in lanes where they can.
        let computed: Vec<(usize, Fetched)> = todo
            .par_chunks(batch_size(todo.len()))
            .map(|group| {
                let scenes: Vec<Scene> = group
                    .iter()
                    .map(|&i| self.scene_at(indices[i]))
                    .collect::<Result<_>>()?;
                let scenes: Vec<&Scene> = scenes.iter().collect();
                let group_keys: Vec<&Key> = group.iter().map(|&i| &keys[i]).collect();
                let fetched = store.get_or_simulate_all((&group_keys, &scenes), self.series)?;
                for _ in group {
                    events.point_done();
                }
                Ok(group.iter().copied().zip(fetched).collect::<Vec<_>>())
            })
            .collect::<Result<Vec<_>>>()?
            .into_iter()
            .flatten()
            .collect();
        let simulated = computed.iter().filter(|(_, f)| f.simulated).count();
        for (i, fetched) in computed {
            results[i] = Some(fetched.result);
        }
        for i in 0..keys.len() {
            if results[i].is_none() {
                results[i] = results[first_of[&keys[i]]].clone();
            }
        }
        let results: Vec<PointResult> = results.into_iter().flatten().collect();
        let stats = PointStats {
            simulated,
            ..woodpile_points::stats_of(&results)
        };
        if stats.failed > 0 {
            events.warn(&format!(
                "stage `{stage}`: {} of {} points failed (null rows with the reason in `failure`)",
                stats.failed, stats.points
            ));
        }
        let frame = self.table(indices, &keys, &results)?;
        Ok((frame, stats))
    }

    fn summary(&self, stats: &PointStats) -> Result<Value> {
        let scene = self.scene_at(0)?;
        let physical = scene.physical.as_ref().map(|p| {
            json!({
                "time_scale_s": p.scales.time_s(),
                "length_scale_m": p.scales.length_m(),
                "defects": p.defects,
            })
        });
        let first = scene.scenario;
        let mut summary = json!({
            "points": stats.points,
            "failed": stats.failed,
            "axes": self.grid.axes.iter().map(|a| a.name.clone()).collect::<Vec<_>>(),
            "method": match first.method { MethodChoice::Auto => "auto", MethodChoice::Named(m) => m.name() },
            "tolerance": first.accuracy.tolerance,
            "dt": first.accuracy.dt,
            "t_end": first.t_end,
            "sample_every": first.sample_every,
            "physical_point_0": physical,
            "series": match self.series { Shares::Energy => "energy", Shares::Kinetic => "kinetic" },
            "rhs_evals": stats.rhs_evals,
            "max_error_estimate": stats.max_error_estimate,
            "max_energy_drift": stats.max_energy_drift,
        });
        self.declare_units(&mut summary);
        Ok(summary)
    }
}

impl Kind for Sweep {
    fn sharing(&self) -> woodpile_pipeline::kind::Sharing {
        woodpile_pipeline::kind::Sharing::Parallel
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        self.compute(ctx.name(), ctx.points, ctx.events)
    }

    fn points(&self) -> Option<&dyn PointGrid> {
        Some(self)
    }
}
