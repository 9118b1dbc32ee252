//! The paper's five sweeps, whole, against the numba script in one run: the comparison the
//! speed targets are stated in. woodpile runs each sweep stage as `woodpile run` does (every
//! core, into an empty results tree, so no point is cached). The trees are removed only at the
//! end ([`Scratch`]): creating files just after deleting thousands makes ext4 search its
//! inode tables for recently deleted ones, which cost a fresh F4 run 0.8 s of system time
//! (1.6 s against 0.1 s); the numba script
//! (`baseline/rk4_numba_scenes.py`, RK4 at dt = 0.01 on the full chain, as a researcher would
//! write it) runs the same grid's scenes split over as many processes as there are cores. Then,
//! optionally, the whole paper from a cold cache, against the numba sweeps' total.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use serde_json::{json, Value};
use woodpile_pipeline::events::Silent;
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::Pipeline;
use woodpile_sim::model::{Boundary, Coupling};
use woodpile_sim::simulation::Scenario;
use woodpile_stages::grid::{point, point_count};
use woodpile_stages::sampling::SURVEY_SWEEPS;
use woodpile_stages::sweep::Sweep;
use woodpile_stages::KINDS;

/// One sweep timed on both sides.
#[derive(Debug, Clone)]
pub struct SweepTiming {
    /// The sweep's label (`F4`, ...).
    pub label: String,
    /// Its grid points.
    pub points: usize,
    /// woodpile's wall time for the stage, s.
    pub woodpile_s: f64,
    /// The numba script's wall time over the same scenes on every core, s; or why it did
    /// not run.
    pub numba_s: Result<f64, String>,
    /// The largest difference of R, T or E_tr between the script's answer and woodpile's
    /// (whose own error is within the sweep's tolerance), over the points both answered.
    pub numba_worst: Option<f64>,
    /// Points the script answered with a non-finite number.
    pub numba_failed: usize,
}

/// A point's final fractions (R, T, E_tr), or `None` where the run failed.
type Shares = Option<[f64; 3]>;

/// The paper's sweeps ([`SURVEY_SWEEPS`]: F4, F5, F6, F7 coarse, F7 fine) under
/// `pipeline_dir`, each timed on both sides; `max_points` (when given) keeps every k-th point
/// of each grid so that at most that many run, for a quick look.
pub fn time_sweeps(
    pipeline_dir: &Path,
    numba_script: Option<&str>,
    max_points: Option<usize>,
    scratch: &Scratch,
) -> Result<Vec<SweepTiming>, String> {
    let pipeline = Pipeline::load(pipeline_dir, KINDS).map_err(|e| e.to_string())?;
    let workers = std::thread::available_parallelism().map_or(1, usize::from);
    let mut timings = Vec::new();
    for (stage, label) in SURVEY_SWEEPS {
        let scenes = grid_scenes(&pipeline, stage, max_points)?;
        let (woodpile_s, ours) = match max_points {
            None => time_stage(&pipeline, stage, scratch)?,
            Some(_) => time_scenes(&scenes),
        };
        let numba = numba_script
            .ok_or_else(|| "no --numba-scenes script".to_string())
            .and_then(|script| time_numba(script, &scenes, workers));
        let theirs = numba
            .as_ref()
            .map(|(_, shares)| shares.as_slice())
            .unwrap_or(&[]);
        let (numba_worst, numba_failed) = disagreement(&ours, theirs);
        timings.push(SweepTiming {
            label: label.to_string(),
            points: scenes.len(),
            woodpile_s,
            numba_s: numba.map(|(seconds, _)| seconds),
            numba_worst,
            numba_failed,
        });
    }
    Ok(timings)
}

/// The whole pipeline under `pipeline_dir` from nothing (every stage, figures included), s.
pub fn time_whole_paper(pipeline_dir: &Path, scratch: &Scratch) -> Result<f64, String> {
    let pipeline = Pipeline::load(pipeline_dir, KINDS).map_err(|e| e.to_string())?;
    timed_run(&pipeline, Vec::new(), &scratch.fresh())
}

/// Every point's scenario of sweep stage `stage`, in grid order (every k-th with
/// `max_points`).
fn grid_scenes(
    pipeline: &Pipeline,
    stage: &str,
    max_points: Option<usize>,
) -> Result<Vec<Scenario>, String> {
    let sweep = pipeline
        .stage(stage)
        .ok()
        .and_then(|s| s.get::<Sweep>())
        .ok_or_else(|| format!("no sweep stage `{stage}`"))?;
    let count = point_count(&sweep.grid.axes);
    let every = max_points.map_or(1, |m| count.div_ceil(m.max(1)));
    (0..count)
        .step_by(every)
        .map(|i| {
            let scene = sweep.scene_with(&point(&sweep.grid.axes, i), None);
            scene.map(|s| s.scenario).map_err(|e| e.to_string())
        })
        .collect()
}

