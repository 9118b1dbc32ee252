//! `woodpile simulate` through the real binary: the contract of docs/scene.md and its error cases
//! (issue 2: unknown key, eps <= 0, even p > 1, defect or impulse off the chain, t_end <= 0,
//! non-finite value, unreadable file).
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Writes `text` to a fresh temporary scene file.
fn scene_file(text: &str) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::SeqCst);
    let dir = std::env::temp_dir().join(format!("woodpile-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("scene{n}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn simulate(text: &str) -> (Output, PathBuf) {
    let path = scene_file(text);
    (simulate_file(&path), path)
}

fn simulate_file(path: &Path) -> Output {
    simulate_command(path).output().unwrap()
}

/// The command `woodpile simulate path`, for a caller to add to.
fn simulate_command(path: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_woodpile"));
    command.arg("simulate").arg(path);
    command
}

/// Asserts that `woodpile simulate path` is refused as bad input: exit 2, nothing on stdout,
/// no panic, and a message naming each of `needles` (the file itself always).
fn assert_refused(path: &Path, needles: &[&str]) {
    let out = simulate_file(path);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let file = path.display().to_string();
    assert_eq!(out.status.code(), Some(2), "{file}: {stderr}");
    assert!(out.stdout.is_empty(), "{file}: printed a result");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for needle in std::iter::once(file.as_str()).chain(needles.iter().copied()) {
        assert!(stderr.contains(needle), "{stderr:?} lacks {needle:?}");
    }
}

/// Asserts that a run exited 0, showing its stderr when it did not.
fn assert_success(out: &Output) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
}

fn json_number(stdout: &str, key: &str) -> f64 {
    let v: serde_json::Value = serde_json::from_str(stdout).unwrap();
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {stdout}"))
}

/// The reference "single" scene (eps = 3) through the binary with method auto at 1e-8: R, T and
/// E_tr within 1e-7 of the independent reference, and every contract key present.
#[test]
fn simulate_prints_the_contract_json() {
    let (out, _) =
        simulate("[[defect]]\nsite = 0\neps = 3.0\n\n[run]\nmethod = \"auto\"\ntolerance = 1e-8\n");
    assert_success(&out);
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1, "one JSON object on one line");
    for (key, reference) in [
        ("R", 0.22497244831703267),
        ("T", 0.748225253767974),
        ("E_tr", 0.026802297914993292),
    ] {
        let got = json_number(&stdout, key);
        assert!(
            (got - reference).abs() < 1e-7,
            "{key}: {got} vs {reference}"
        );
    }
    assert_eq!(json_number(&stdout, "E_initial"), 0.5);
    assert!((json_number(&stdout, "E_final") - 0.5).abs() < 1e-6);
    assert!(json_number(&stdout, "steps") > 0.0);
    assert!(json_number(&stdout, "wall_s") >= 0.0);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["method"], "rkn6-contact");
    assert_eq!(v["requested_method"], "auto");
}

/// A named fixed-step method with dt runs exactly that method.
#[test]
fn named_method_with_dt() {
    let (out, _) = simulate(
        "[[defect]]\nsite = 0\neps = 3.0\n[run]\nmethod = \"yoshida6\"\ndt = 0.01\nt_end = 20.0\n",
    );
    assert_success(&out);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["method"], "yoshida6");
    assert_eq!(v["steps"], 2000);
}

