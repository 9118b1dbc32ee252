//! `kind = "workprecision"`: speed against accuracy. Every method over a range of steps or
//! tolerances, on a few representative scenes: the error in E_tr against a tight reference, the
//! energy drift, and the wall time (SciML's DiffEqDevTools work-precision charts are the model).
//!
//! ```toml
//! kind = "workprecision"
//! repeats = 3                      # wall time is the best of this many runs
//! threads = 1                      # optional: runs timed at once (default: one per physical core)
//! reference_tolerance = 1e-13      # the reference: dop853 at this tolerance
//! [[scene]]
//! name = "one defect, eps = 10"
//! defect = [{ site = 0, eps = 10.0 }]   # the rest of the table is a scene file
//! [[method]]
//! name = "rk4"
//! dt = [0.1, 0.05, 0.02, 0.01]          # fixed-step methods take dt,
//! [[method]]
//! name = "dop853"
//! tolerance = [1e-6, 1e-8, 1e-10]       # adaptive ones and `auto` take tolerance
//! ```
//!
//! One row per scene, method and setting. Each setting's runs are made one after another on one
//! thread, and as many settings are timed at once as there are physical cores (`threads = N`
//! sets it; `threads = 1` times each run alone), so that timed runs need not share a core; a run
//! that fails (blow-up, drift beyond its bound) is a row with its reason in `failure` and null
//! numbers. The manifest notes the reference values, the machine (CPU model and cores), the
//! threads that timed and the runs counted. Wall times differ between machines and runs: `make check`
//! compares every other column exactly and the `wall_ms` columns not at all.

// Comparisons are written `!(x > 0.0)` on purpose: a NaN must fail them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;
use serde_json::json;
use woodpile_scene::threads::MAX_THREADS;
use woodpile_scene::Scene;
use woodpile_sim::integrate::{Accuracy, Method, MethodChoice, Plan};
use woodpile_sim::simulation::{run_with_plan, simulate, Outcome, Scenario};

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{Context, Kind};
use woodpile_pipeline::table::{rows_frame, Cell, Row};
use woodpile_pipeline::Output;

/// A parsed work-precision stage.
#[derive(Debug, Clone)]
pub struct WorkPrecision {
    /// Runs per setting; the best wall time is kept.
    pub repeats: usize,
    /// Runs timed at once; `None`: one per physical core (`timing_threads`).
    pub threads: Option<usize>,
    /// Tolerance of the DOP853 reference.
    pub reference_tolerance: f64,
    /// The scenes, named.
    pub scenes: Vec<(String, Scene)>,
    /// The method settings, in order.
    pub settings: Vec<Setting>,
}

/// One method at one step or tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// Method name as in scene files (`auto` included).
    pub method: String,
    /// Index of the method among the stage's `[[method]]` tables (a curve of the chart).
    pub method_index: usize,
    /// The method.
    pub choice: MethodChoice,
    /// Step or tolerance.
    pub accuracy: Accuracy,
}

/// The `[[scene]]` tables: each a named scene file's content.
fn parse_scenes(fields: &mut Fields<'_>) -> Result<Vec<(String, Scene)>> {
    let file = fields.file().to_path_buf();
    let Some(toml::Value::Array(scene_tables)) = fields.take("scene") else {
        return Err(fields.error("scene", "expected one or more [[scene]] tables"));
    };
    let mut scenes = Vec::new();
    for (i, entry) in scene_tables.into_iter().enumerate() {
        let key = format!("scene[{i}]");
        let toml::Value::Table(mut table) = entry else {
            return Err(fields.error(&key, "expected a table"));
        };
        let name = match table.remove("name") {
            Some(toml::Value::String(s)) => s,
            _ => return Err(fields.error(&format!("{key}.name"), "expected a string")),
        };
        let scene = woodpile_scene::from_table(table, &file)
            .map_err(|e| crate::grid::scene_error(&file, &key, e, ""))?;
        scenes.push((name, scene));
    }
    Ok(scenes)
}

