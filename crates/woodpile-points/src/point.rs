//! One point: a scene simulated once, its fraction series or why it failed, the key it is
//! cached under, and the statistics a set of points reports.

use serde_json::json;
use woodpile_scene::Scene;
use woodpile_sim::integrate::{StepControl, Stoppable};
use woodpile_sim::observe::FractionSeries;
use woodpile_sim::simulation::{simulate_batch, Outcome, Scenario};
use woodpile_sim::{Share, SimError};

use woodpile_files::key::{code_version, Key};
use woodpile_files::PointStats;

use crate::canonical::scene_json;

/// What simulating one scene gave: its fraction time series, or why it failed.
pub type PointResult = std::result::Result<PointData, String>;

/// A successful point: the sampled fractions and the facts that make them trustworthy.
#[derive(Debug, Clone, PartialEq)]
pub struct PointData {
    /// The method that produced the reported run.
    pub method: String,
    /// Its fixed step as taken (the longest), if any.
    pub dt: Option<f64>,
    /// Steps of the reported run.
    pub steps: u64,
    /// Right-hand-side evaluations of every run made (auto's verification included).
    pub rhs_evals: u64,
    /// `auto`'s Richardson error estimate.
    pub error_estimate: Option<f64>,
    /// Largest relative energy drift (None where energy is not conserved).
    pub energy_drift: Option<f64>,
    /// E(0).
    pub e_initial: f64,
    /// E(t_end).
    pub e_final: f64,
    /// When the wave first reached an end of the chain (None: it never did before t_end).
    pub end_reached_at: Option<f64>,
    /// Sample times.
    pub t: Vec<f64>,
    /// R(t).
    pub reflected: Vec<f64>,
    /// T(t).
    pub transmitted: Vec<f64>,
    /// E_tr(t).
    pub trapped: Vec<f64>,
    /// E(t).
    pub energy: Vec<f64>,
    /// S(t), the striker's share: only for a scene with a striker, so that a paper point's
    /// data (and file) is what it was before strikers existed.
    pub striker: Option<Vec<f64>>,
    /// D(t), the dissipated share: only for a dissipative scene, for the same reason.
    pub dissipated: Option<Vec<f64>>,
}

impl PointData {
    /// `share` at sample `sample`; `None` for S at a point with no striker. A point whose
    /// values dissipate nothing has no D series, and shows D = 0: it lost nothing.
    pub fn share_at(&self, share: Share, sample: usize) -> Option<f64> {
        match share {
            Share::Reflected => Some(self.reflected[sample]),
            Share::Transmitted => Some(self.transmitted[sample]),
            Share::Trapped => Some(self.trapped[sample]),
            Share::Striker => self.striker.as_ref().map(|s| s[sample]),
            Share::Dissipated => Some(self.dissipated.as_ref().map_or(0.0, |d| d[sample])),
        }
    }
}

/// Which energy a sweep's fractions split.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shares {
    /// Total energy, fractions of E(t) (the paper's Sections IV–V).
    Energy,
    /// Kinetic energy divided by the impact energy (the woodpile experiment, paper Fig. 2).
    Kinetic,
}

impl Shares {
    /// An empty series of this kind for `scenario`, or why it cannot be recorded.
    pub fn recorder(self, scenario: &Scenario) -> Result<FractionSeries, String> {
        let (model, region) = (&scenario.model, scenario.region);
        match self {
            Shares::Energy => Ok(FractionSeries::new(model, region)),
            Shares::Kinetic => {
                let impact = scenario.impact_energy();
                if impact.is_nan() || impact <= 0.0 {
                    return Err(
                        "a kinetic series is divided by the impact energy, which is zero".into(),
                    );
                }
                Ok(FractionSeries::kinetic(model, region, impact))
            }
        }
    }
}

/// Simulates `scene`, recording its fractions at every sample.
pub fn simulate_point(scene: &Scene, kind: Shares) -> PointResult {
    simulate_point_until(scene, kind, &|| false).unwrap_or_else(|| Err("cancelled".into()))
}

/// [`simulate_point`], stopped within a sample interval once `stop()` says so (Ctrl-C in a
/// Python session): `None` then, since a cancelled run is no result and must not be cached.
pub fn simulate_point_until(
    scene: &Scene,
    kind: Shares,
    stop: &dyn Fn() -> bool,
) -> Option<PointResult> {
    simulate_points_until(&[scene], kind, stop).pop().flatten()
}

