//! What features a scene does not use cost it (the experiment's chain, dissipation): two
//! `woodpile` binaries, one built before those features (`COST_BASE` in the Makefile) and one
//! after, run on the same scene files side by side in one run.
//!
//! Scenes: the paper sample of `make bench` (8 seeded points each of F4, F7 coarse and F7
//! fine, at the sweeps' own settings) and the standard scene (`scenes/single_eps10.toml`,
//! `auto` at 1e-8). Each scene file is run by `woodpile simulate`, and its time is the
//! simulation's own (`wall_s` in the JSON, without the process's start). The binaries alternate
//! within every round, which side starts alternates between rounds, and each side's time is
//! its best round. Both must print the same fractions, bit for bit: the paper's numbers do not
//! change.
//!
//! A scene the new build runs with a method the old one lacks (`erkn6-contact`, on a resonator
//! too fast for DPRKN6) uses a feature, so it is left out of the comparison and counted (but
//! kept, and timed, with `--numbers-may-differ`).
//!
//! With `--numbers-may-differ` (what `make bench PREVIOUS=...` passes: a previous release
//! build may have other numerics) the binaries are timed all the same, and the scenes whose
//! numbers differ are counted instead of stopping the run.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example unused_cost -- OLD_BINARY NEW_BINARY [ROUNDS] [--numbers-may-differ]
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

use woodpile_bench::paper::PAPER_SWEEPS;
use woodpile_pipeline::Pipeline;
use woodpile_stages::sampling::sampled_scene_tables;
use woodpile_stages::KINDS;

/// Points drawn from each sweep, and the seed: the paper sample of `make bench`.
const PER_SWEEP: usize = 8;
const SEED: u64 = 2026;
/// The keys two binaries must print alike (the numbers; not times or versions).
const SAME: [&str; 6] = ["R", "T", "E_tr", "E_final", "steps", "method"];

/// Runs `binary` on `scene`: its simulation time (s) and the JSON values that must agree.
fn simulate(binary: &Path, scene: &Path) -> (f64, Vec<serde_json::Value>) {
    let out = Command::new(binary)
        .args([Path::new("simulate"), scene])
        .output()
        .unwrap();
    let (shown, stderr) = (scene.display(), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{shown}: {stderr}");
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let same = SAME.iter().map(|k| json[*k].clone()).collect();
    (json["wall_s"].as_f64().unwrap(), same)
}

/// The sample's scene files, written under `dir`, labelled; then the standard scene.
fn scene_files(dir: &Path) -> Vec<(String, PathBuf)> {
    let pipeline = Pipeline::load("pipeline".as_ref(), KINDS).unwrap();
    let tables = sampled_scene_tables(&pipeline, PAPER_SWEEPS, PER_SWEEP, SEED).unwrap();
    let mut files: Vec<(String, PathBuf)> = tables
        .into_iter()
        .enumerate()
        .map(|(i, (label, table))| {
            let path = dir.join(format!("scene_{i:02}.toml"));
            std::fs::write(&path, toml::to_string(&table).unwrap()).unwrap();
            (label, path)
        })
        .collect();
    files.push(("standard scene".into(), "scenes/single_eps10.toml".into()));
    files
}

/// The scenes both binaries run with the same method (one probe run each), and how many the
/// new one runs with another: a feature those scenes use.
fn comparable(
    scenes: Vec<(String, PathBuf)>,
    (old, new): (&Path, &Path),
) -> (Vec<(String, PathBuf)>, usize) {
    let method = |binary: &Path, scene: &Path| simulate(binary, scene).1[SAME.len() - 1].clone();
    let total = scenes.len();
    let kept: Vec<_> = scenes
        .into_iter()
        .filter(|(_, scene)| method(old, scene) == method(new, scene))
        .collect();
    let left_out = total - kept.len();
    (kept, left_out)
}

fn main() {
    let mut args: Vec<String> = std::env::args().collect();
    let may_differ = args.iter().any(|a| a == "--numbers-may-differ");
    args.retain(|a| a != "--numbers-may-differ");
    let (old, new) = (PathBuf::from(&args[1]), PathBuf::from(&args[2]));
    let rounds: usize = args.get(3).map_or(15, |r| r.parse().unwrap());
    let mut differing = std::collections::BTreeSet::new();
    let dir = std::env::temp_dir().join(format!("woodpile_unused_cost_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (scenes, new_method) = match may_differ {
        true => (scene_files(&dir), 0),
        false => comparable(scene_files(&dir), (&old, &new)),
    };
    let sample = scenes.len() - 1;
    // best[side][group]: group 0 the paper sample, 1 the standard scene.
    let mut best = [[f64::INFINITY; 2]; 2];
    for round in 0..rounds {
        let mut total = [[0.0; 2]; 2];
        for (i, (label, scene)) in scenes.iter().enumerate() {
            let order = if round % 2 == 0 { [0, 1] } else { [1, 0] };
            let mut printed = [Vec::new(), Vec::new()];
            for side in order {
                let binary = if side == 0 { &old } else { &new };
                let (seconds, same) = simulate(binary, scene);
                total[side][usize::from(i == sample)] += seconds;
                printed[side] = same;
            }
            if printed[0] != printed[1] {
                assert!(may_differ, "{label}: the two binaries disagree");
                differing.insert(label.clone());
            }
        }
        for side in 0..2 {
            for group in 0..2 {
                best[side][group] = best[side][group].min(total[side][group]);
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    let mut agreement = match differing.len() {
        0 => "the same fractions, steps and methods from both".to_string(),
        n => format!("{n} of {} scenes gave other numbers", scenes.len()),
    };
    if new_method > 0 {
        agreement += &format!(
            "; {new_method} scenes left out: the new build runs them with a method the old one lacks"
        );
    }
    println!("{rounds} rounds, each side's best, simulation time only; {agreement}\n");
    println!("| scenes | before (ms) | after (ms) | after / before |");
    println!("|---|---|---|---|");
    let groups = [
        format!("paper sample ({sample} scenes of F4, F7 coarse and F7 fine)"),
        "standard scene (auto, 1e-8)".to_string(),
    ];
    for (group, name) in groups.iter().enumerate() {
        let (before, after) = (best[0][group] * 1e3, best[1][group] * 1e3);
        println!(
            "| {name} | {before:.1} | {after:.1} | {:.3} |",
            after / before
        );
    }
}
