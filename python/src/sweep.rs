//! `sweep`: a grid of scenes, as a sweep stage defines it (`$axis` placeholders in a scene,
//! axes as lists or `{from, to, step}` ranges, `through` blocks), simulated on every core with
//! the GIL released, through the same code as the stage (`woodpile_points`): the same points,
//! keys, optional point cache and table columns. A point that fails is a row with its reason,
//! never numbers. `simulate_many` runs a list of scenes as `simulate` would, one row each.

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use woodpile_files::Key;
use woodpile_points::rows::{SweepPoint, SweepShape};
use woodpile_points::{point_key, simulate_points_until, PointResult, PointStore, Shares};
use woodpile_scene::grid::{parse_axes, AxisValue, MAX_SWEEP_BYTES, PLANNED_BYTES_PER_SITE};
use woodpile_scene::sweep_grid::{GridError, SceneGrid};
use woodpile_scene::template::Template;
use woodpile_scene::units_out::{SiFactors, Units};
use woodpile_scene::Scene;
use woodpile_sim::simulation::batch_size;
use woodpile_sim::ShareSet;

use crate::interrupt::{internal_message, interruptible_keeping};
use crate::listed::{outcome_rows, table_dict};
use crate::scene_input::{self, label_text, Source};
use crate::series;
use crate::SceneError;

/// _sweep(scene, axes, series=None, cache=None, progress=None) -> dict
/// --
///
/// The native call behind `woodpile.sweep`: the sweep stage's table, as `names` (the columns
/// in order), each column as an array or list, and `masks` (the nulls of integer columns).
/// Without `series`, each point's last sample only. With `cache`, points are read from and
/// written to that point store. Ctrl-C raises `KeyboardInterrupt` whose `partial` holds the
/// table of the points finished so far.
#[pyfunction]
#[pyo3(signature = (scene, axes, series = None, cache = None, progress = None, units = "scaled"))]
pub(crate) fn sweep<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    axes: &Bound<'py, PyDict>,
    series: Option<&Bound<'py, PyAny>>,
    cache: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
    units: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = match series {
        Some(value) => series::parse(value, true)?,
        None => None,
    };
    // A bad template fails at once, not as a column of failures: the grid's corners exercise
    // every axis's extremes, as a sweep stage checks them.
    let (grid, first) = Grid::of(scene, axes)?;
    let count = grid.scenes.count();
    let units = Units::parse(units)
        .and_then(|u| SiFactors::of(&first, u).map(|_| u))
        .map_err(|reason| SceneError::new_err(format!("{}: units: {reason}", grid.label)))?;
    let store = match cache {
        Some(dir) => Some(point_store(dir)?),
        None => None,
    };
    let run = Run {
        grid: &grid,
        series: kind.unwrap_or(Shares::Energy),
        every_sample: kind.is_some(),
        store: store.as_ref(),
        done: AtomicUsize::new(0),
        units,
    };
    let shape = SweepShape {
        axes: &grid.scenes.axes,
        shares: ShareSet {
            striker: first.scenario.region.has_striker(),
            dissipative: grid.scenes.template().declares_dissipation(),
        },
        kinetic: kind == Some(Shares::Kinetic),
    };
    run.table(py, count, shape, progress.as_ref())
}

/// The point store in `dir`, refused (as the pipeline refuses its own) when it is a symbolic
/// link or not a folder.
fn point_store(dir: PathBuf) -> PyResult<PointStore> {
    woodpile_files::layout::check_tree_folder(&dir)
        .map_err(|reason| PyValueError::new_err(format!("cache: {}: {reason}", dir.display())))?;
    Ok(PointStore::new(dir))
}

/// A grid of scenes ([`SceneGrid`], the sweep stage's own type) and what its messages call it.
struct Grid {
    scenes: SceneGrid,
    label: String,
}

impl Grid {
    /// The grid of template `scene` (a dict, a TOML string or a path) over `axes`, checked
    /// as a sweep stage checks its own, with its first scene.
    fn of(scene: &Bound<'_, PyAny>, axes: &Bound<'_, PyDict>) -> PyResult<(Grid, Scene)> {
        let source = Source::of(scene)?;
        let label = label_text(&source.label());
        let template = source.table()?;
        let axes = parse_axes(scene_input::table(axes, "axes")?).map_err(|(key, reason)| {
            let key = if key.is_empty() {
                "axes".into()
            } else {
                format!("axes.{key}")
            };
            SceneError::new_err(format!("{label}: key `{key}`: {reason}"))
        })?;
        let template = Template::new(template, &axes).map_err(|(key, reason)| {
            SceneError::new_err(format!("{label}: key `{}`: {reason}", unprefixed(&key)))
        })?;
        let (scenes, first) = SceneGrid::checked(axes, template, Path::new(&label))
            .map_err(|e| SceneError::new_err(grid_message(&label, e)))?;
        Ok((Grid { scenes, label }, first))
    }

