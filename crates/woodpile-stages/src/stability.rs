//! `kind = "stability"`: where each fixed-step method fails. For every method, step and value
//! of one defect parameter (eps or p), a run of the scene is classified: 0 it meets the
//! tolerance on E_tr, 1 it runs but misses it, 2 it is unstable (non-finite state, or the
//! energy drifts by more than 100%). The runs have no drift guard, so an inaccurate but stable
//! step is told apart from an unstable one.
//!
//! ```toml
//! kind = "stability"
//! tolerance = 1e-6                  # |ΔE_tr| allowed, against `auto` at tolerance / 100
//! methods = ["rk4", "rk4-contact", "verlet", "yoshida4", "yoshida6"]
//! vary = "eps"                      # the first defect's eps, or "p"
//! values = [0.01, 0.1, 1.0, 10.0]
//! step = "dt_omega"                 # steps given as dt·ω (ω² = kappa (1 + 1/eps)), or "dt"
//! steps = [0.5, 1.0, 2.0, 3.0]
//! [scene]                           # a scene file; its first defect is varied
//! defect = [{ site = 0, eps = 1.0 }]
//! ```
//!
//! With `step = "dt_omega"` the linear stability bound of each method (dt·ω = 2√2 for RK4, 2 for
//! Verlet, ...) is a vertical line on the map, and `auto`'s largest step (dt·ω = 0.5, never above
//! 0.9 of the bound; dt·ω = 2 where it integrates the resonator exactly, `erkn6-contact`) can
//! be read off against it. Output: one row per run with the method, the
//! value (and its log10), the requested `step` (the map's grid), the step dt actually taken
//! (t_end tiled by equal steps, within 1% of the request) and its dt·ω, the method's linear
//! bound as a dt, `auto`'s first step, both again in the map's step unit as `log10_bound_step`
//! and `log10_auto_step` (the figure draws them as lines over the map), the status, the error
//! and the failure's reason.

// Comparisons are written `!(x > 0.0)` on purpose: a NaN must fail them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use rayon::prelude::*;
use serde_json::json;
use std::sync::atomic::{AtomicUsize, Ordering};
use woodpile_sim::integrate::{Accuracy, Method, MethodChoice, Plan};
use woodpile_sim::simulation::{auto_first_step, run_with_plan, simulate, Scenario};

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::{pick, Fields};
use woodpile_pipeline::kind::{Context, Kind};
use woodpile_pipeline::table::Columns;
use woodpile_pipeline::Output;

/// The defect parameter a stability map varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vary {
    /// The mass ratio of the first defect.
    Eps,
    /// The coupling exponent of the first defect.
    P,
}

/// A parsed stability stage.
#[derive(Debug, Clone)]
pub struct Stability {
    /// |ΔE_tr| allowed.
    pub tolerance: f64,
    /// The fixed-step methods.
    pub methods: Vec<Method>,
    /// What is varied.
    pub vary: Vary,
    /// Its values.
    pub values: Vec<f64>,
    /// Steps as dt·ω (true) or dt (false).
    pub steps_are_dt_omega: bool,
    /// The steps.
    pub steps: Vec<f64>,
    scene: toml::Table,
    file: std::path::PathBuf,
}

impl Stability {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Stability> {
        let tolerance: f64 = fields.required("tolerance")?;
        if !(tolerance > 0.0) {
            return Err(fields.error("tolerance", "must be > 0"));
        }
        let names: Vec<String> = fields.required("methods")?;
        let mut methods = Vec::new();
        let fixed: Vec<(&str, Method)> = Method::ALL
            .into_iter()
            .filter(|m| !m.is_adaptive())
            .map(|m| (m.name(), m))
            .collect();
        for name in names {
            let method = pick(&fixed, &name)
                .map_err(|e| fields.error("methods", format!("a fixed-step method: {e}")))?;
            methods.push(method);
        }
        let vary = fields.choice("vary", &[("eps", Vary::Eps), ("p", Vary::P)], None)?;
        let values: Vec<f64> = fields.required("values")?;
        let steps_are_dt_omega =
            fields.choice("step", &[("dt_omega", true), ("dt", false)], None)?;
        let steps: Vec<f64> = fields.required("steps")?;
        if values.is_empty() || steps.is_empty() || steps.iter().any(|s| !(*s > 0.0)) {
            return Err(fields.error("steps", "expected non-empty `values` and positive `steps`"));
        }
        let scene: toml::Table = fields.required("scene")?;
        let stage = Stability {
            tolerance,
            methods,
            vary,
            values,
            steps_are_dt_omega,
            steps,
            scene,
            file: fields.file().to_path_buf(),
        };
        for &v in &stage.values {
            stage.scene_at(v)?;
        }
        Ok(stage)
    }

