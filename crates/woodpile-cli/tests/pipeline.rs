//! `woodpile run`, `status` and `diff` through the real binary: exit codes and the messages a
//! user reads first.
#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::process::{Command, Output};

#[path = "../../woodpile-stages/tests/common/stage_files.rs"]
mod stage_files;
use stage_files::{sweep_file, FIGURE};

/// A sweep over eps in {0.5, 1} on a chain of 21 sites, to t = 10.
fn sweep() -> String {
    sweep_file("eps = [0.5, 1.0]", 10, (10.0, 0.02, 5.0), &[(0, "$eps")])
}

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
    std::fs::write(dir.path().join("pipeline/sweep.toml"), sweep()).unwrap();
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
        sweep().replace("dt = 0.02", "dt = 0.04"),
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
        sweep().replace("[axes]", "[axes]\nfoo = \"x\""),
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
        text(&incomplete.stderr).contains("1 of 2 shard(s) missing (1;"),
        "{}",
        text(&incomplete.stderr)
    );
    // Inside a SLURM array job a plain run does not shard: it writes the table.
    let plain = Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .current_dir(d)
        .args(["run", "sweep", "--results", "plain"])
        .env("SLURM_ARRAY_TASK_ID", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .output()
        .unwrap();
    assert!(plain.status.success());
    assert!(d.join("plain/sweep.parquet").exists());
    // Shard 1 from a SLURM array task's environment, when asked.
    let task = Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .current_dir(d)
        .args(["run", "sweep", "--shard-from-env", "--results", "cluster"])
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

    for bad in [
        vec!["--tasks", "3"],
        vec!["--tasks", "1000000000"],
        vec!["--partition", "short\ntouch x"],
        vec!["--time", "1:00; rm -rf ~"],
        vec!["--out", "slurm\nx"],
    ] {
        let mut args = vec!["slurm", "sweep"];
        args.extend(bad.iter().copied());
        let out = woodpile(d, &args);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {}", text(&out.stderr));
    }
    assert!(!d.join("x").exists());
    let scripts = woodpile(
        d,
        &["slurm", "sweep", "--tasks", "2", "--partition", "short"],
    );
    assert!(scripts.status.success(), "{}", text(&scripts.stderr));
    let array = std::fs::read_to_string(d.join("slurm/sweep.array.sbatch")).unwrap();
    assert!(array.contains("#SBATCH --array=0-1") && array.contains("#SBATCH --partition=short"));
    let submit = std::fs::read_to_string(d.join("slurm/sweep.submit.sh")).unwrap();
    assert!(submit.contains("--dependency=afterok"));
}