    /// The validated scene of point `index`, or the error naming its axis values.
    fn scene_at(&self, index: usize) -> Result<Scene, String> {
        self.scenes
            .scene_at(index)
            .map_err(|e| grid_message(&self.label, e))
    }
}

/// A grid's error as Python words it: the dict is the scene, so keys lose `scene.`.
fn grid_message(label: &str, e: GridError) -> String {
    match e {
        GridError::Template { key, reason } => {
            format!("{label}: key `{}`: {reason}", unprefixed(&key))
        }
        GridError::Scene { error, at } => format!("{error}{at}"),
        GridError::Memory(reason) => format!("{label}: {reason}"),
    }
}

/// A stage-file key of the template without its `scene.` prefix: in Python the dict is the scene.
fn unprefixed(key: &str) -> &str {
    key.strip_prefix("scene.").unwrap_or(key)
}

/// One finished point: its key and its series (or why it failed).
type Finished = (Key, PointResult);

/// Why a point could not be made at all: its scene is invalid, or the cache cannot be written.
enum Unmade {
    Scene(String),
    Cache(String),
}

/// A sweep being run.
struct Run<'a> {
    grid: &'a Grid,
    series: Shares,
    /// Every sample of each point, or its last one only.
    every_sample: bool,
    store: Option<&'a PointStore>,
    /// Points finished so far, for the progress line.
    done: AtomicUsize,
    /// The table's units: each point's own SI factors convert it.
    units: Units,
}