    /// The scene with the first defect's parameter set to `value`.
    fn scene_at(&self, value: f64) -> Result<woodpile_scene::Scene> {
        let mut table = self.scene.clone();
        let defect = table
            .get_mut("defect")
            .and_then(|d| d.as_array_mut())
            .and_then(|a| a.first_mut())
            .and_then(|d| d.as_table_mut())
            .ok_or_else(|| PipelineError::Definition {
                file: self.file.clone(),
                key: "scene.defect".into(),
                reason: "the scene needs a first [[defect]] to vary".into(),
                source: None,
            })?;
        match self.vary {
            Vary::Eps => defect.insert("eps".into(), toml::Value::Float(value)),
            Vary::P => defect.insert("p".into(), toml::Value::Integer(value as i64)),
        };
        woodpile_scene::from_table(table, &self.file).map_err(|e| {
            crate::grid::scene_error(&self.file, "scene", e, &format!(" (at {value})"))
        })
    }

    /// The stage: each value's reference, every (value, method, step) run classified, then
    /// the summary and the table.
    pub(crate) fn compute(&self, stage: &str) -> Result<Output> {
        let references: Vec<Reference> = self
            .values
            .par_iter()
            .map(|&v| self.reference(stage, v))
            .collect::<Result<_>>()?;
        let jobs: Vec<(usize, usize, usize)> = (0..self.values.len())
            .flat_map(|v| {
                (0..self.methods.len())
                    .flat_map(move |m| (0..self.steps.len()).map(move |s| (v, m, s)))
            })
            .collect();
        let simulated = AtomicUsize::new(0);
        let runs: Vec<Run> = jobs
            .par_iter()
            .map(|&(v, m, s)| self.classified(&references[v], (v, m, s), &simulated))
            .collect();
        let summary = self.summary(&runs);
        // Each value's reference, and every run that got past choosing its plan.
        let simulated = references.len() + simulated.into_inner();
        Ok(Output::table(self.table(&runs)?, summary).with_simulated(simulated))
    }

    /// The scene at `value`, E_tr of `auto` a hundred times tighter than the tolerance, and
    /// the first step `auto` takes at the tolerance.
    fn reference(&self, stage: &str, value: f64) -> Result<Reference> {
        let scene = self.scene_at(value)?;
        let mut reference = scene.scenario.clone();
        reference.method = MethodChoice::Auto;
        reference.accuracy = Accuracy {
            tolerance: self.tolerance / 100.0,
            tolerance_explicit: true,
            dt: None,
        };
        let e_ref = simulate(&reference, &mut ())
            .map_err(|e| PipelineError::stage(stage, format!("reference at {value}: {e}")))?
            .fractions
            .trapped;
        let auto_plan = Plan::choose(
            &scene.scenario.model,
            MethodChoice::Auto,
            Accuracy {
                tolerance: self.tolerance,
                ..reference.accuracy
            },
        )
        .map_err(|e| PipelineError::stage(stage, format!("auto at {value}: {e}")))?;
        let auto_dt = auto_first_step(&scene.scenario, &auto_plan);
        Ok(Reference {
            scene,
            e_ref,
            auto_dt,
            auto_method: auto_plan.method.name(),
        })
    }

    /// Method `m` at step `s` on value `v` (whose reference is `reference`), classified.
    fn classified(
        &self,
        reference: &Reference,
        (v, m, s): (usize, usize, usize),
        simulated: &AtomicUsize,
    ) -> Run {
        let Reference {
            scene,
            e_ref,
            auto_dt,
            auto_method,
        } = reference;
        let method = self.methods[m];
        let omega = scene.scenario.model.max_linear_omega(false);
        // A step in the map's own x unit (dt or dt·ω) as a dt, and back.
        let to_dt = |step: f64| match self.steps_are_dt_omega {
            true => step / omega,
            false => step,
        };
        let to_step = |dt: f64| match self.steps_are_dt_omega {
            true => dt * omega,
            false => dt,
        };
        // The step the driver takes: t_end tiled by equal steps no longer than requested.
        let t_end = scene.scenario.t_end;
        let dt = t_end / (t_end / to_dt(self.steps[s]) - 1e-9).ceil().max(1.0);
        let (status, error, failure) = classify(
            &scene.scenario,
            method,
            dt,
            *e_ref,
            self.tolerance,
            simulated,
        );
        // A method that integrates the resonator exactly has no bound on it.
        let stepped = scene
            .scenario
            .model
            .max_linear_omega(method.integrates_harmonic_exactly());
        let bound = (stepped > 0.0).then_some(method.stability_limit() / stepped);
        Run {
            method: method.name(),
            method_index: m as i64,
            value: self.values[v],
            dt,
            step: self.steps[s],
            dt_omega: (omega > 0.0).then_some(dt * omega),
            bound,
            auto_dt: *auto_dt,
            auto_method,
            // The bound and auto's step in the map's own x unit, for the overlay lines.
            bound_step: bound.map(to_step),
            auto_step: to_step(*auto_dt),
            status,
            error,
            failure,
        }
    }