/// The `i`th `[[method]]` table: its method, and one setting per step (fixed-step methods) or
/// tolerance (`auto` and adaptive methods) it lists.
fn parse_method(fields: &Fields<'_>, i: usize, entry: toml::Value) -> Result<Vec<Setting>> {
    let key = format!("method[{i}]");
    let toml::Value::Table(table) = entry else {
        return Err(fields.error(&key, "expected a table"));
    };
    let mut f = fields.nested(&key, table);
    let options = MethodChoice::options();
    let choice = f.choice("name", &options, None)?;
    let name = options
        .iter()
        .find(|(_, c)| *c == choice)
        .map_or("", |(n, _)| n);
    let adaptive = match choice {
        MethodChoice::Auto => true,
        MethodChoice::Named(m) => m.is_adaptive(),
    };
    let values: Vec<f64> = if adaptive {
        f.required("tolerance")?
    } else {
        f.required("dt")?
    };
    f.finish()?;
    if values.is_empty() || values.iter().any(|v| !(*v > 0.0)) {
        let what = if adaptive { "tolerance" } else { "dt" };
        return Err(fields.error(&format!("{key}.{what}"), "expected positive numbers"));
    }
    Ok(values
        .into_iter()
        .map(|v| Setting {
            method: name.to_string(),
            method_index: i,
            choice,
            accuracy: match adaptive {
                true => Accuracy {
                    tolerance: v,
                    tolerance_explicit: true,
                    dt: None,
                },
                false => Accuracy {
                    tolerance: 1e-8,
                    tolerance_explicit: false,
                    dt: Some(v),
                },
            },
        })
        .collect())
}

impl WorkPrecision {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<WorkPrecision> {
        let repeats = fields.optional::<i64>("repeats")?.unwrap_or(3);
        if !(1..=100).contains(&repeats) {
            return Err(fields.error("repeats", "expected 1 to 100"));
        }
        let threads = match fields.optional::<i64>("threads")? {
            Some(n) if !(1..=MAX_THREADS as i64).contains(&n) => {
                return Err(fields.error("threads", format!("expected 1 to {MAX_THREADS}")));
            }
            n => n.map(|n| n as usize),
        };
        let reference_tolerance = fields
            .optional::<f64>("reference_tolerance")?
            .unwrap_or(1e-13);
        if !(reference_tolerance > 0.0) {
            return Err(fields.error("reference_tolerance", "must be > 0"));
        }
        let scenes = parse_scenes(fields)?;
        let Some(toml::Value::Array(method_tables)) = fields.take("method") else {
            return Err(fields.error("method", "expected one or more [[method]] tables"));
        };
        let mut settings = Vec::new();
        for (i, entry) in method_tables.into_iter().enumerate() {
            settings.extend(parse_method(fields, i, entry)?);
        }
        Ok(WorkPrecision {
            repeats: repeats as usize,
            threads,
            reference_tolerance,
            scenes,
            settings,
        })
    }