/// Runs stage `stage` alone into a fresh results tree, as `woodpile run` would: s, and each
/// point's final fractions from its table.
fn time_stage(
    pipeline: &Pipeline,
    stage: &str,
    scratch: &Scratch,
) -> Result<(f64, Vec<Shares>), String> {
    let tree = scratch.fresh();
    let seconds = timed_run(pipeline, vec![stage.to_string()], &tree)?;
    let table = tree.join("results").join(format!("{stage}.parquet"));
    Ok((seconds, final_shares(&table)?))
}

/// Each point's fractions at its last sample, from a sweep table, by point.
fn final_shares(table: &Path) -> Result<Vec<Shares>, String> {
    use woodpile_points::rows::sweep;
    let frame = woodpile_pipeline::table::read(table).map_err(|e| e.to_string())?;
    let column =
        |name| woodpile_pipeline::table::f64_column(&frame, name).map_err(|e| e.to_string());
    let (point, t) = (column(sweep::POINT)?, column(sweep::TIME)?);
    let shares = [sweep::REFLECTED, sweep::TRANSMITTED, sweep::TRAPPED].map(column);
    let [r, tr, e] = shares;
    let (r, tr, e) = (r?, tr?, e?);
    let points = point.iter().flatten().fold(0.0f64, |m, &p| m.max(p + 1.0)) as usize;
    let mut last: Vec<(f64, Shares)> = vec![(f64::NEG_INFINITY, None); points];
    for k in 0..point.len() {
        let (Some(p), Some(time)) = (point[k], t[k]) else {
            continue;
        };
        let slot = &mut last[p as usize];
        if time > slot.0 {
            *slot = (time, r[k].zip(tr[k]).zip(e[k]).map(|((a, b), c)| [a, b, c]));
        }
    }
    Ok(last.into_iter().map(|(_, shares)| shares).collect())
}

/// The largest difference of any fraction between `ours` and `theirs` over the points both
/// answered with finite numbers, and how many of `theirs` are not finite.
fn disagreement(ours: &[Shares], theirs: &[[f64; 3]]) -> (Option<f64>, usize) {
    let failed = theirs
        .iter()
        .filter(|s| !s.iter().all(|x| x.is_finite()))
        .count();
    let worst = ours
        .iter()
        .zip(theirs)
        .filter_map(|(o, t)| o.map(|o| (o, t)))
        .filter(|(_, t)| t.iter().all(|x| x.is_finite()))
        .map(|(o, t)| (0..3).map(|k| (o[k] - t[k]).abs()).fold(0.0, f64::max))
        .reduce(f64::max);
    (worst, failed)
}

/// Runs `targets` (all stages when empty) into the tree `tree`: s.
fn timed_run(pipeline: &Pipeline, targets: Vec<String>, tree: &Path) -> Result<f64, String> {
    let options = RunOptions {
        targets,
        force: true,
        dry_run: false,
        results: tree.join("results"),
        figures: tree.join("figures"),
    };
    let t0 = Instant::now();
    run(pipeline, &options, &Silent).map_err(|e| e.to_string())?;
    Ok(t0.elapsed().as_secs_f64())
}

/// A folder of this process's own for the timed runs' trees, removed when dropped (after
/// every timing, not between them).
pub struct Scratch {
    root: PathBuf,
    made: std::cell::Cell<usize>,
}

impl Scratch {
    /// An empty scratch folder in the system's temporary folder.
    pub fn new() -> Scratch {
        let root = std::env::temp_dir().join(format!("woodpile-bench-{}", std::process::id()));
        Scratch {
            root,
            made: std::cell::Cell::new(0),
        }
    }

    /// A path for a new tree, not used before.
    fn fresh(&self) -> PathBuf {
        self.made.set(self.made.get() + 1);
        self.root.join(self.made.get().to_string())
    }
}

impl Default for Scratch {
    fn default() -> Self {
        Scratch::new()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.root);
    }
}

/// woodpile's `simulate` over `scenes` on every core (the subsampled look, which runs no
/// stage): s, and each scene's fractions.
fn time_scenes(scenes: &[Scenario]) -> (f64, Vec<Shares>) {
    use rayon::prelude::*;
    let t0 = Instant::now();
    let shares = scenes
        .par_iter()
        .map(|s| {
            let out = woodpile_sim::simulation::simulate(s, &mut ()).ok()?;
            let f = out.fractions;
            Some([f.reflected, f.transmitted, f.trapped])
        })
        .collect();
    (t0.elapsed().as_secs_f64(), shares)
}

