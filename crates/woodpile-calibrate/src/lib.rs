//! A physical scene's keys fitted to a measured trace: the lab's probe records rods'
//! velocities, and the fit finds the damping, quality factors, soft-end constants or impact
//! velocity that reproduce them, with confidence intervals.
//!
//! How, and why so:
//! - **One step sequence for the whole fit.** `auto` chooses its step anew for every scene,
//!   and a step that moves with a parameter makes the residuals jump (a 1% change of γ took
//!   `auto` from 4,957 to 16,522 steps). So the starting scene is run once with `auto`, and
//!   every evaluation of the fit then runs the method `auto` verified there at its step
//!   ([`prediction::Stepping::Fixed`]).
//! - **Bounded Levenberg–Marquardt** ([`woodpile_analysis::least_squares`]), weighted by the
//!   trace's σ where it gives one, with standard errors from s² (JᵀJ)⁻¹ and 95% intervals as
//!   ±1.96 of them (the normal approximation; a parameter on its bound is flagged).
//! - **Verified at the end.** The fitted scene is run again as written (`auto` at its
//!   tolerance), and the fixed-step prediction must agree with it to a tenth of the residuals'
//!   RMS (or to the tolerance times the velocity scale, for a trace with no noise):
//!   the step the fit ran on moved the fit by less than the noise.

pub mod keys;
pub mod prediction;
pub mod synthetic;
pub mod testing;
pub mod trace;

use std::path::Path;

pub use keys::Parameter;
pub use trace::Trace;
use woodpile_analysis::least_squares::{least_squares, Bounds, LeastSquares};
use woodpile_scene::Scene;

use prediction::{predict, Stepping};

/// The error of a fit asked to stop.
pub const STOPPED: &str = "stopped";

/// One fitted key.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Its dotted name.
    pub key: String,
    /// The fitted value.
    pub value: f64,
    /// Its standard error.
    pub std_error: f64,
    /// The 95% interval's ends, value ∓ 1.96 standard errors.
    pub low: f64,
    /// See `low`.
    pub high: f64,
    /// Whether it ended on a bound of its box (its interval then means little).
    pub at_bound: bool,
}

/// The fitted scene run as written, against the fit's fixed step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verification {
    /// The largest difference between the two predictions at the trace's rows, m/s.
    pub max_difference: f64,
    /// What it had to stay within, m/s.
    pub allowed: f64,
    /// Whether it did.
    pub passed: bool,
}

/// A finished calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// The fitted keys, in the order asked.
    pub estimates: Vec<Estimate>,
    /// The fitted scene's velocity at each trace row, m/s (the fit's fixed step).
    pub fitted: Vec<f64>,
    /// Measured minus fitted, m/s, row by row.
    pub residuals: Vec<f64>,
    /// Their root mean square, m/s.
    pub rms: f64,
    /// The method and step (s) every evaluation ran.
    pub method: &'static str,
    /// See `method`.
    pub dt_s: f64,
    /// Levenberg–Marquardt's iterations and the simulations they took.
    pub iterations: usize,
    /// See `iterations`.
    pub simulations: usize,
    /// The check of the fit's step.
    pub verification: Verification,
    /// The scene with the fitted values.
    pub scene: toml::Table,
}

/// Fits `parameters` of `scene` (a scene table read from `file`, which messages name) to
/// `trace`. `stop` is asked before every simulation; once it says yes the fit ends with an
/// error (Ctrl-C in Python).
pub fn calibrate(
    scene: &toml::Table,
    file: &Path,
    trace: &Trace,
    parameters: &[Parameter],
    stop: &dyn Fn() -> bool,
) -> Result<Calibration, String> {
    trace.check().map_err(|reason| format!("trace: {reason}"))?;
    // Before the scene is resolved: a scaled scene's own run may not even be admitted.
    if !scene.contains_key("physical") {
        return Err(prediction::NOT_PHYSICAL.into());
    }
    let problem = Problem::new(scene, file, parameters)?;
    let start = problem.start();
    let (_, first) = problem.with(&start)?;
    let (_, opening) = predict(&first, trace, Stepping::AsWritten)?;
    let dt = opening
        .plan
        .dt()
        .ok_or("the scene's method is adaptive: give a fixed-step method or auto")?;
    let fixed = Stepping::Fixed {
        method: opening.plan.method,
        dt,
    };
    let weights = trace.weights();
    let simulations = std::cell::Cell::new(0);
    let residuals = |values: &[f64]| -> Result<Vec<f64>, String> {
        if stop() {
            return Err(STOPPED.into());
        }
        simulations.set(simulations.get() + 1);
        let (_, resolved) = problem.with(values)?;
        let (predicted, _) = predict(&resolved, trace, fixed)?;
        Ok(predicted
            .iter()
            .zip(&trace.velocity)
            .zip(&weights)
            .map(|((p, m), w)| (p - m) * w)
            .collect())
    };
    let fit = best_of_starts(&residuals, &start, &problem.bounds());
    if stop() {
        return Err(STOPPED.into());
    }
    let fit = fit?;
    let mut done = problem.conclude(trace, &fit, fixed)?;
    done.iterations = fit.iterations;
    done.simulations = simulations.get() + 3;
    Ok(done)
}