/// [`simulate_point_until`] of each of `scenes`, four neighbours at a time in lanes where they
/// allow it ([`simulate_batch`]): the same points, sooner. A sweep's neighbouring points are
/// mostly the same chain at one first step.
pub fn simulate_points_until(
    scenes: &[&Scene],
    kind: Shares,
    stop: &dyn Fn() -> bool,
) -> Vec<Option<PointResult>> {
    let mut results: Vec<Option<PointResult>> = vec![None; scenes.len()];
    let mut runnable = Vec::with_capacity(scenes.len());
    let mut recorders = Vec::with_capacity(scenes.len());
    for (k, scene) in scenes.iter().enumerate() {
        match kind.recorder(&scene.scenario) {
            Ok(series) => {
                runnable.push(k);
                recorders.push(Stoppable {
                    inner: series,
                    stop,
                });
            }
            Err(reason) => results[k] = Some(Err(reason)),
        }
    }
    let scenarios: Vec<&Scenario> = runnable.iter().map(|&k| &scenes[k].scenario).collect();
    let outcomes = simulate_batch(&scenarios, &mut recorders);
    for ((k, outcome), watched) in runnable.into_iter().zip(outcomes).zip(recorders) {
        let s = &scenes[k].scenario;
        results[k] = match outcome {
            Err(SimError::Cancelled { .. }) => None,
            Err(e) => Some(Err(e.to_string())),
            Ok(out) => Some(Ok(PointData::of(s, &out, watched.inner))),
        };
    }
    results
}

impl PointData {
    /// The point of scenario `s`, whose run gave `out` and recorded `series`.
    fn of(s: &Scenario, out: &Outcome, series: FractionSeries) -> PointData {
        PointData {
            method: out.plan.method.name().to_string(),
            dt: match out.plan.control {
                // The step taken (each sample interval cut into equal steps of at most dt).
                StepControl::Fixed { .. } => Some(out.stats.max_step),
                StepControl::Adaptive { .. } => None,
            },
            steps: out.stats.steps,
            rhs_evals: out.total_rhs_evals,
            error_estimate: out.error_estimate,
            energy_drift: (!s.model.is_time_dependent()).then_some(out.stats.max_energy_drift),
            e_initial: out.e_initial,
            e_final: out.e_final,
            end_reached_at: out.stats.end_reached_at,
            t: series.t,
            reflected: series.reflected,
            transmitted: series.transmitted,
            trapped: series.trapped,
            striker: s.region.has_striker().then_some(series.striker),
            dissipated: s.model.is_dissipative().then_some(series.dissipated),
            energy: series.energy,
        }
    }

    /// The point with its last sample only (at t_end): what a table of final values keeps of
    /// each point, without holding every point's series at once.
    pub fn last_sample(mut self) -> PointData {
        let last = |v: &mut Vec<f64>| {
            let keep = v.len().saturating_sub(1);
            v.drain(..keep);
        };
        for v in [
            &mut self.t,
            &mut self.reflected,
            &mut self.transmitted,
            &mut self.trapped,
            &mut self.energy,
        ] {
            last(v);
        }
        self.striker
            .iter_mut()
            .chain(&mut self.dissipated)
            .for_each(last);
        self
    }
}

/// A point's cache key: its resolved scene, the code version and, for kinetic series only (so
/// that energy points keep their keys), the series.
pub fn point_key(scene: &Scene, series: Shares) -> Key {
    let mut key = json!({"scene": scene_json(scene), "code": code_version()});
    if series == Shares::Kinetic {
        key["series"] = json!("kinetic");
    }
    Key::of(&key)
}

/// The statistics of `results`.
pub fn stats_of(results: &[PointResult]) -> PointStats {
    let ok = || results.iter().filter_map(|r| r.as_ref().ok());
    let max = |f: fn(&PointData) -> Option<f64>| ok().filter_map(f).reduce(f64::max);
    PointStats {
        points: results.len(),
        failed: results.iter().filter(|r| r.is_err()).count(),
        simulated: 0,
        rhs_evals: ok().map(|p| p.rhs_evals).sum(),
        max_error_estimate: max(|p| p.error_estimate),
        max_energy_drift: max(|p| p.energy_drift),
    }
}