/// The scene as the numba script reads it: `res` holds `[site, eps, kappa, p]` per resonator.
/// The script knows the paper's chain only (unit masses, Hertz contacts, walls or free ends,
/// no damping, constant couplings): any other scene is refused, not misread.
pub fn numba_scene(scene: &Scenario, dt: f64) -> Result<Value, String> {
    let model = &scene.model;
    let plain_ends = matches!(model.boundary(), Boundary::Fixed | Boundary::Free);
    let unit_masses = (0..model.n_sites()).all(|i| model.site_mass(i) == 1.0);
    if !plain_ends || !unit_masses || !model.law().is_papers() || model.is_dissipative() {
        return Err("the numba baseline takes the paper's chain only".to_string());
    }
    let res = model
        .resonators()
        .iter()
        .map(|r| match r.coupling {
            Coupling::Constant(k) => Ok(json!([r.site, r.eps, k, r.p])),
            _ => Err("the numba baseline takes constant couplings only".to_string()),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(json!({
        "n": model.n_sites(),
        "fixed": model.boundary() == Boundary::Fixed,
        "striker": scene.impulse_site,
        "velocity": scene.impulse_velocity,
        "t_end": scene.t_end,
        "dt": dt,
        "lo": scene.region.lo(),
        "hi": scene.region.hi(),
        "res": res,
    }))
}

/// The numba script over `scenes` at dt = 0.01, dealt round-robin to `workers` processes
/// running at once: the slowest process's time (its compile excluded, as the script reports
/// it), s, and every scene's fractions in `scenes`' order.
fn time_numba(
    script: &str,
    scenes: &[Scenario],
    workers: usize,
) -> Result<(f64, Vec<[f64; 3]>), String> {
    let input = scenes
        .iter()
        .map(|s| numba_scene(s, 0.01))
        .collect::<Result<Vec<_>, _>>()?;
    let workers = workers.clamp(1, input.len().max(1));
    let started: Vec<_> = (0..workers)
        .map(|w| {
            let share: Vec<Value> = input.iter().skip(w).step_by(workers).cloned().collect();
            spawn_numba(script, &share)
        })
        .collect();
    // Every started process is waited for before any error is reported: none is left running
    // beside the next sweep's timing.
    let outputs: Vec<Result<Value, String>> = started
        .into_iter()
        .map(|child| child.and_then(|c| finished(script, c)))
        .collect();
    let mut slowest_ms = 0.0f64;
    let mut shares = vec![[f64::NAN; 3]; scenes.len()];
    for (w, output) in outputs.into_iter().enumerate() {
        let v = output?;
        slowest_ms = slowest_ms.max(v["ms"].as_f64().ok_or("no ms")?);
        let answers = v["fractions"].as_array().ok_or("no fractions")?;
        let expected = (w..scenes.len()).step_by(workers).count();
        if answers.len() != expected {
            return Err(format!(
                "{script}: {} answers for {expected} scenes",
                answers.len()
            ));
        }
        for (k, f) in answers.iter().enumerate() {
            let get = |key: &str| f[key].as_f64().unwrap_or(f64::NAN);
            shares[w + k * workers] = [get("R"), get("T"), get("E_tr")];
        }
    }
    Ok((slowest_ms / 1e3, shares))
}

/// The JSON line a started script printed, or why it failed (its stderr).
fn finished(script: &str, child: std::process::Child) -> Result<Value, String> {
    let out = child.wait_with_output().map_err(|e| e.to_string())?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        return Err(format!("{script} failed: {}", stderr.trim()));
    }
    serde_json::from_slice(&out.stdout).map_err(|e| format!("{script}: {e}"))
}

/// `python3 script 1` reading `scenes` on stdin, started.
fn spawn_numba(script: &str, scenes: &[Value]) -> Result<std::process::Child, String> {
    let mut child = Command::new("python3")
        .args([script, "1"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("python3 {script}: {e}"))?;
    let text = Value::Array(scenes.to_vec()).to_string();
    let mut stdin = child.stdin.take().ok_or("no stdin")?;
    if let Err(e) = stdin.write_all(text.as_bytes()) {
        // The script died before reading its scenes: its own message says why.
        drop(stdin);
        return Err(finished(script, child)
            .err()
            .unwrap_or_else(|| e.to_string()));
    }
    Ok(child)
}