/// The keys to fit in one scene, each on the scale it is fitted on.
struct Problem<'a> {
    scene: &'a toml::Table,
    file: &'a Path,
    parameters: &'a [Parameter],
    scales: Vec<Scale>,
}

impl<'a> Problem<'a> {
    fn new(
        scene: &'a toml::Table,
        file: &'a Path,
        parameters: &'a [Parameter],
    ) -> Result<Problem<'a>, String> {
        if parameters.is_empty() {
            return Err("no parameters to fit".into());
        }
        for p in parameters {
            p.check()?;
        }
        Ok(Problem {
            scene,
            file,
            parameters,
            scales: parameters.iter().map(Scale::of).collect(),
        })
    }

    /// Where the fit starts, on the fitted scale: each parameter's `start`, else the scene's
    /// value if it lies in the box, else the box's middle.
    fn start(&self) -> Vec<f64> {
        self.parameters
            .iter()
            .zip(&self.scales)
            .map(|(p, scale)| {
                let middle = 0.5 * (p.min + p.max);
                let from_scene =
                    keys::get(self.scene, &p.key).filter(|v| (p.min..=p.max).contains(v));
                scale.to_fit(p.start.or(from_scene).unwrap_or(middle))
            })
            .collect()
    }

    /// The boxes on the fitted scale.
    fn bounds(&self) -> Vec<Bounds> {
        self.parameters
            .iter()
            .zip(&self.scales)
            .map(|(p, scale)| Bounds {
                min: scale.to_fit(p.min),
                max: scale.to_fit(p.max),
                // A logarithm's size is not its value: step it by a relative STEP of the value.
                step: (*scale == Scale::Log).then_some(woodpile_analysis::least_squares::STEP),
            })
            .collect()
    }

    /// The scene with the fitted-scale `values` set, as a table and resolved.
    fn with(&self, values: &[f64]) -> Result<(toml::Table, Scene), String> {
        let mut table = self.scene.clone();
        for ((p, scale), &v) in self.parameters.iter().zip(&self.scales).zip(values) {
            keys::set(&mut table, &p.key, scale.to_key(v))?;
        }
        let resolved =
            woodpile_scene::from_table(table.clone(), self.file).map_err(|e| e.to_string())?;
        Ok((table, resolved))
    }

    /// The calibration at `fit`'s end: its estimates, its residuals on the fit's step, and
    /// that step checked against the scene run as written (iterations and simulations left
    /// for the caller).
    fn conclude(
        &self,
        trace: &Trace,
        fit: &LeastSquares,
        fixed: Stepping,
    ) -> Result<Calibration, String> {
        let (table, best) = self.with(&fit.params)?;
        let (fitted, _) = predict(&best, trace, fixed)?;
        let (as_written, _) = predict(&best, trace, Stepping::AsWritten)?;
        let residuals: Vec<f64> = trace
            .velocity
            .iter()
            .zip(&fitted)
            .map(|(m, f)| m - f)
            .collect();
        let rms = (residuals.iter().map(|r| r * r).sum::<f64>() / residuals.len() as f64).sqrt();
        let verification = verify(&best, &fitted, &as_written, rms);
        let time_s = best.physical.as_ref().map_or(1.0, |p| p.scales.time_s());
        let Stepping::Fixed { method, dt } = fixed else {
            return Err("the fit ran on no fixed step".into());
        };
        Ok(Calibration {
            estimates: self
                .parameters
                .iter()
                .zip(&self.scales)
                .zip(fit.params.iter().zip(&fit.std_errors))
                .zip(&fit.at_bound)
                .map(|(((p, scale), (&u, &se)), &at_bound)| scale.estimate(&p.key, u, se, at_bound))
                .collect(),
            fitted,
            residuals,
            rms,
            method: method.name(),
            dt_s: dt * time_s,
            iterations: 0,
            simulations: 0,
            verification,
            scene: table,
        })
    }
}

