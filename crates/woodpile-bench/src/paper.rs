//! The paper-level comparison of `make bench`: a seeded sample of the sweeps' own scenes (F4,
//! F7 coarse, F7 fine), woodpile at the pipeline's settings (each sweep's `auto` tolerance and
//! sample interval) against `baseline/rk4_numba_scenes.py` at RK4 dt = 0.01 on the full chain,
//! one thread each, in the same run, and both sides' worst error against a tight reference
//! (`rk4-contact` at dt = 0.001). Each side's time is its summed time over the sample, the best
//! of [`REPEATS`] passes (one pass varied by ±15% from run to run), and its first pass's: the
//! time a user meets, who runs a sample once.

use std::io::Write;
use std::process::{Command, Stdio};
use std::time::Instant;
use woodpile_stages::KINDS;

use serde_json::Value;
use woodpile_pipeline::Pipeline;
use woodpile_sim::energy::Fractions;
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{reference_dt, reference_fractions, tolerance};
use woodpile_stages::sampling::sampled_scenes;

/// The sweeps the sample is drawn from, with their labels.
pub const PAPER_SWEEPS: &[(&str, &str)] = &[
    ("f4_sweep", "F4"),
    ("f7_coarse_sweep", "F7 coarse"),
    ("f7_fine_sweep", "F7 fine"),
];

/// Passes over the sample each side is timed on; the best counts.
pub const REPEATS: usize = 3;

/// One side of the comparison over the whole sample.
#[derive(Debug, Clone)]
pub struct Side {
    /// Who ran it, and how.
    pub name: String,
    /// Summed wall time over the sample, ms: the best pass.
    pub ms: f64,
    /// The same, of the first pass.
    pub first_ms: f64,
    /// Largest error of R, T or E_tr over the sample against the reference.
    pub worst_error: f64,
}

/// The comparison's result.
#[derive(Debug, Clone)]
pub struct Comparison {
    /// Scenes in the sample.
    pub scenes: usize,
    /// woodpile at the pipeline's settings, then at tolerance 1e-6 for every scene.
    pub woodpile: [Side; 2],
    /// The numba script, if it ran.
    pub numba: Result<Side, String>,
}

/// `per_sweep` scenes of each of [`PAPER_SWEEPS`] drawn with `seed` from the stage files under
/// `pipeline_dir`, as the pipeline runs them.
pub fn paper_sample(
    pipeline_dir: &str,
    per_sweep: usize,
    seed: u64,
) -> Result<Vec<(String, Scenario)>, String> {
    let pipeline = Pipeline::load(pipeline_dir.as_ref(), KINDS).map_err(|e| e.to_string())?;
    sampled_scenes(&pipeline, PAPER_SWEEPS, per_sweep, seed).map_err(|e| e.to_string())
}

/// Runs both sides over `scenes` (numba through `python3 script` when given).
pub fn compare(scenes: &[(String, Scenario)], numba_script: Option<&str>) -> Comparison {
    let references: Vec<Fractions> = scenes
        .iter()
        .map(|(name, s)| {
            reference_fractions(s, reference_dt(&s.model))
                .unwrap_or_else(|e| panic!("reference for {name}: {e}"))
        })
        .collect();
    let at_1e6: Vec<(String, Scenario)> = scenes
        .iter()
        .map(|(name, s)| {
            let scene = Scenario {
                accuracy: tolerance(1e-6),
                ..s.clone()
            };
            (name.clone(), scene)
        })
        .collect();
    let woodpile = [
        woodpile_side("woodpile, each sweep's own settings", scenes, &references),
        woodpile_side(
            "woodpile, tolerance 1e-6 for every scene",
            &at_1e6,
            &references,
        ),
    ];
    let numba = numba_script
        .ok_or_else(|| "no --numba script".to_string())
        .and_then(|script| numba_side(script, scenes, &references));
    Comparison {
        scenes: scenes.len(),
        woodpile,
        numba,
    }
}

/// woodpile over the sample on this thread: summed wall time and worst error.
fn woodpile_side(label: &str, scenes: &[(String, Scenario)], references: &[Fractions]) -> Side {
    let mut best_ms = f64::INFINITY;
    let mut first_ms = None;
    let mut worst = 0.0f64;
    for _ in 0..REPEATS {
        let mut ms = 0.0;
        for ((name, scene), reference) in scenes.iter().zip(references) {
            let t0 = Instant::now();
            let out = simulate(scene, &mut ()).unwrap_or_else(|e| panic!("{name}: {e}"));
            ms += t0.elapsed().as_secs_f64() * 1e3;
            worst = worst.max(out.fractions.largest_difference(reference));
        }
        best_ms = best_ms.min(ms);
        first_ms.get_or_insert(ms);
    }
    Side {
        name: label.into(),
        ms: best_ms,
        first_ms: first_ms.unwrap_or(f64::NAN),
        worst_error: worst,
    }
}

fn numba_side(
    script: &str,
    scenes: &[(String, Scenario)],
    references: &[Fractions],
) -> Result<Side, String> {
    let input = scenes
        .iter()
        .map(|(_, s)| crate::sweeps::numba_scene(s, 0.01))
        .collect::<Result<Vec<_>, _>>()?;
    let mut child = Command::new("python3")
        .arg(script)
        .arg(REPEATS.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("python3 {script}: {e}"))?;
    child
        .stdin
        .take()
        .ok_or("no stdin")?
        .write_all(Value::Array(input).to_string().as_bytes())
        .map_err(|e| e.to_string())?;
    let out = child.wait_with_output().map_err(|e| e.to_string())?;
    if !out.status.success() {
        return Err(format!(
            "{script} failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let v: Value = serde_json::from_slice(&out.stdout).map_err(|e| format!("{script}: {e}"))?;
    let fractions = v["fractions"].as_array().ok_or("no fractions")?;
    let mut worst = 0.0f64;
    for (f, reference) in fractions.iter().zip(references) {
        let get = |k: &str| f[k].as_f64().unwrap_or(f64::NAN);
        let numba = Fractions {
            reflected: get("R"),
            transmitted: get("T"),
            trapped: get("E_tr"),
            striker: 0.0,
            dissipated: 0.0,
            total: reference.total,
        };
        worst = worst.max(numba.largest_difference(reference));
    }
    Ok(Side {
        name: "numba RK4 dt = 0.01, full chain".into(),
        ms: v["ms"].as_f64().ok_or("no ms")?,
        first_ms: v["first_ms"].as_f64().ok_or("no first_ms")?,
        worst_error: worst,
    })
}