    /// The manifest's summary of `runs`.
    fn summary(&self, runs: &[Run]) -> serde_json::Value {
        let counts = |k: i64| runs.iter().filter(|r| r.status == k).count();
        // `auto` runs its method at `auto_dt` or shorter: none of those steps may be unstable.
        let auto_unstable = runs
            .iter()
            .filter(|r| r.method == r.auto_method && r.status == 2 && r.dt <= r.auto_dt)
            .count();
        json!({
            "runs": runs.len(),
            "meet_tolerance": counts(0),
            "miss_tolerance": counts(1),
            "fail": counts(2),
            "unstable_at_or_below_auto_step": auto_unstable,
            "tolerance": self.tolerance,
            "reference": {"method": "auto", "tolerance": self.tolerance / 100.0},
        })
    }

    /// The stage's table: one row per run.
    fn table(&self, runs: &[Run]) -> Result<polars::prelude::DataFrame> {
        let name = match self.vary {
            Vary::Eps => "eps",
            Vary::P => "p",
        };
        let mut c = Columns::new();
        c.str(
            "method",
            runs.iter().map(|r| Some(r.method.to_string())).collect(),
        )
        .i64(
            "method_index",
            runs.iter().map(|r| Some(r.method_index)).collect(),
        )
        .f64(name, runs.iter().map(|r| Some(r.value)).collect())
        .f64(
            &format!("log10_{name}"),
            runs.iter().map(|r| Some(r.value.log10())).collect(),
        )
        .f64("step", runs.iter().map(|r| Some(r.step)).collect())
        .f64(
            "log10_step",
            runs.iter().map(|r| Some(r.step.log10())).collect(),
        )
        .f64("dt", runs.iter().map(|r| Some(r.dt)).collect())
        .f64("dt_omega", runs.iter().map(|r| r.dt_omega).collect())
        .f64("linear_bound_dt", runs.iter().map(|r| r.bound).collect())
        .f64("auto_dt", runs.iter().map(|r| Some(r.auto_dt)).collect())
        .f64(
            "log10_bound_step",
            runs.iter().map(|r| r.bound_step.map(f64::log10)).collect(),
        )
        .f64(
            "log10_auto_step",
            runs.iter().map(|r| Some(r.auto_step.log10())).collect(),
        )
        .i64("status", runs.iter().map(|r| Some(r.status)).collect())
        .f64("error", runs.iter().map(|r| r.error).collect())
        .str("failure", runs.iter().map(|r| r.failure.clone()).collect());
        c.into_frame()
    }
}

/// One value's reference: its scene, E_tr at a hundredth of the tolerance, and `auto`'s first
/// step.
struct Reference {
    scene: woodpile_scene::Scene,
    e_ref: f64,
    auto_dt: f64,
    /// The method `auto` runs on the scene (`erkn6-contact` where a resonator is harmonic).
    auto_method: &'static str,
}

/// Runs `method` at step `dt` with no drift guard and classifies it: 2 if the state becomes
/// non-finite or the energy drifts by more than 100% (the method is unstable), 1 if it runs but
/// misses `tolerance` on E_tr, 0 if it meets it.
fn classify(
    scenario: &Scenario,
    method: Method,
    dt: f64,
    e_ref: f64,
    tolerance: f64,
    simulated: &AtomicUsize,
) -> (i64, Option<f64>, Option<String>) {
    let accuracy = Accuracy {
        tolerance,
        tolerance_explicit: false,
        dt: Some(dt),
    };
    let mut plan = match Plan::choose(&scenario.model, MethodChoice::Named(method), accuracy) {
        Ok(plan) => plan,
        Err(e) => return (2, None, Some(e.to_string())),
    };
    plan.drift_limit = f64::INFINITY;
    // One sample interval: the driver tiles each interval with equal steps no longer than dt,
    // so a single interval keeps the step within 1% of dt (shorter intervals would shrink it).
    let one_interval = Scenario {
        sample_every: scenario.t_end,
        ..scenario.clone()
    };
    simulated.fetch_add(1, Ordering::Relaxed);
    match run_with_plan(&one_interval, &plan, &mut (), true) {
        Err(e) => (2, None, Some(e.to_string())),
        Ok(o) if !(o.stats.max_energy_drift <= 1.0) => (
            2,
            None,
            Some(format!(
                "energy drift {:.3e}: unstable",
                o.stats.max_energy_drift
            )),
        ),
        Ok(o) => {
            let error = (o.fractions.trapped - e_ref).abs();
            (i64::from(!(error <= tolerance)), Some(error), None)
        }
    }
}

struct Run {
    /// The requested step (dt·ω or dt), exactly as listed: the map's grid.
    step: f64,
    method: &'static str,
    method_index: i64,
    value: f64,
    dt: f64,
    dt_omega: Option<f64>,
    bound: Option<f64>,
    auto_dt: f64,
    /// The method `auto` runs at `auto_dt` on this value's scene.
    auto_method: &'static str,
    /// The linear bound in the map's step unit (dt·ω or dt).
    bound_step: Option<f64>,
    /// `auto`'s first step in the map's step unit.
    auto_step: f64,
    status: i64,
    error: Option<f64>,
    failure: Option<String>,
}

impl Kind for Stability {
    fn sharing(&self) -> woodpile_pipeline::kind::Sharing {
        woodpile_pipeline::kind::Sharing::Parallel
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        self.compute(ctx.name())
    }
}