/// Levenberg–Marquardt from the two best of several starts: the one asked for, and a grid of
/// three points a parameter across its box (its 20%, 50% and 80% points, on the scale it is
/// fitted on) for up to three parameters. A trace can have more than one valley: a resonator's
/// Q fitted from far above its value slides towards an undamped ringing that γ half mimics.
/// Each start costs one simulation; the fit keeps the lower sum of squares.
fn best_of_starts<F>(
    residuals: &F,
    asked: &[f64],
    bounds: &[Bounds],
) -> Result<LeastSquares, String>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, String>,
{
    let mut starts = vec![asked.to_vec()];
    if bounds.len() <= 3 {
        let axes: Vec<[f64; 3]> = bounds
            .iter()
            .map(|b| [0.2, 0.5, 0.8].map(|f| b.min + f * (b.max - b.min)))
            .collect();
        for k in 0..3usize.pow(bounds.len() as u32) {
            let point = (0..bounds.len()).map(|i| axes[i][k / 3usize.pow(i as u32) % 3]);
            starts.push(point.collect());
        }
    }
    let ssr =
        |x: &Vec<f64>| residuals(x).map_or(f64::INFINITY, |r| r.iter().map(|v| v * v).sum::<f64>());
    let mut ranked: Vec<(f64, Vec<f64>)> = starts.into_iter().map(|x| (ssr(&x), x)).collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best: Option<LeastSquares> = None;
    let mut last_error = String::new();
    for (_, start) in ranked.iter().take(2) {
        match least_squares(residuals, start, bounds) {
            Ok(fit) if best.as_ref().is_none_or(|b| fit.ssr < b.ssr) => best = Some(fit),
            Ok(_) => {}
            Err(e) => last_error = e,
        }
    }
    polish(residuals, best.ok_or(last_error)?, bounds)
}

/// Nelder–Mead from Levenberg–Marquardt's end, in steps of two standard errors: a simulation's
/// residuals are smooth only to its event corrections' kinks (about 1e-5 of the sum of squares
/// over a 0.1% step of γ), on which a difference Jacobian can stall short of the valley's
/// floor. The polished point is kept only if its sum of squares is lower.
fn polish<F>(residuals: &F, fit: LeastSquares, bounds: &[Bounds]) -> Result<LeastSquares, String>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, String>,
{
    let inside =
        |x: &[f64]| -> Vec<f64> { x.iter().zip(bounds).map(|(&v, b)| b.clamp(v)).collect() };
    let mut objective = |x: &[f64]| -> Result<f64, String> {
        let r = residuals(&inside(x))?;
        Ok(-r.iter().map(|v| v * v).sum::<f64>())
    };
    let steps: Vec<f64> = fit
        .std_errors
        .iter()
        .zip(bounds)
        .map(|(&se, b)| match se.is_finite() && se > 0.0 {
            true => 2.0 * se,
            false => 0.01 * (b.max - b.min),
        })
        .collect();
    let Ok((x, value)) = woodpile_analysis::nelder_mead::maximise(
        &mut objective,
        &fit.params,
        &steps,
        -fit.ssr,
        POLISH_EVALUATIONS,
    ) else {
        return Ok(fit);
    };
    if -value >= fit.ssr {
        return Ok(fit);
    }
    let mut polished = woodpile_analysis::least_squares::assess(residuals, &inside(&x), bounds)?;
    polished.iterations = fit.iterations;
    Ok(polished)
}

/// Most simulations the polish may spend.
const POLISH_EVALUATIONS: usize = 60;

/// How a parameter is fitted: a positive one (a damping, a Q, a spring) by its logarithm,
/// since its effect scales with it and Levenberg–Marquardt then meets a rounder valley;
/// others as they are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scale {
    Log,
    Linear,
}

impl Scale {
    fn of(p: &Parameter) -> Scale {
        match p.min > 0.0 {
            true => Scale::Log,
            false => Scale::Linear,
        }
    }

    fn to_fit(self, value: f64) -> f64 {
        match self {
            Scale::Log => value.ln(),
            Scale::Linear => value,
        }
    }

    fn to_key(self, u: f64) -> f64 {
        match self {
            Scale::Log => u.exp(),
            Scale::Linear => u,
        }
    }

    /// The estimate from the fitted `u` and its standard error: a log-fitted parameter's
    /// interval is exp(u ∓ 1.96 se), and its standard error value · se (the delta method).
    fn estimate(self, key: &str, u: f64, se: f64, at_bound: bool) -> Estimate {
        let value = self.to_key(u);
        let (std_error, low, high) = match self {
            Scale::Log => (value * se, (u - 1.96 * se).exp(), (u + 1.96 * se).exp()),
            Scale::Linear => (se, u - 1.96 * se, u + 1.96 * se),
        };
        Estimate {
            key: key.to_string(),
            value,
            std_error,
            low,
            high,
            at_bound,
        }
    }
}

/// The fixed step's prediction against the scene run as written.
fn verify(scene: &Scene, fitted: &[f64], as_written: &[f64], rms: f64) -> Verification {
    let max_difference = fitted
        .iter()
        .zip(as_written)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let speed = scene.physical.as_ref().map_or(1.0, |p| p.scales.velocity);
    let allowed = (0.1 * rms).max(scene.scenario.accuracy.tolerance * speed);
    Verification {
        max_difference,
        allowed,
        passed: max_difference <= allowed,
    }
}
