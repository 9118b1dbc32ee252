//! Tables handed to Python: rows (`woodpile_files::rows::Row`) as a dict of NumPy arrays and
//! lists, and the rows of `simulate_many`, one per scene as `simulate` reports it.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering};

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use woodpile_files::rows::{columns, Cell, Column, Row};
use woodpile_points::rows::sweep;
use woodpile_scene::units_out::SiFactors;
use woodpile_scene::Scene;
use woodpile_sim::observe::SiteField;
use woodpile_sim::simulation::{simulate, simulate_batch, Outcome};
use woodpile_sim::ShareSet;

use crate::interrupt::{internal_message, Watch};

/// The table of `rows` as the Python side reads it: `names` (the columns in order), each
/// column under its name (floats and integers as arrays, a null float as NaN, text and lists
/// as lists), and `masks`, each integer column's nulls.
pub(crate) fn table_dict<'py, R: Row>(py: Python<'py>, rows: &[R]) -> PyResult<Bound<'py, PyDict>> {
    let columns = columns(rows).map_err(pyo3::exceptions::PyRuntimeError::new_err)?;
    let out = PyDict::new(py);
    let masks = PyDict::new(py);
    let mut names = Vec::with_capacity(columns.len());
    for (name, column) in columns {
        match column {
            Column::F64(v) => {
                let v: Vec<f64> = v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect();
                out.set_item(&name, v.into_pyarray(py))?;
            }
            Column::I64(v) => {
                let mask: Vec<bool> = v.iter().map(Option::is_none).collect();
                let v: Vec<i64> = v.into_iter().map(|x| x.unwrap_or(0)).collect();
                out.set_item(&name, v.into_pyarray(py))?;
                masks.set_item(&name, mask.into_pyarray(py))?;
            }
            Column::Str(v) => out.set_item(&name, PyList::new(py, v)?)?,
            Column::F64List(v) => out.set_item(&name, PyList::new(py, v)?)?,
            Column::I64List(v) => out.set_item(&name, PyList::new(py, v)?)?,
        }
        names.push(name);
    }
    out.set_item("names", names)?;
    out.set_item("masks", masks)?;
    Ok(out)
}

/// One listed scene's run: its outcome (or why it failed) and, when fields were asked for, the
/// field it recorded.
pub(crate) type Listed = (Result<Outcome, String>, Option<SiteField>);

/// What one scene's run records: nothing, or every site's field.
fn recorder(scene: &Scene, fields: bool) -> Option<SiteField> {
    let n = scene.scenario.model.n_sites();
    fields.then(|| SiteField::new(&scene.scenario.model, 0, n - 1))
}

/// `scene` simulated as `simulate` runs it (stopped once `cancel` is raised), keeping only what
/// the table reads: a run's final state is a chain's worth of floats, which thousands of scenes
/// of a long chain would hold at once. A panic in the core is this scene's failure.
pub(crate) fn simulate_one(scene: &Scene, cancel: &AtomicBool, fields: bool) -> Listed {
    if cancel.load(Ordering::Relaxed) {
        return (Err("cancelled".into()), None);
    }
    let stop = || cancel.load(Ordering::Relaxed);
    let run = || {
        let mut watched = Watch {
            inner: recorder(scene, fields),
            stop: &stop,
            clock: None,
        };
        let outcome = simulate(&scene.scenario, &mut watched).map(|mut outcome| {
            outcome.final_state = Vec::new();
            outcome
        });
        match outcome {
            Ok(outcome) => (Ok(outcome), watched.inner),
            Err(e) => (Err(e.to_string()), None),
        }
    };
    std::panic::catch_unwind(AssertUnwindSafe(run))
        .unwrap_or_else(|panic| (Err(internal_message(&panic)), None))
}