impl Run<'_> {
    /// Simulates the grid's `count` points on every core with the GIL released, and returns
    /// their table; on Ctrl-C, raises `KeyboardInterrupt` with the finished points' table as
    /// its `partial`.
    fn table<'py>(
        &self,
        py: Python<'py>,
        count: usize,
        shape: SweepShape<'_>,
        progress: Option<&Py<PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let poll = |py: Python<'_>| points_done(py, progress, &self.done, count);
        let (points, signal) = interruptible_keeping(py, &poll, |cancel| {
            crate::pool::run_parallel(|| {
                // Neighbouring points in batches of groups of four, which run in lanes where
                // they can (`woodpile_sim::simulation::simulate_batch`), as the pipeline's
                // sweeps do.
                let indices: Vec<usize> = (0..count).collect();
                indices
                    .par_chunks(batch_size(count))
                    .flat_map_iter(|group| self.group(group, cancel))
                    .collect::<Vec<_>>()
            })
        })?;
        let points = points.map_err(PyValueError::new_err)?;
        let mut finished = Vec::with_capacity(count);
        for (index, point) in points.into_iter().enumerate() {
            match point {
                Ok(Some(done)) => finished.push((index, done)),
                Ok(None) => {}
                Err(Unmade::Scene(reason)) => return Err(SceneError::new_err(reason)),
                Err(Unmade::Cache(reason)) => return Err(PyOSError::new_err(reason)),
            }
        }
        let table = self.rows(py, &finished, shape)?;
        match signal {
            None => Ok(table),
            Some(signal) => {
                signal.value(py).setattr("partial", table)?;
                Err(signal)
            }
        }
    }

    /// The table of the `finished` points (each with its grid index).
    fn rows<'py>(
        &self,
        py: Python<'py>,
        finished: &[(usize, Finished)],
        shape: SweepShape<'_>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let values: Vec<Vec<AxisValue>> = finished
            .iter()
            .map(|(i, _)| self.grid.scenes.values(*i))
            .collect();
        let points: Vec<SweepPoint<'_>> = finished
            .iter()
            .zip(&values)
            .map(|((index, (key, result)), values)| SweepPoint {
                index: *index,
                values,
                key,
                result,
                si: self.si_of(*index),
            })
            .collect();
        table_dict(py, &shape.rows(&points))
    }

    /// Point `index`'s SI factors, when the table is asked in SI (checked on the first point
    /// before the run: every point of the grid is a physical scene).
    fn si_of(&self, index: usize) -> Option<SiFactors> {
        if self.units == Units::Scaled {
            return None;
        }
        let scene = self.grid.scene_at(index).ok()?;
        SiFactors::of(&scene, self.units).ok().flatten()
    }

    /// Points `indices`, together: as [`Run::point`] makes each. A panic in the core makes
    /// each point again alone, so that it is the failure of its own point only.
    fn group(
        &self,
        indices: &[usize],
        cancel: &AtomicBool,
    ) -> Vec<Result<Option<Finished>, Unmade>> {
        let stop = || cancel.load(Ordering::Relaxed);
        let made: Vec<Result<(Key, Scene), String>> = indices
            .iter()
            .map(|&i| {
                let scene = self.grid.scene_at(i)?;
                Ok((point_key(&scene, self.series), scene))
            })
            .collect();
        if stop() || made.iter().any(Result::is_err) {
            return indices.iter().map(|&i| self.point(i, cancel)).collect();
        }
        let made: Vec<&(Key, Scene)> = made.iter().flatten().collect();
        let keys: Vec<&Key> = made.iter().map(|(key, _)| key).collect();
        let scenes: Vec<&Scene> = made.iter().map(|(_, scene)| scene).collect();
        let simulated = std::panic::catch_unwind(AssertUnwindSafe(|| match self.store {
            Some(store) => store
                .get_or_simulate_many((&keys, &scenes), self.series, &stop)
                .map(|all| all.into_iter().map(|f| f.map(|f| f.result)).collect())
                .map_err(|e| e.to_string()),
            None => Ok(simulate_points_until(&scenes, self.series, &stop)),
        }));
        let results: Vec<Option<PointResult>> = match simulated {
            Ok(Ok(results)) => results,
            Ok(Err(reason)) => {
                return indices
                    .iter()
                    .map(|_| Err(Unmade::Cache(reason.clone())))
                    .collect()
            }
            Err(_) => return indices.iter().map(|&i| self.point(i, cancel)).collect(),
        };
        keys.into_iter()
            .zip(results)
            .map(|(key, result)| Ok(self.finish(result).map(|r| (key.clone(), r))))
            .collect()
    }

    /// A point's result as the table keeps it (its last sample only, without series),
    /// counted as done.
    fn finish(&self, result: Option<PointResult>) -> Option<PointResult> {
        // Without series, a point keeps its last sample only: thousands of points' series of a
        // long run would fill the memory.
        let result = result.map(|r| match self.every_sample {
            true => r,
            false => r.map(|p| p.last_sample()),
        });
        if result.is_some() {
            self.done.fetch_add(1, Ordering::Relaxed);
        }
        result
    }

    /// Point `index`: from the cache or simulated (and cached), `None` if the sweep was
    /// stopped first. A panic in the core is the point's failure, not the sweep's.
    fn point(&self, index: usize, cancel: &AtomicBool) -> Result<Option<Finished>, Unmade> {
        let stop = || cancel.load(Ordering::Relaxed);
        if stop() {
            return Ok(None);
        }
        let scene = self.grid.scene_at(index).map_err(Unmade::Scene)?;
        let key = point_key(&scene, self.series);
        let simulated = std::panic::catch_unwind(AssertUnwindSafe(|| match self.store {
            Some(store) => store
                .get_or_simulate_until(&key, &scene, self.series, &stop)
                .map(|fetched| fetched.map(|f| f.result))
                .map_err(|e| Unmade::Cache(e.to_string())),
            None => Ok(woodpile_points::point::simulate_point_until(
                &scene,
                self.series,
                &stop,
            )),
        }));
        let result = match simulated {
            Ok(result) => result?,
            Err(panic) => Some(Err(internal_message(&panic))),
        };
        Ok(self.finish(result).map(|r| (key, r)))
    }
}

/// Calls `progress(done, total)`, if given.
fn points_done(
    py: Python<'_>,
    progress: Option<&Py<PyAny>>,
    done: &AtomicUsize,
    total: usize,
) -> PyResult<()> {
    match progress {
        Some(callback) => callback
            .call1(py, (done.load(Ordering::Relaxed), total))
            .map(|_| ()),
        None => Ok(()),
    }
}