    pub(crate) fn compute(&self, stage: &str) -> Result<Output> {
        // The user's thread limit (`RAYON_NUM_THREADS`, `--threads`) caps the default.
        let threads = self
            .threads
            .unwrap_or_else(|| timing_threads().min(rayon::current_num_threads()));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| PipelineError::stage(stage, format!("no timing threads: {e}")))?;
        // Collected whole, so that the first failure in scene order is the one reported.
        let references: Vec<Result<_>> = pool.install(|| {
            self.scenes
                .par_iter()
                .map(|(name, scene)| {
                    reference(&scene.scenario, self.reference_tolerance).map_err(|e| {
                        PipelineError::stage(
                            stage,
                            format!("scene `{name}`: reference failed: {e}"),
                        )
                    })
                })
                .collect()
        });
        let references = references.into_iter().collect::<Result<Vec<_>>>()?;
        let jobs: Vec<(usize, &Setting)> = (0..self.scenes.len())
            .flat_map(|index| self.settings.iter().map(move |setting| (index, setting)))
            .collect();
        let timed: Vec<Timed> = pool.install(|| {
            jobs.par_iter()
                .map(|&(index, setting)| self.timed(index, setting))
                .collect()
        });
        let simulated = self.scenes.len() + timed.iter().map(|t| t.runs).sum::<usize>();
        let rows: Vec<Run> = timed
            .into_iter()
            .zip(jobs)
            .map(|(timed, (index, setting))| {
                let scene = &self.scenes[index];
                Run {
                    scene: index,
                    name: &scene.0,
                    setting,
                    e_ref: references[index].0,
                    wall_ms: timed.best_ms,
                    outcome: timed.outcome,
                    conserves_energy: !scene.1.scenario.model.is_time_dependent(),
                }
            })
            .collect();
        let references: Vec<_> = references
            .iter()
            .zip(&self.scenes)
            .enumerate()
            .map(|(index, ((e_ref, drift), (name, _)))| {
                json!({"scene": index, "name": name, "E_tr": e_ref, "energy_drift": drift})
            })
            .collect();
        Ok(Output::table(
            rows_frame(&rows)?,
            json!({
                "reference": {"method": Method::Dop853.name(), "tolerance": self.reference_tolerance},
                "references": references,
                "repeats": self.repeats,
                "timing_threads": threads,
                "machine": machine(),
                "runs": self.scenes.len() * self.settings.len() * self.repeats,
            }),
        )
        .with_simulated(simulated))
    }

    /// Scene `index` by `setting`, [`WorkPrecision::repeats`] times on this thread (fewer if
    /// it fails): its best wall time and its last outcome.
    fn timed(&self, index: usize, setting: &Setting) -> Timed {
        let mut scenario = self.scenes[index].1.scenario.clone();
        scenario.method = setting.choice;
        scenario.accuracy = setting.accuracy;
        let mut best_ms = f64::INFINITY;
        let mut runs = 0;
        loop {
            let t0 = Instant::now();
            runs += 1;
            let outcome = measured_run(&scenario).map_err(|e| e.to_string());
            best_ms = best_ms.min(t0.elapsed().as_secs_f64() * 1e3);
            if outcome.is_err() || runs == self.repeats {
                return Timed {
                    best_ms,
                    runs,
                    outcome,
                };
            }
        }
    }
}

/// What [`WorkPrecision::timed`] measured of one setting.
struct Timed {
    /// Best wall time of the runs, in ms.
    best_ms: f64,
    /// Runs made.
    runs: usize,
    /// The last run's outcome.
    outcome: std::result::Result<Outcome, String>,
}

/// How many runs are timed at once when the stage does not say: one per physical core, so that
/// the runs need not share a core's execution units, as two hardware threads of one core do
/// (Linux's `thread_siblings_list`; one run at a time where the topology is unknown). The
/// threads are not pinned: the scheduler spreads them over idle cores. On this project's
/// 2-core machine two runs at once time within 1.5% of one alone, inside the 4.5% that two
/// runs alone differ by (docs/performance.md, "The whole paper from a cold cache").
fn timing_threads() -> usize {
    let logical = std::thread::available_parallelism().map_or(1, |n| n.get());
    let siblings =
        std::fs::read_to_string("/sys/devices/system/cpu/cpu0/topology/thread_siblings_list")
            .ok()
            .and_then(|list| cpus_in_list(&list));
    match siblings {
        Some(per_core) if per_core > 0 => (logical / per_core).max(1),
        _ => 1,
    }
}

/// The number of CPUs in a Linux CPU list such as `0-3,8`; `None` if it does not parse.
fn cpus_in_list(list: &str) -> Option<usize> {
    list.trim()
        .split(',')
        .map(|part| match part.split_once('-') {
            Some((lo, hi)) => {
                let (lo, hi) = (lo.parse::<usize>().ok()?, hi.parse::<usize>().ok()?);
                (hi >= lo).then_some(hi - lo + 1)
            }
            None => part.parse::<usize>().ok().map(|_| 1),
        })
        .sum()
}