/// A physical (SI) scene reports its derived eps and kappa.
#[test]
fn physical_scene_reports_derived_parameters() {
    let text = "[chain]\nn = 20\nboundary = \"free\"\n[impulse]\nsite = -19\n[physical]\ncontact = 2.47e9\nmass = 0.866e-3\nvelocity = 1.98\n[[defect]]\nsite = 0\nmass = 0.838e-3\nresonator_mass = 0.894e-3\nstiffness = 3.961e6\n[run]\nt_end = 30.0\nmethod = \"rk4\"\ndt = 0.01\n";
    let (out, _) = simulate(text);
    assert_success(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = &v["physical"]["defects"][0];
    assert!((d["eps"].as_f64().unwrap() - 0.894 / 0.866).abs() < 1e-12);
    let kappa = 3.961e6 / (0.866e-3f64.powf(0.2) * 2.47e9f64.powf(0.8) * 1.98f64.powf(0.4));
    assert!((d["kappa"].as_f64().unwrap() / kappa - 1.0).abs() < 1e-12);
    assert!(v["physical"]["time_scale_s"].as_f64().unwrap() > 0.0);
}

/// `--si` gives a physical scene's times in s and energies in J, in the JSON object and in the
/// series table, and says so; shares keep their values; a dimensionless scene is refused.
#[test]
fn si_outputs_of_a_physical_scene() {
    let text = "[chain]\nn = 20\nboundary = \"free\"\n[impulse]\nsite = -19\n[physical]\ncontact = 2.47e9\nmass = 0.866e-3\nvelocity = 1.98\n[run]\nt_end = 10.0\nmethod = \"rk4\"\ndt = 0.01\n";
    let path = scene_file(text);
    let dir = path.parent().unwrap().to_path_buf();
    let series = |name: &str| {
        dir.join(format!(
            "{name}-{}.parquet",
            COUNTER.fetch_add(1, Ordering::SeqCst)
        ))
    };
    let (scaled_table, si_table) = (series("scaled"), series("si"));
    let run = |extra: &[&str], table: &Path| {
        let out = simulate_command(&path)
            .args(extra)
            .arg("--series")
            .arg(table)
            .output()
            .unwrap();
        assert_success(&out);
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let scaled = run(&[], &scaled_table);
    let si = run(&["--si"], &si_table);
    assert_eq!(
        (scaled["units"].as_str(), si["units"].as_str()),
        (Some("scaled"), Some("SI"))
    );
    let time_s = si["physical"]["time_scale_s"].as_f64().unwrap();
    let energy_j = 0.866e-3 * 1.98 * 1.98;
    // serde_json reads floats to within an ulp, not always exactly: compare so.
    let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * b.abs();
    assert!(close(si["t_end"].as_f64().unwrap(), 10.0 * time_s));
    let e = |v: &serde_json::Value| v["E_initial"].as_f64().unwrap();
    assert!(close(e(&si), e(&scaled) * energy_j));
    assert!(
        (e(&si) - 0.5 * energy_j).abs() <= 1e-12 * energy_j,
        "the impact's M V^2 / 2"
    );
    assert_eq!(si["R"], scaled["R"]);
    let (a, b) = (
        woodpile_pipeline::table::read(&scaled_table).unwrap(),
        woodpile_pipeline::table::read(&si_table).unwrap(),
    );
    let column = |f, c: &str| woodpile_pipeline::table::f64_column(f, c).unwrap();
    let t_scaled: Vec<f64> = column(&a, "t")
        .into_iter()
        .flatten()
        .map(|t| t * time_s)
        .collect();
    let t_si: Vec<f64> = column(&b, "t").into_iter().flatten().collect();
    assert_eq!(t_si.len(), t_scaled.len());
    assert!(t_si.iter().zip(&t_scaled).all(|(a, b)| close(*a, *b)));
    assert_eq!(column(&b, "R"), column(&a, "R"));

    let (plain, _) = simulate("[run]\nt_end = 10.0\n");
    assert!(plain.status.success());
    let out = simulate_command(&scene_file("[run]\nt_end = 10.0\n"))
        .arg("--si")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--si:"));
}

/// Each bad scene exits 2 with a message naming the file, the key and the reason.
#[test]
fn bad_scenes_exit_nonzero_with_a_clear_message() {
    #[rustfmt::skip]
    let cases: &[(&str, &str, &str)] = &[
        ("[chain]\nn = 100\nfoo = 1\n", "foo", "unknown field"),
        ("[[defect]]\nsite = 0\neps = 0.0\n", "defect[0].eps", "> 0"),
        ("[[defect]]\nsite = 0\neps = -2.0\n", "defect[0].eps", "> 0"),
        ("[[defect]]\nsite = 0\neps = 1.0\np = 4\n", "defect[0].p", "odd"),
        ("[[defect]]\nsite = 101\neps = 1.0\n", "defect[0].site", "off the chain"),
        ("[impulse]\nsite = -150\n", "impulse.site", "off the chain"),
        ("[run]\nt_end = 0.0\n", "run.t_end", "> 0"),
        ("[run]\nt_end = -5.0\n", "run.t_end", "> 0"),
        ("[[defect]]\nsite = 0\neps = nan\n", "defect[0].eps", "finite"),
        ("[[defect]]\nsite = 0\neps = 1.0\nkappa = inf\n", "defect[0].kappa", "finite"),
        ("[impulse]\nvelocity = inf\n", "impulse.velocity", "finite"),
        ("[run]\nmethod = \"euler\"\n", "run.method", "unknown method"),
        ("[[defect]]\nsite = 0\neps = 1.0\nkappa = { k1 = 0.0, k2 = 1.0, t0 = 1.0 }\n", "defect[0].kappa.tau", "required"),
        ("[fractions]\nregion = [3, 1]\n", "fractions.region", "greater"),
        ("[[defect]]\neps = 1.0\n", "defect[0].site", "required"),
        ("[chain]\nboundary = \"periodic\"\n", "chain.boundary", "fixed"),
        ("[[defect]\nsite = 0\n", "line 1", "column 10"),
    ];
    for (text, key, reason) in cases {
        assert_refused(&scene_file(text), &[key, reason]);
    }
}

#[test]
fn unreadable_file_exits_nonzero() {
    assert_refused(Path::new("/nonexistent/scene.toml"), &["cannot read"]);
}

/// A run that blows up is reported as a failure (exit 3), never as numbers.
#[test]
fn blow_up_exits_3_without_numbers() {
    let (out, _) = simulate(
        "[[defect]]\nsite = 0\neps = 0.001\n[run]\nmethod = \"rk4\"\ndt = 0.9\nt_end = 60.0\n",
    );
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("simulation failed") && stderr.contains("t = "),
        "{stderr}"
    );
}

/// Inputs that are not files, or far too large, are refused before they are read.
#[test]
fn devices_and_oversized_files_are_refused_unread() {
    assert_refused(Path::new("/dev/zero"), &["not a regular file"]);
    // Kernel files pass as regular ones (`/proc/kmsg` blocks a root reader for ever).
    assert_refused(Path::new("/proc/self/status"), &["a kernel file"]);
    assert_refused(Path::new("/proc/self/environ"), &["a kernel file"]);

    let mut big = String::from("[chain]\nn = 100\n");
    while big.len() <= 2 << 20 {
        big.push_str("[[defect]]\nsite = 0\neps = 1.0\n");
    }
    assert_refused(&scene_file(&big), &["bytes"]);
}

/// Runs that could never finish are refused at once with the key and the estimate, and a
/// standing impulse is named for what it is.
#[test]
fn endless_runs_and_standing_impulses_exit_2_naming_the_key() {
    for (scene, key) in [
        ("[run]\nt_end = 1e12\n", "run.t_end"),
        ("[run]\nmethod = \"rk4\"\ndt = 1e-300\n", "run.dt"),
        ("[run]\ntolerance = 1e-30\n", "run.tolerance"),
        ("[run]\ntolerance = 10.0\n", "run.tolerance"),
        ("[run]\ntolerance = 1e300\n", "run.tolerance"),
        ("[impulse]\nvelocity = -1e-308\n", "impulse.velocity"),
        ("[impulse]\nvelocity = 1e200\n", "impulse.velocity"),
        ("[run]\nsample_every = 1e-12\n", "run.sample_every"),
        ("[[defect]]\nsite = 0\neps = 1e-300\n", "defect[0]"),
        ("[impulse]\nvelocity = 0.0\n", "impulse.velocity"),
    ] {
        assert_refused(&scene_file(scene), &[&format!("key `{key}`")]);
    }
    // A tiny value is shown as 1e-308, not as a 300-digit decimal.
    let out = simulate_file(&scene_file("[run]\nt_end = -1e-308\n"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("got -1e-308") && stderr.len() < 200,
        "{stderr}"
    );
}

/// The binary carries three copies of its hot loops, for AVX-512, for AVX2 and for the x86-64
/// baseline, and picks the best the CPU has at run time (`WOODPILE_SIMD` caps it): every copy
/// this CPU runs gives the same bits, on a scene with contact events and two resonators, by
/// `auto` (its verification runs) and by each fixed-step method with its own stage sums.
#[test]
fn every_simd_path_gives_the_same_bits() {
    let runs = [
        "method = \"auto\"\ntolerance = 1e-7",
        "method = \"rk4\"\ndt = 0.02",
        "method = \"rk4-contact\"\ndt = 0.05",
        "method = \"rkn4-contact\"\ndt = 0.05",
        "method = \"yoshida4\"\ndt = 0.02",
    ];
    for method in runs {
        let path = scene_file(&format!(
            r#"
[chain]
n = 60
[impulse]
site = -20
velocity = 1.3
[run]
t_end = 60.0
{method}
[[defect]]
site = 0
eps = 0.67
[[defect]]
site = 12
eps = 3.0
p = 3
"#
        ));
        let run = |simd: &str| {
            let out = simulate_command(&path)
                .env("WOODPILE_SIMD", simd)
                .output()
                .unwrap();
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(out.status.success(), "{method}, {simd}: {stderr}");
            let mut json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            json.as_object_mut().unwrap().remove("wall_s");
            json
        };
        let best = run("auto");
        assert_eq!(run("avx2"), best, "{method}");
        assert_eq!(run("baseline"), best, "{method}");
    }
}

/// `--series` and `--field` never rename over what is not theirs to replace: a FIFO, a device,
/// a symbolic link, the scene being read, or each other. Each is refused with exit 2 naming the
/// flag, before anything runs, and the target is left as it was.
#[test]
fn outputs_that_are_not_plain_new_files_are_refused() {
    let scene = scene_file("[run]\nt_end = 5.0\n");
    let dir = scene
        .parent()
        .unwrap()
        .join(format!("outputs{}", COUNTER.fetch_add(1, Ordering::SeqCst)));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let target = dir.join("kept.parquet");
    std::fs::write(&target, "mine").unwrap();
    let link = dir.join("link.parquet");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let same = dir.join("both.parquet");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let round_about = dir.join("sub/../both.parquet");
    let cases: [(&[&Path], &str); 7] = [
        (&[&fifo], "not a regular file"),
        (&[&dir], "not a regular file"),
        (&[&link], "a symbolic link"),
        (&[&scene], "is the scene being read"),
        (&[&same, &same], "name the same file"),
        (&[&round_about, &same], "name the same file"),
        (&[Path::new("/dev/null")], "not a regular file"),
    ];
    for (paths, needle) in cases {
        let mut command = simulate_command(&scene);
        command.arg("--series").arg(paths[0]);
        if let Some(field) = paths.get(1) {
            command.arg("--field").arg(field);
        }
        let out = command.output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{paths:?}: {stderr}");
        assert!(
            stderr.contains(needle) && out.stdout.is_empty(),
            "{paths:?}: {stderr}"
        );
    }
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "mine");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::read_to_string(&scene).unwrap().contains("t_end"));
    assert!(!same.exists());
}