/// _simulate_many(scenes, progress=None) -> dict
/// --
///
/// The native call behind `woodpile.simulate_many`: every scene of the list (dicts, TOML
/// strings or paths) simulated on all cores with the GIL released, one row each in input
/// order, as `_sweep` returns its points (four neighbours at a time in lanes where they can). A scene that fails to simulate is a row with its
/// reason; one that is invalid is a `SceneError` naming its index.
#[pyfunction]
#[pyo3(signature = (scenes, progress = None, units = "scaled", fields = false))]
pub(crate) fn simulate_many<'py>(
    py: Python<'py>,
    scenes: &Bound<'py, PyAny>,
    progress: Option<Py<PyAny>>,
    units: &str,
    fields: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let units =
        Units::parse(units).map_err(|reason| SceneError::new_err(format!("units: {reason}")))?;
    let mut list = Vec::new();
    // The scenes planned so far hold their chains: stop as soon as they alone are too many,
    // before the next is planned (the whole list is checked below).
    let mut planned = 0.0;
    for (index, item) in scenes.try_iter()?.enumerate() {
        if planned > MAX_SWEEP_BYTES {
            woodpile_scene::grid::check_list_memory(&list)
                .map_err(|reason| SceneError::new_err(format!("scenes: {reason}")))?;
        }
        let source = Source::of(&item?)?;
        let scene = source
            .scene()
            .map_err(|e| SceneError::new_err(format!("scenes[{index}]: {}", e.value(py))))?;
        planned += scene.scenario.model.n_sites() as f64 * PLANNED_BYTES_PER_SITE;
        list.push(scene);
    }
    woodpile_scene::grid::check_list_memory(&list)
        .map_err(|reason| SceneError::new_err(format!("scenes: {reason}")))?;
    let si = list
        .iter()
        .enumerate()
        .map(|(index, scene)| {
            SiFactors::of(scene, units)
                .map_err(|reason| SceneError::new_err(format!("scenes[{index}]: units: {reason}")))
        })
        .collect::<PyResult<Vec<_>>>()?;
    if fields {
        check_fields(&list)?;
    }
    let done = AtomicUsize::new(0);
    let poll = |py: Python<'_>| points_done(py, progress.as_ref(), &done, list.len());
    let (outcomes, signal) = interruptible_keeping(py, &poll, |cancel| {
        crate::pool::run_parallel(|| {
            // Neighbouring scenes in batches of groups of four, which run in lanes where
            // they can.
            list.par_chunks(batch_size(list.len()))
                .flat_map_iter(|group| {
                    let group: Vec<&Scene> = group.iter().collect();
                    let outcomes = crate::listed::simulate_group(&group, cancel, fields);
                    done.fetch_add(group.len(), Ordering::Relaxed);
                    outcomes
                })
                .collect::<Vec<_>>()
        })
    })?;
    if let Some(signal) = signal {
        return Err(signal);
    }
    let listed = outcomes.map_err(PyValueError::new_err)?;
    let (outcomes, recorded): (Vec<_>, Vec<_>) = listed.into_iter().unzip();
    let table = table_dict(py, &outcome_rows(&outcomes, &list, &si))?;
    if fields {
        let each = pyo3::types::PyList::empty(py);
        for ((scene, field), si) in list.iter().zip(recorded).zip(&si) {
            match field {
                None => each.append(py.None())?,
                Some(mut field) => {
                    if let Some(si) = si {
                        si.field(&mut field);
                    }
                    let arrays = PyDict::new(py);
                    crate::simulate::add_field(py, &arrays, scene, field)?;
                    each.append(arrays)?;
                }
            }
        }
        table.set_item("fields", each)?;
    }
    Ok(table)
}

/// Most field values (samples × sites, summed over the scenes) `simulate_many(fields=True)`
/// keeps: each is four doubles, so 2.5·10^7 take 800 MB.
const MAX_LISTED_FIELD_VALUES: f64 = 2.5e7;

/// Refuses fields too large to hold: each scene's own bound, then all of them together.
fn check_fields(list: &[Scene]) -> PyResult<()> {
    let mut total = 0.0;
    for (index, scene) in list.iter().enumerate() {
        let s = &scene.scenario;
        let n = s.model.n_sites();
        woodpile_sim::simulation::check_field_size(s, n)
            .map_err(|reason| SceneError::new_err(format!("scenes[{index}]: fields: {reason}")))?;
        let samples = woodpile_sim::integrate::intervals(s.t_end, s.sample_every) as f64 + 1.0;
        total += samples * n as f64;
    }
    if total > MAX_LISTED_FIELD_VALUES {
        return Err(SceneError::new_err(format!(
            "fields: the scenes' fields would hold {total:.3e} values, more than the {MAX_LISTED_FIELD_VALUES:e} simulate_many keeps; ask for fewer scenes at once, or sample less often"
        )));
    }
    Ok(())
}