/// [`simulate_one`] of each of `scenes`, neighbours together: four consecutive scenes that
/// share a chain and a first step run `auto`'s first pair in lanes
/// (`woodpile_sim::simulation::simulate_batch`), with the same results. A panic makes each
/// scene again alone, so that it is the failure of its own scene only.
pub(crate) fn simulate_group(scenes: &[&Scene], cancel: &AtomicBool, fields: bool) -> Vec<Listed> {
    let stop = || cancel.load(Ordering::Relaxed);
    let run = || {
        let scenarios: Vec<_> = scenes.iter().map(|s| &s.scenario).collect();
        let mut watches: Vec<_> = scenes
            .iter()
            .map(|scene| Watch {
                inner: recorder(scene, fields),
                stop: &stop,
                clock: None,
            })
            .collect();
        let outcomes = simulate_batch(&scenarios, &mut watches);
        outcomes
            .into_iter()
            .zip(watches)
            .map(|(outcome, watched)| match outcome {
                Ok(mut outcome) => {
                    outcome.final_state = Vec::new();
                    (Ok(outcome), watched.inner)
                }
                Err(e) => (Err(e.to_string()), None),
            })
            .collect()
    };
    if stop() {
        return scenes
            .iter()
            .map(|_| (Err("cancelled".into()), None))
            .collect();
    }
    std::panic::catch_unwind(AssertUnwindSafe(run)).unwrap_or_else(|_| {
        scenes
            .iter()
            .map(|s| simulate_one(s, cancel, fields))
            .collect()
    })
}

/// The rows of `simulate_many`: one per scene, in input order; `S` on every row when any
/// scene has a striker, and `D` when any declares damping, as a sweep's table has them. With
/// `si` (one per scene), `dt` is in s and the energies in J.
pub(crate) fn outcome_rows<'a>(
    outcomes: &'a [Result<Outcome, String>],
    scenes: &[Scene],
    si: &[Option<SiFactors>],
) -> Vec<OutcomeRow<'a>> {
    let shares = scenes
        .iter()
        .map(|s| ShareSet::of(&s.scenario.model, &s.scenario.region))
        .fold(ShareSet::default(), ShareSet::union);
    outcomes
        .iter()
        .enumerate()
        .map(|(point, outcome)| OutcomeRow {
            point,
            outcome,
            shares,
            si: si.get(point).copied().flatten(),
        })
        .collect()
}

/// One scene's row: its final fractions and how the run went, or why it failed.
pub(crate) struct OutcomeRow<'a> {
    point: usize,
    outcome: &'a Result<Outcome, String>,
    /// The shares every row carries: those of any scene.
    shares: ShareSet,
    /// SI factors, when the row is asked in SI units.
    si: Option<SiFactors>,
}

impl Row for OutcomeRow<'_> {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let ok = self.outcome.as_ref().ok();
        let (time, energy) = self.si.map_or((1.0, 1.0), |f| (f.time_s, f.energy_j));
        let mut cells = vec![(sweep::POINT, Cell::from(self.point as i64))];
        for kind in self.shares.iter() {
            cells.push((kind.name(), Cell::from(ok.map(|o| kind.of(&o.fractions)))));
        }
        cells.extend([
            ("E_initial", ok.map(|o| o.e_initial * energy).into()),
            ("E_final", ok.map(|o| o.e_final * energy).into()),
            ("error_estimate", ok.and_then(|o| o.error_estimate).into()),
            (
                "dt",
                ok.and_then(|o| o.plan.dt().map(|_| o.stats.max_step * time))
                    .into(),
            ),
            ("steps", ok.map(|o| o.stats.steps as i64).into()),
            ("rhs_evals", ok.map(|o| o.stats.rhs_evals as i64).into()),
            (
                "total_rhs_evals",
                ok.map(|o| o.total_rhs_evals as i64).into(),
            ),
            (
                "method",
                ok.map(|o| o.plan.method.name().to_string()).into(),
            ),
            ("failure", self.outcome.as_ref().err().cloned().into()),
        ]);
        cells
    }
}