#[test]
fn malformed_or_unknown_tolerance_columns_exit_2() {
    let dir = project();
    let d = dir.path();
    assert!(woodpile(d, &["run"]).status.success());
    for tol in ["R=1,2,3", "nope=1", "=1", "E_tr=x", "E_tr=-1", "E_tr=nan"] {
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
    for args in [
        vec!["--abs=-1"],
        vec!["--abs", "nan"],
        vec!["--rel", "-0.5"],
        vec!["--tol", "E_tr=1", "--tol", "E_tr=2"],
    ] {
        let mut all = vec!["diff", "results", "results"];
        all.extend(args.iter().copied());
        let out = woodpile(d, &all);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            text(&out.stderr)
        );
    }
    std::fs::create_dir_all(d.join("empty_a")).unwrap();
    std::fs::create_dir_all(d.join("empty_b")).unwrap();
    let empty = woodpile(d, &["diff", "empty_a", "empty_b"]);
    assert_eq!(empty.status.code(), Some(1), "{}", text(&empty.stdout));
    assert!(text(&empty.stdout).contains("nothing to compare"));
    std::fs::write(d.join("a_file"), "x").unwrap();
    let not_dir = woodpile(d, &["run", "--results", "a_file"]);
    assert_eq!(not_dir.status.code(), Some(2));
    assert!(
        text(&not_dir.stderr).contains("not a directory"),
        "{}",
        text(&not_dir.stderr)
    );
    let threads = Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .current_dir(d)
        .args(["status"])
        .env("RAYON_NUM_THREADS", "100000")
        .output()
        .unwrap();
    assert_eq!(threads.status.code(), Some(2));
    assert!(
        text(&threads.stderr).contains("RAYON_NUM_THREADS")
            && !text(&threads.stderr).contains("panicked")
    );
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

const REDUCE: &str = r#"
kind = "reduce"
inputs = ["sweep"]
at = 10.0
"#;

/// `kill -9` at spread-out moments of a render run for an edited title, then the edit
/// reverted: whatever the kill left, `status` never calls the figure fresh unless it is the
/// original's, and the next run restores it.
#[test]
fn a_killed_render_followed_by_a_revert_is_never_fresh_with_the_wrong_figure() {
    let dir = project();
    let d = dir.path();
    let write = |title: &str| {
        std::fs::write(d.join("pipeline/at_end.toml"), REDUCE).unwrap();
        std::fs::write(d.join("pipeline/fig.toml"), FIGURE.replace("TITLE", title)).unwrap();
    };
    write("original");
    assert!(woodpile(d, &["run"]).status.success());
    let png = d.join("figures/fig.png");
    let original = std::fs::read(&png).unwrap();
    // Delays from 0 to about 150 ms, spread by a fixed sequence (the render takes about that).
    let mut seed: u64 = 12345;
    for trial in 0..12 {
        write(&format!("edited {trial}"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_woodpile"))
            .current_dir(d)
            .args(["run"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        std::thread::sleep(std::time::Duration::from_millis((seed >> 33) % 150));
        let _ = child.kill();
        let _ = child.wait();
        write("original");
        let status = woodpile(d, &["status", "--json"]);
        let fresh = text(&status.stdout)
            .contains(r#"{"kind":"render","stage":"fig","state":"fresh","why":""}"#);
        if fresh {
            assert_eq!(
                std::fs::read(&png).unwrap(),
                original,
                "trial {trial}: fresh with another figure"
            );
        }
        assert!(woodpile(d, &["run"]).status.success());
        assert_eq!(std::fs::read(&png).unwrap(), original, "trial {trial}");
    }
}

/// `woodpile new study` makes a folder that runs as written, from itself or any folder inside
/// it, with no directory flags; a variant runs beside the stage; the environment moves a tree.
#[test]
fn a_new_study_runs_as_written_without_directory_flags() {
    let dir = tempfile::tempdir().unwrap();
    let made = woodpile(dir.path(), &["new", "study", "mine"]);
    assert!(made.status.success(), "{}", text(&made.stderr));
    assert_eq!(
        woodpile(dir.path(), &["new", "study", "mine"])
            .status
            .code(),
        Some(2)
    );
    let study = dir.path().join("mine");
    let ran = woodpile(&study, &["run"]);
    assert!(ran.status.success(), "{}", text(&ran.stderr));
    assert!(
        text(&ran.stderr).contains("25 scene(s) simulated"),
        "{}",
        text(&ran.stderr)
    );
    assert!(study.join("figures/figure.png").exists());
    // The study's figure is set for print by its defaults: one panel at column width, E_tr
    // written as E with a subscript.
    let svg = std::fs::read_to_string(study.join("figures/figure.svg")).unwrap();
    assert!(svg.contains(r#"width="86.0mm""#) && svg.contains("Eₜᵣ"));
    let inside = woodpile(&study.join("pipeline"), &["status", "--check"]);
    assert_eq!(inside.status.code(), Some(0), "{}", text(&inside.stdout));
    let variant = woodpile(&study, &["run", "--set", "fractions.at=40"]);
    assert!(variant.status.success(), "{}", text(&variant.stderr));
    assert!(study.join("results/fractions--at-40.parquet").exists());
    assert_eq!(
        woodpile(&study, &["status", "--check"]).status.code(),
        Some(0)
    );
    let moved = Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .current_dir(&study)
        .args(["status", "--check"])
        .env("WOODPILE_RESULTS", "elsewhere")
        .output()
        .unwrap();
    assert_eq!(moved.status.code(), Some(1), "{}", text(&moved.stdout));
    let nowhere = woodpile(dir.path(), &["status"]);
    assert_eq!(nowhere.status.code(), Some(2));
    assert!(
        text(&nowhere.stderr).contains("woodpile new study"),
        "{}",
        text(&nowhere.stderr)
    );
}

/// A `woodpile.toml` above a project does not take it over: the search stops at the first
/// folder holding `pipeline/`, and a `woodpile.toml` in a folder everyone may write (a shared
/// `/tmp`) is ignored even where no project is found below it.
#[test]
fn a_woodpile_toml_above_a_project_does_not_take_it_over() {
    use std::os::unix::fs::PermissionsExt;
    let outer = tempfile::tempdir().unwrap();
    let shared = outer.path().join("shared");
    std::fs::create_dir_all(shared.join("elsewhere")).unwrap();
    std::fs::write(
        shared.join("woodpile.toml"),
        "pipeline = \"elsewhere\"\nresults = \"stolen\"\n",
    )
    .unwrap();
    std::fs::set_permissions(&shared, std::fs::Permissions::from_mode(0o777)).unwrap();
    let project = shared.join("project");
    std::fs::create_dir_all(project.join("pipeline")).unwrap();
    std::fs::write(project.join("pipeline/small_sweep.toml"), sweep()).unwrap();
    let inside = project.join("notes");
    std::fs::create_dir_all(&inside).unwrap();
    let out = woodpile(&inside, &["status"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("small_sweep"),
        "{}",
        text(&out.stdout)
    );
    // Without a project below it, the world-writable folder's file is still ignored (with a
    // warning), and so is a pipeline/ planted there.
    std::fs::create_dir_all(shared.join("pipeline")).unwrap();
    std::fs::write(shared.join("pipeline/planted.toml"), sweep()).unwrap();
    let lone = shared.join("lone");
    std::fs::create_dir_all(&lone).unwrap();
    let out = woodpile(&lone, &["status"]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(
        stderr.contains("warning: ignoring") && stderr.contains("everyone may write"),
        "{stderr}"
    );
    assert!(
        !stdout.contains("planted") && !stderr.contains("elsewhere"),
        "{stdout}{stderr}"
    );
    assert!(!shared.join("stolen").exists());
}

/// `results/points` or `results/parts` as a symbolic link to a folder elsewhere is refused by
/// `run` and by `--shard` (exit 2, naming it), and nothing is written or deleted there.
#[test]
fn symlinked_tree_folders_are_refused() {
    for (folder, args) in [
        ("points", &["run"][..]),
        ("parts", &["run", "sweep", "--shard", "0/2"][..]),
    ] {
        let dir = project();
        let elsewhere = tempfile::tempdir().unwrap();
        std::fs::write(elsewhere.path().join("keep.tmp"), "mine").unwrap();
        std::fs::create_dir_all(dir.path().join("results")).unwrap();
        std::os::unix::fs::symlink(elsewhere.path(), dir.path().join("results").join(folder))
            .unwrap();
        let out = woodpile(dir.path(), args);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{folder}: {stderr}");
        assert!(
            stderr.contains(folder) && stderr.contains("symbolic link"),
            "{stderr}"
        );
        let left: Vec<_> = std::fs::read_dir(elsewhere.path())
            .unwrap()
            .flatten()
            .collect();
        assert_eq!(left.len(), 1, "{folder}: wrote or deleted outside the tree");
    }
}

/// Bad requests about the tree exit 2, as bad input does: a symbolic link as the lock, more
/// shards than points.
#[test]
fn a_symlinked_lock_and_too_many_shards_are_bad_input() {
    let dir = project();
    let elsewhere = tempfile::tempdir().unwrap();
    let target = elsewhere.path().join("file");
    std::fs::write(&target, "mine").unwrap();
    std::fs::create_dir_all(dir.path().join("results")).unwrap();
    std::os::unix::fs::symlink(&target, dir.path().join("results/.woodpile.lock")).unwrap();
    let out = woodpile(dir.path(), &["run"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "mine");
    let out = woodpile(dir.path(), &["run", "sweep", "--shard", "0/1000"]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("key `--shard`") && stderr.contains("at most one shard per point"),
        "{stderr}"
    );
}

/// Control characters from a stage file (a raw ESC in a value, an escaped one in a key) never
/// reach the terminal raw: errors, status lines and warnings print them escaped.
#[test]
fn control_characters_from_stage_files_are_printed_escaped() {
    let dir = project();
    let stage = dir.path().join("pipeline/sweep.toml");
    let with_value = sweep().replace(
        "kind = \"sweep\"",
        "kind = \"sweep\"\ndescription = \"x\u{1b}[2J\u{1b}[Hall stages fresh\"",
    );
    std::fs::write(&stage, &with_value).unwrap();
    let out = woodpile(dir.path(), &["status"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(!out.stdout.contains(&0x1b) && !out.stderr.contains(&0x1b));
    std::fs::write(
        &stage,
        sweep().replace("[axes]", "\"\\u001b[2J\" = 1\n[axes]"),
    )
    .unwrap();
    for args in [&["status"][..], &["run"][..]] {
        let out = woodpile(dir.path(), args);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(
            !out.stdout.contains(&0x1b) && !out.stderr.contains(&0x1b),
            "{stderr:?}"
        );
        assert!(stderr.contains("\\u{1b}[2J"), "{stderr:?}");
    }
    // A newline in a key cannot start a line of its own that passes for a status line.
    std::fs::write(
        &stage,
        sweep().replace("[axes]", "\"x\\nfresh     sweep\" = 1\n[axes]"),
    )
    .unwrap();
    let out = woodpile(dir.path(), &["status"]);
    let stderr = text(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr:?}");
}

/// A sweep keeps a point's key and series, not its scene: 120 points of a 200,001-site chain
/// run in 200 MB of address space (holding the scenes took over 250 MB and aborted).
#[test]
fn a_sweep_of_a_long_chain_holds_no_scene_per_point() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("pipeline")).unwrap();
    let stage = "kind = \"sweep\"\n[axes]\neps = { from = 0.001, to = 4.0, count = 120 }\n[scene]\nchain = { n = 100000 }\nimpulse = { site = -5 }\nrun = { t_end = 0.5, method = \"rk4\", dt = 0.05 }\n[[scene.defect]]\nsite = 0\neps = \"$eps\"\n";
    std::fs::write(dir.path().join("pipeline/long.toml"), stage).unwrap();
    let out = Command::new("sh")
        .current_dir(dir.path())
        .arg("-c")
        .arg(format!(
            "ulimit -v 200000; exec {} run",
            env!("CARGO_BIN_EXE_woodpile")
        ))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(dir.path().join("results/long.parquet").is_file());
}

/// Foreign parquet files that the decoder cannot take end `diff` with exit 2 naming the file,
/// never an abort or a printed backtrace: one whose damaged page header makes the decoder ask
/// for 2^61 bytes (decoded in a child process), and one with a decimal column.
#[test]
fn diff_of_foreign_parquet_the_decoder_cannot_take_exits_2() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for bad in ["foreign_aborts_decoder.parquet", "foreign_decimal.parquet"] {
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        std::fs::copy(data.join(bad), a.path().join("t.parquet")).unwrap();
        std::fs::copy(data.join("foreign_ok.parquet"), b.path().join("t.parquet")).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_woodpile"))
            .arg("diff")
            .args([a.path(), b.path()])
            .output()
            .unwrap();
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {stderr}");
        assert!(
            stderr.contains("t.parquet") && !stderr.contains("panicked"),
            "{bad}: {stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{bad}: {stderr}");
    }
}

/// A stage file whose name starts with `-` is refused at load: as a stage name it would pass
/// for a flag (`--dry-run.toml` ran as a stage).
#[test]
fn flag_like_stage_names_are_refused() {
    let dir = project();
    std::fs::write(dir.path().join("pipeline/--dry-run.toml"), sweep()).unwrap();
    let out = woodpile(dir.path(), &["status"]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--dry-run.toml") && stderr.contains("starting with a letter or digit"),
        "{stderr}"
    );
}

/// `--set`: a key given twice is refused before anything runs, and a long value makes a short
/// name (it was a file name too long, after the computation).
#[test]
fn set_refuses_a_repeated_key_and_names_long_values_briefly() {
    let dir = project();
    let out = woodpile(
        dir.path(),
        &[
            "run",
            "--set",
            "sweep.scene.run.t_end=5.0",
            "--set",
            "sweep.scene.run.t_end=6.0",
        ],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("given twice"), "{stderr}");
    assert!(!dir.path().join("results").join("points").exists());
    let long = format!("sweep.description={}", "x".repeat(3000));
    let out = woodpile(dir.path(), &["run", "--set", &long]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

/// A fan-out folder of the point cache (`results/points/ab`) as a symbolic link is refused
/// too: no point is written, and no stale temporary deleted, outside the tree.
#[test]
fn symlinked_point_fan_out_folders_are_refused() {
    let dir = project();
    let elsewhere = tempfile::tempdir().unwrap();
    std::fs::write(elsewhere.path().join(".x~h~1~Ab3dEf6hIj9l.tmp"), "mine").unwrap();
    let points = dir.path().join("results/points");
    std::fs::create_dir_all(&points).unwrap();
    for byte in 0..=255u8 {
        std::os::unix::fs::symlink(elsewhere.path(), points.join(format!("{byte:02x}"))).unwrap();
    }
    let out = woodpile(dir.path(), &["run"]);
    let stderr = text(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("symbolic link"),
        "{stderr}"
    );
    let left = std::fs::read_dir(elsewhere.path())
        .unwrap()
        .flatten()
        .count();
    assert_eq!(left, 1, "wrote or deleted outside the tree");
}
