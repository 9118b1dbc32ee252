//! `sweep`: a grid of scenes, as a sweep stage defines it (`$axis` placeholders in a scene,
//! axes as lists or `{from, to, step}` ranges, `through` blocks), simulated on every core with
//! the GIL released. A point that fails is a row with its reason, never numbers.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering};

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use woodpile_scene::grid::{parse_axes, point, point_count, Axis, AxisValue};
use woodpile_scene::template::Template;

use crate::series::SeriesKind;
use woodpile_scene::Scene;
use woodpile_sim::observe::FractionSeries;
use woodpile_sim::run::{simulate, Outcome};

use crate::interrupt::{internal_message, interruptible, Watch};
use crate::scene_input::{self, shown, Source};
use crate::SceneError;

/// One simulated point: its outcome and, when asked for, its series.
struct Point {
    outcome: Outcome,
    series: Option<FractionSeries>,
}

impl Point {
    /// The point with only what the table reads: a run's final state and its series' scratch
    /// are a chain's worth of floats each, which thousands of points of a long chain would
    /// hold at once.
    fn kept(mut outcome: Outcome, mut series: Option<FractionSeries>) -> Point {
        outcome.final_state = Vec::new();
        if let Some(s) = series.as_mut() {
            s.drop_scratch();
        }
        Point { outcome, series }
    }
}

/// _sweep(scene, axes, series=None) -> dict
/// --
///
/// The native call behind `woodpile.sweep`: `names` (the columns in order) and each column as
/// an array or list; `valid` masks the integer columns of failed points.
#[pyfunction]
#[pyo3(signature = (scene, axes, series = None))]
pub(crate) fn sweep<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    axes: &Bound<'py, PyDict>,
    series: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = match series {
        Some(value) => SeriesKind::parse(value, true)?,
        None => None,
    };
    let source = Source::of(scene)?;
    let label = shown(&source.label());
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
    let grid = Grid {
        axes,
        scenes: Scenes::Template(template),
        label,
    };
    let count = point_count(&grid.axes);
    // A bad template fails at once, not as a column of failures: the grid's corners exercise
    // every axis's extremes, as a sweep stage checks them.
    grid.scene_at(0).map_err(SceneError::new_err)?;
    let last = grid.scene_at(count - 1).map_err(SceneError::new_err)?;
    if kind.is_some() {
        woodpile_scene::grid::check_sweep_memory(count, &last)
            .map_err(|reason| SceneError::new_err(format!("{}: {reason}", grid.label)))?;
    }
    grid.run(py, count, kind)
}

/// _simulate_many(scenes) -> dict
/// --
///
/// The native call behind `woodpile.simulate_many`: every scene of the list (dicts, TOML
/// strings or paths) simulated on all cores with the GIL released, one row each in input
/// order, as `_sweep` returns its points (without axes). A scene that fails to simulate is a
/// row with its reason; one that is invalid is a `SceneError` naming its index.
#[pyfunction]
pub(crate) fn simulate_many<'py>(
    py: Python<'py>,
    scenes: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut list = Vec::new();
    for (index, item) in scenes.try_iter()?.enumerate() {
        let source = Source::of(&item?)?;
        let scene = source
            .scene()
            .map_err(|e| SceneError::new_err(format!("scenes[{index}]: {}", e.value(py))))?;
        list.push(scene);
    }
    let count = list.len();
    let grid = Grid {
        axes: Vec::new(),
        scenes: Scenes::List(list),
        label: "<scenes>".into(),
    };
    grid.run(py, count, None)
}

/// A stage-file key of the template without its `scene.` prefix: in Python the dict is the scene.
fn unprefixed(key: &str) -> &str {
    key.strip_prefix("scene.").unwrap_or(key)
}

struct Grid {
    axes: Vec<Axis>,
    scenes: Scenes,
    label: String,
}

/// Where a grid's scenes come from: a template over its axes, or a list given whole.
enum Scenes {
    Template(Template),
    List(Vec<Scene>),
}