/// E_tr (and the energy drift) of DOP853 at `tolerance`. At 1e-13 round-off alone drifts the
/// energy by about 1e-10, beyond the drift bound `simulate` derives from the tolerance, so the
/// reference runs without that bound; its drift is recorded instead.
fn reference(
    scenario: &Scenario,
    tolerance: f64,
) -> std::result::Result<(f64, Option<f64>), String> {
    let accuracy = Accuracy {
        tolerance,
        tolerance_explicit: true,
        dt: None,
    };
    let mut plan = Plan::choose(
        &scenario.model,
        MethodChoice::Named(Method::Dop853),
        accuracy,
    )
    .map_err(|e| e.to_string())?;
    plan.drift_limit = f64::INFINITY;
    let outcome = run_with_plan(scenario, &plan, &mut (), true).map_err(|e| e.to_string())?;
    let drift = (!scenario.model.is_time_dependent()).then_some(outcome.stats.max_energy_drift);
    Ok((outcome.fractions.trapped, drift))
}

/// One timed run: `auto` as a user runs it; a named method exactly as asked, without the half-step
/// check `simulate` adds on a kappa ramp (this stage measures every run's error itself, against
/// the reference, and a check run would double the time it charts).
fn measured_run(scenario: &Scenario) -> std::result::Result<Outcome, woodpile_sim::SimError> {
    match scenario.method {
        MethodChoice::Auto => simulate(scenario, &mut ()),
        MethodChoice::Named(_) => {
            let plan = Plan::choose(&scenario.model, scenario.method, scenario.accuracy)?;
            run_with_plan(scenario, &plan, &mut (), true)
        }
    }
}

/// CPU model and core count, for the record.
fn machine() -> serde_json::Value {
    let cpu = std::fs::read_to_string(Path::new("/proc/cpuinfo"))
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    json!({"cpu": cpu, "cores": cores})
}

/// log10 of a positive number, floored at 1e-16 (an exact match would be minus infinity).
fn log10_floor(x: f64) -> f64 {
    x.max(1e-16).log10()
}

/// One run: a scene, a method at a setting, and what it gave (or why it failed).
struct Run<'a> {
    scene: usize,
    name: &'a str,
    setting: &'a Setting,
    /// The reference's E_tr.
    e_ref: f64,
    /// Best wall time of the repeats.
    wall_ms: f64,
    outcome: std::result::Result<Outcome, String>,
    /// Whether the scene conserves energy (so a drift is measured).
    conserves_energy: bool,
}

impl Row for Run<'_> {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let ok = self.outcome.as_ref().ok();
        let error = ok.map(|o| (o.fractions.trapped - self.e_ref).abs());
        let drift = ok
            .filter(|_| self.conserves_energy)
            .map(|o| o.stats.max_energy_drift);
        let accuracy = &self.setting.accuracy;
        vec![
            ("scene", Cell::from(self.scene as i64)),
            ("scene_name", self.name.into()),
            ("method", self.setting.method.clone().into()),
            ("method_index", Cell::from(self.setting.method_index as i64)),
            ("dt", accuracy.dt.into()),
            (
                "tolerance",
                accuracy.dt.is_none().then_some(accuracy.tolerance).into(),
            ),
            ("E_tr", ok.map(|o| o.fractions.trapped).into()),
            ("error", error.into()),
            ("log10_error", error.map(log10_floor).into()),
            ("energy_drift", drift.into()),
            ("log10_energy_drift", drift.map(log10_floor).into()),
            ("steps", ok.map(|o| o.stats.steps as i64).into()),
            ("rhs_evals", ok.map(|o| o.total_rhs_evals as i64).into()),
            ("wall_ms", ok.map(|_| self.wall_ms).into()),
            ("log10_wall_ms", ok.map(|_| self.wall_ms.log10()).into()),
            ("failure", self.outcome.as_ref().err().cloned().into()),
        ]
    }
}

impl Kind for WorkPrecision {
    fn sharing(&self) -> woodpile_pipeline::kind::Sharing {
        woodpile_pipeline::kind::Sharing::Alone
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        self.compute(ctx.name())
    }
}

#[cfg(test)]
mod tests {
    use super::cpus_in_list;

    #[test]
    fn cpu_lists_count_their_cpus() {
        assert_eq!(cpus_in_list("0\n"), Some(1));
        assert_eq!(cpus_in_list("0,8"), Some(2));
        assert_eq!(cpus_in_list("0-3,8,10-11"), Some(7));
        assert_eq!(cpus_in_list("3-1"), None);
        assert_eq!(cpus_in_list("zero"), None);
    }
}
