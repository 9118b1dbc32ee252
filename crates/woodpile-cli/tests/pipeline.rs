//! `woodpile run`, `status` and `diff` through the real binary: exit codes and the messages a
//! user reads first.
#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::process::{Command, Output};

const SWEEP: &str = r#"
kind = "sweep"
[axes]
eps = [0.5, 1.0]
[scene]
chain = { n = 10 }
impulse = { site = -5 }
run = { t_end = 10.0, method = "rk4", dt = 0.02, sample_every = 5.0 }
[[scene.defect]]
site = 0
eps = "$eps"
"#;

fn woodpile(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn project() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("pipeline")).unwrap();
    std::fs::write(dir.path().join("pipeline/sweep.toml"), SWEEP).unwrap();
    dir
}

#[test]
fn run_status_and_diff_exit_codes() {
    let dir = project();
    let d = dir.path();
    let dry = woodpile(d, &["run", "--dry-run"]);
    assert!(dry.status.success());
    assert!(
        text(&dry.stdout).contains("would run sweep: missing"),
        "{}",
        text(&dry.stdout)
    );
    assert!(text(&dry.stdout).contains("2 scenes: 0 cached, 2 to simulate"));
    assert_eq!(woodpile(d, &["status", "--check"]).status.code(), Some(1));

    assert!(woodpile(d, &["run"]).status.success());
    assert!(woodpile(d, &["run", "--results", "other"]).status.success());
    assert_eq!(woodpile(d, &["status", "--check"]).status.code(), Some(0));
    let same = woodpile(d, &["diff", "results", "other"]);
    assert_eq!(same.status.code(), Some(0), "{}", text(&same.stdout));
    assert!(text(&same.stdout).contains("AGREE"));

    // An edit makes the stage stale, and status says which parameter changed.
    std::fs::write(
        d.join("pipeline/sweep.toml"),
        SWEEP.replace("dt = 0.02", "dt = 0.04"),
    )
    .unwrap();
    let status = woodpile(d, &["status"]);
    assert!(
        text(&status.stdout).contains("stale    parameter scene.run.dt: 0.02 -> 0.04"),
        "{}",
        text(&status.stdout)
    );
    assert!(woodpile(d, &["run", "--results", "other"]).status.success());
    let differ = woodpile(d, &["diff", "results", "other"]);
    assert_eq!(differ.status.code(), Some(1), "{}", text(&differ.stdout));
    assert!(text(&differ.stdout).contains("DIFFER"));
    let loose = woodpile(
        d,
        &[
            "diff",
            "results/sweep.parquet",
            "other/sweep.parquet",
            "--abs",
            "1",
            "--tol",
            "scene_key=0",
        ],
    );
    // Keys are strings: no numeric tolerance makes two different scenes equal.
    assert_eq!(loose.status.code(), Some(1));
}

#[test]
fn bad_stage_files_and_unknown_stages_exit_2_naming_file_and_key() {
    let dir = project();
    let d = dir.path();
    let unknown = woodpile(d, &["run", "nope"]);
    assert_eq!(unknown.status.code(), Some(2));
    assert!(text(&unknown.stderr).contains("no stage named `nope`"));
    std::fs::write(
        d.join("pipeline/sweep.toml"),
        SWEEP.replace("[axes]", "[axes]\nfoo = \"x\""),
    )
    .unwrap();
    let bad = woodpile(d, &["status"]);
    assert_eq!(bad.status.code(), Some(2));
    let err = text(&bad.stderr);
    assert!(
        err.contains("sweep.toml") && err.contains("axes.foo"),
        "{err}"
    );
    let missing = woodpile(d, &["diff", "results", "nowhere"]);
    assert_eq!(missing.status.code(), Some(2));
}