/// `dt` is the step taken: each sample interval is cut into equal steps of at most the one
/// asked for, and `dt_requested` keeps that. dt = 0.08 with samples every 1 takes 13 steps of
/// 1/13 per interval.
#[test]
fn dt_is_the_step_taken() {
    let (out, _) =
        simulate("[run]\nmethod = \"rkn6-contact\"\ndt = 0.08\nsample_every = 1.0\nt_end = 20.0\n");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_success(&out);
    assert_eq!(json_number(&stdout, "dt_requested"), 0.08);
    assert!(
        (json_number(&stdout, "dt") - 1.0 / 13.0).abs() < 1e-12,
        "{stdout}"
    );
    assert_eq!(json_number(&stdout, "steps"), 260.0);
}

/// A named fixed-step method on a kappa ramp, which no energy drift can check, is checked by
/// a run at half the step: RK4 at dt = 0.5 on an F10-style ramp (E_tr 0.171 where auto gives
/// 0.280) exits 3 naming the check; at dt = 0.01 it passes with an error estimate.
#[test]
fn fixed_steps_on_a_kappa_ramp_are_checked_by_halving() {
    let ramp = "[chain]\nn = 100\n[impulse]\nsite = -25\n[[defect]]\nsite = 0\neps = 1.0\nkappa = { k1 = 0.0, k2 = 1.0, t0 = 40.0, tau = 1.0 }\n[run]\nt_end = 150.0\nmethod = \"rk4\"\n";
    let (out, _) = simulate(&format!("{ramp}dt = 0.5\n"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("kappa depends on time") && out.stdout.is_empty(),
        "{stderr}"
    );
    let (out, _) = simulate(&format!("{ramp}dt = 0.01\n"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_success(&out);
    let estimate = json_number(&stdout, "error_estimate");
    assert!(estimate > 0.0 && estimate < 1e-6, "{stdout}");
}

/// A damped scene: `D` and `normalisation` in the JSON, the shares of E(0) summing to one with
/// D, the ledger as `energy_drift`, and a column `D` in `--series`; a Nyström method is refused
/// with exit 2 naming `run.method`.
#[test]
fn a_damped_scene_reports_its_ledger() {
    let damped = "[chain]\nn = 30\nboundary = { left = \"free\", right = { spring = 0.05, damping = 0.5 } }\n[[defect]]\nsite = 0\neps = 0.5\ndamping = 0.05\n[damping]\ncontact = 0.1\n[run]\nt_end = 60.0\ntolerance = 1e-8\n";
    let path = scene_file(damped);
    let series = path.with_extension("parquet");
    let out = simulate_command(&path)
        .arg("--series")
        .arg(&series)
        .output()
        .unwrap();
    assert_success(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["normalisation"], "E(0)");
    // The ledger E + D = E(0) held: what "conserved" means with losses.
    assert_eq!(v["energy_conserved"], true);
    assert_eq!(v["method"], "rk4-contact");
    let share = |k: &str| v[k].as_f64().unwrap();
    let sum = share("R") + share("T") + share("E_tr") + share("D");
    assert!((sum - 1.0).abs() < 1e-8, "{sum}");
    assert!(share("D") > 0.5 && share("energy_drift") < 1e-7);
    let columns = woodpile_pipeline::table::read(&series).unwrap();
    let names: Vec<String> = columns
        .get_column_names()
        .iter()
        .map(|c| c.to_string())
        .collect();
    assert_eq!(names, ["t", "R", "T", "E_tr", "D", "E"]);
    let nystrom = scene_file(&format!("{damped}method = \"rkn4-contact\"\ndt = 0.01\n"));
    assert_refused(&nystrom, &["run.method", "rk4-contact"]);
}

/// A wave that reaches a wall before `t_end`: the JSON says when, and stderr notes that R and
/// T include what the wall sent back; a run that ends first says nothing.
#[test]
fn a_wave_reaching_an_end_before_t_end_is_noted() {
    let short = "[chain]\nn = 20\n[impulse]\nsite = -15\n[run]\nt_end = 60.0\ntolerance = 1e-6\n";
    let (out, _) = simulate(short);
    assert_success(&out);
    let reached = json_number(&String::from_utf8(out.stdout).unwrap(), "end_reached_at");
    assert!(reached > 10.0 && reached < 60.0, "{reached}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("note:") && stderr.contains(&format!("t = {reached}")),
        "{stderr}"
    );
    let (quiet, _) = simulate(&short.replace("t_end = 60.0", "t_end = 5.0"));
    let v: serde_json::Value = serde_json::from_slice(&quiet.stdout).unwrap();
    assert!(v["end_reached_at"].is_null());
    assert!(quiet.stderr.is_empty());
}

/// A refused `auto` keeps its finest run: exit 3, the reason on stderr, and on stdout its
/// fractions under `unverified`, marked `verified: false`, with an estimate above the tolerance.
#[test]
fn a_refused_run_keeps_its_finest_run_marked_unverified() {
    let stiff = "[chain]\nn = 10\n[impulse]\nsite = -5\n[[defect]]\nsite = 0\neps = 0.3\nkappa = 2.0\np = 7\n[run]\nt_end = 20.0\ntolerance = 1e-13\n";
    let (out, _) = simulate(stiff);
    assert_eq!(out.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&out.stderr).contains("could not verify"));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let kept = &v["unverified"];
    assert_eq!(kept["verified"], false);
    let sum: f64 = ["R", "T", "E_tr"]
        .iter()
        .map(|k| kept[k].as_f64().unwrap())
        .sum();
    assert!((sum - 1.0).abs() < 1e-9, "{sum}");
    assert!(kept["error_estimate"].as_f64().unwrap() > 1e-13 * 6.25e-2);
}

/// A tolerance the ladder cannot reach is refused at the rung that shows it, not after all
/// seven: three cubic resonators over t = 400 scatter E_tr by percents between steps, and the
/// refusal comes at the fourth rung (dt = first step / 8), keeping that rung's run.
#[test]
fn an_out_of_reach_tolerance_is_refused_at_once() {
    let defects: String = [(0, 0.2, 2.0), (1, 0.3, 5.0), (2, 0.1, 3.0)]
        .iter()
        .map(|(site, eps, kappa)| {
            format!("[[defect]]\nsite = {site}\neps = {eps}\nkappa = {kappa}\np = 3\n")
        })
        .collect();
    let text = format!("[chain]\nn = 100\n{defects}[run]\nt_end = 400.0\ntolerance = 1e-8\n");
    let (out, _) = simulate(&text);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("halving(s) left could not bring it there"),
        "{stderr}"
    );
    assert!(stderr.contains("refused at once"), "{stderr}");
    let kept: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let finest = kept["unverified"]["dt"].as_f64().unwrap();
    // auto's first step here is the tolerance's 0.0215 (rkn6-contact at 1e-8): the fourth
    // rung's is an eighth of it, the last one's a sixty-fourth.
    assert!(
        (finest - 0.0215 / 8.0).abs() < 0.0215 / 64.0,
        "refused at dt = {finest}"
    );
}