impl Grid {
    /// Simulates the grid's `count` points on every core with the GIL released, and returns
    /// their table.
    fn run<'py>(
        &self,
        py: Python<'py>,
        count: usize,
        kind: Option<SeriesKind>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let points: Vec<Result<Point, String>> = interruptible(py, |cancel| {
            crate::pool::run_parallel(|| {
                (0..count)
                    .into_par_iter()
                    .map(|i| self.simulate(i, kind, cancel))
                    .collect()
            })
        })?
        .map_err(pyo3::exceptions::PyValueError::new_err)?;
        self.columns(py, &points, kind.is_some())
    }

    /// Whether its scenes declare dissipation: the table then has `D` on every row.
    fn declares_dissipation(&self) -> bool {
        match &self.scenes {
            Scenes::Template(template) => template.declares_dissipation(),
            Scenes::List(list) => list.iter().any(|s| s.scenario.model.is_dissipative()),
        }
    }

    /// The validated scene of point `index`, or the error naming its axis values.
    fn scene_at(&self, index: usize) -> Result<Scene, String> {
        let template = match &self.scenes {
            Scenes::List(list) => return Ok(list[index].clone()),
            Scenes::Template(template) => template,
        };
        let values = point(&self.axes, index);
        let at: Vec<String> = self
            .axes
            .iter()
            .zip(&values)
            .map(|(a, v)| format!("{} = {v}", a.name))
            .collect();
        let at = if at.is_empty() {
            String::new()
        } else {
            format!(" (at {})", at.join(", "))
        };
        let table = template
            .instantiate(&self.axes, &values)
            .map_err(|(key, reason)| {
                format!("{}: key `{}`: {reason}{at}", self.label, unprefixed(&key))
            })?;
        woodpile_scene::from_table(table, std::path::Path::new(&self.label))
            .map_err(|e| format!("{e}{at}"))
    }

    fn simulate(
        &self,
        index: usize,
        series: Option<SeriesKind>,
        cancel: &AtomicBool,
    ) -> Result<Point, String> {
        if cancel.load(Ordering::Relaxed) {
            return Err("cancelled".into());
        }
        let scene = self.scene_at(index)?;
        let s = &scene.scenario;
        let stop = || cancel.load(Ordering::Relaxed);
        let run = || -> Result<Point, String> {
            if let Some(kind) = series {
                let mut watched = Watch {
                    inner: kind.recorder(s)?,
                    stop: &stop,
                };
                let outcome = simulate(s, &mut watched).map_err(|e| e.to_string())?;
                Ok(Point::kept(outcome, Some(watched.inner)))
            } else {
                let outcome = simulate(
                    s,
                    &mut Watch {
                        inner: (),
                        stop: &stop,
                    },
                )
                .map_err(|e| e.to_string())?;
                Ok(Point::kept(outcome, None))
            }
        };
        std::panic::catch_unwind(AssertUnwindSafe(run))
            .unwrap_or_else(|panic| Err(internal_message(&panic)))
    }

    /// Each axis's value on every row (integer axes as integers), named in `names`.
    fn axis_columns(
        &self,
        py: Python<'_>,
        out: &Bound<'_, PyDict>,
        rows: &[(usize, Option<usize>)],
        names: &mut Vec<String>,
    ) -> PyResult<()> {
        for (a, axis) in self.axes.iter().enumerate() {
            let value = |i: usize| point(&self.axes, i)[a];
            if axis.is_integer() {
                let v: Vec<i64> = rows
                    .iter()
                    .map(|&(i, _)| match value(i) {
                        AxisValue::Int(x) => x,
                        AxisValue::Float(x) => x as i64,
                    })
                    .collect();
                out.set_item(&axis.name, v.into_pyarray(py))?;
            } else {
                let v: Vec<f64> = rows.iter().map(|&(i, _)| value(i).as_f64()).collect();
                out.set_item(&axis.name, v.into_pyarray(py))?;
            }
            names.push(axis.name.clone());
        }
        Ok(())
    }

    /// The table, column by column: one row per point, or per point and sample.
    fn columns<'py>(
        &self,
        py: Python<'py>,
        points: &[Result<Point, String>],
        series: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        // Which point each row belongs to, and its sample (None: the point's one row).
        let rows: Vec<(usize, Option<usize>)> = points
            .iter()
            .enumerate()
            .flat_map(|(i, p)| match p {
                Ok(Point {
                    series: Some(s), ..
                }) => (0..s.t.len()).map(|k| (i, Some(k))).collect(),
                _ => vec![(i, None)],
            })
            .collect();
        let out = PyDict::new(py);
        let mut names = vec!["point".to_string()];
        let index: Vec<i64> = rows.iter().map(|&(i, _)| i as i64).collect();
        out.set_item("point", index.into_pyarray(py))?;
        self.axis_columns(py, &out, &rows, &mut names)?;
        let ok = |i: usize| points[i].as_ref().ok();
        // D on every row of a sweep whose scene declares dissipation (0 where it dissipates
        // nothing), as in a pipeline sweep's table.
        let dissipation = self.declares_dissipation();
        let mut float =
            |name: &str, f: &dyn Fn(&Point, Option<usize>) -> Option<f64>| -> PyResult<()> {
                let v: Vec<f64> = rows
                    .iter()
                    .map(|&(i, k)| ok(i).and_then(|p| f(p, k)).unwrap_or(f64::NAN))
                    .collect();
                names.push(name.to_string());
                out.set_item(name, v.into_pyarray(py))
            };
        if series {
            let sample = |p: &Point, k: Option<usize>, pick: fn(&FractionSeries) -> &Vec<f64>| {
                Some(pick(p.series.as_ref()?)[k?])
            };
            float("t", &|p, k| sample(p, k, |s| &s.t))?;
            float("R", &|p, k| sample(p, k, |s| &s.reflected))?;
            float("T", &|p, k| sample(p, k, |s| &s.transmitted))?;
            float("E_tr", &|p, k| sample(p, k, |s| &s.trapped))?;
            if dissipation {
                float("D", &|p, k| sample(p, k, |s| &s.dissipated))?;
            }
            float("E", &|p, k| sample(p, k, |s| &s.energy))?;
        } else {
            float("R", &|p, _| Some(p.outcome.fractions.reflected))?;
            float("T", &|p, _| Some(p.outcome.fractions.transmitted))?;
            float("E_tr", &|p, _| Some(p.outcome.fractions.trapped))?;
            if dissipation {
                float("D", &|p, _| Some(p.outcome.fractions.dissipated))?;
            }
            float("E_initial", &|p, _| Some(p.outcome.e_initial))?;
            float("E_final", &|p, _| Some(p.outcome.e_final))?;
        }
        float("error_estimate", &|p, _| p.outcome.error_estimate)?;
        float("dt", &|p, _| {
            p.outcome.plan.dt().map(|_| p.outcome.stats.max_step)
        })?;
        let mut integer = |name: &str, f: &dyn Fn(&Point) -> u64| -> PyResult<()> {
            let v: Vec<i64> = rows
                .iter()
                .map(|&(i, _)| ok(i).map_or(0, |p| f(p) as i64))
                .collect();
            names.push(name.to_string());
            out.set_item(name, v.into_pyarray(py))
        };
        integer("steps", &|p| p.outcome.stats.steps)?;
        integer("rhs_evals", &|p| p.outcome.total_rhs_evals)?;
        let valid: Vec<bool> = rows.iter().map(|&(i, _)| ok(i).is_some()).collect();
        out.set_item("valid", valid.into_pyarray(py))?;
        let text = |f: &dyn Fn(&Result<Point, String>) -> Option<String>| {
            rows.iter().map(|&(i, _)| f(&points[i])).collect::<Vec<_>>()
        };
        out.set_item(
            "method",
            PyList::new(
                py,
                text(&|p| {
                    p.as_ref()
                        .ok()
                        .map(|p| p.outcome.plan.method.name().to_string())
                }),
            )?,
        )?;
        out.set_item(
            "failure",
            PyList::new(py, text(&|p| p.as_ref().err().cloned()))?,
        )?;
        names.push("method".into());
        names.push("failure".into());
        out.set_item("names", names)?;
        Ok(out)
    }
}