#[test]
fn shards_from_flags_and_slurm_variables_merge_to_the_local_result() {
    let dir = project();
    let d = dir.path();
    assert!(woodpile(d, &["run", "--results", "local"]).status.success());
    let early = woodpile(d, &["merge", "sweep", "--results", "cluster"]);
    assert_eq!(early.status.code(), Some(3));
    assert!(
        text(&early.stderr).contains("no parts"),
        "{}",
        text(&early.stderr)
    );
    assert!(woodpile(
        d,
        &["run", "sweep", "--shard", "0/2", "--results", "cluster"]
    )
    .status
    .success());
    let incomplete = woodpile(d, &["merge", "sweep", "--results", "cluster"]);
    assert!(
        text(&incomplete.stderr).contains("missing shard(s) 1 of 2"),
        "{}",
        text(&incomplete.stderr)
    );
    // Shard 1 from a SLURM array task's environment.
    let task = Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .current_dir(d)
        .args(["run", "sweep", "--results", "cluster"])
        .env("SLURM_ARRAY_TASK_ID", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .output()
        .unwrap();
    assert!(task.status.success());
    assert!(
        text(&task.stderr).contains("shard 1/2"),
        "{}",
        text(&task.stderr)
    );
    assert!(woodpile(d, &["merge", "sweep", "--results", "cluster"])
        .status
        .success());
    assert_eq!(
        woodpile(d, &["diff", "local", "cluster"]).status.code(),
        Some(0)
    );
    assert_eq!(
        woodpile(d, &["run", "sweep", "--shard", "2/2"])
            .status
            .code(),
        Some(2)
    );

    let scripts = woodpile(
        d,
        &["slurm", "sweep", "--tasks", "3", "--partition", "short"],
    );
    assert!(scripts.status.success(), "{}", text(&scripts.stderr));
    let array = std::fs::read_to_string(d.join("slurm/sweep.array.sbatch")).unwrap();
    assert!(array.contains("#SBATCH --array=0-2") && array.contains("#SBATCH --partition=short"));
    let submit = std::fs::read_to_string(d.join("slurm/sweep.submit.sh")).unwrap();
    assert!(submit.contains("--dependency=afterok"));
}

#[test]
fn malformed_or_unknown_tolerance_columns_exit_2() {
    let dir = project();
    let d = dir.path();
    assert!(woodpile(d, &["run"]).status.success());
    for tol in ["R=1,2,3", "nope=1", "=1", "E_tr=x", "E_tr=-1"] {
        let out = woodpile(d, &["diff", "results", "results", "--tol", tol]);
        assert_eq!(
            out.status.code(),
            Some(2),
            "--tol {tol}: {}",
            text(&out.stderr)
        );
        assert!(
            text(&out.stderr).contains("error:"),
            "{}",
            text(&out.stderr)
        );
    }
    let ok = woodpile(
        d,
        &["diff", "results", "results", "--tol", "E_tr=1e-9,1e-6"],
    );
    assert_eq!(ok.status.code(), Some(0), "{}", text(&ok.stderr));
}

/// Two `woodpile run` on one results tree at once: the second waits for the first (or finds
/// its work done); both succeed, and the tree is what one run makes, with no temporaries.
#[test]
fn two_runs_on_one_results_tree_do_not_duplicate_or_damage_work() {
    let dir = project();
    let d = dir.path();
    let spawn = || {
        Command::new(env!("CARGO_BIN_EXE_woodpile"))
            .current_dir(d)
            .arg("run")
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (first, second) = (spawn(), spawn());
    let (first, second) = (
        first.wait_with_output().unwrap(),
        second.wait_with_output().unwrap(),
    );
    assert!(first.status.success(), "{}", text(&first.stderr));
    assert!(second.status.success(), "{}", text(&second.stderr));
    assert_eq!(woodpile(d, &["status", "--check"]).status.code(), Some(0));
    assert!(woodpile(d, &["run", "--results", "alone"]).status.success());
    let same = woodpile(d, &["diff", "results", "alone"]);
    assert_eq!(same.status.code(), Some(0), "{}", text(&same.stdout));
    let leftovers: Vec<_> = walk(&d.join("results"))
        .into_iter()
        .filter(|p| p.to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(walk(&path));
        } else {
            out.push(path);
        }
    }
    out
}

/// A reader that goes away (`woodpile status | head -1`) ends the command quietly with the
/// SIGPIPE exit code, never a panic.
#[test]
fn a_closed_pipe_is_not_a_panic() {
    let dir = project();
    let mut child = Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .current_dir(dir.path())
        .args(["run", "--dry-run"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = text(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        matches!(out.status.code(), Some(0 | 141)),
        "{:?}",
        out.status
    );
}
