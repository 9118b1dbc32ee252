//! The experimenter's workbench (issue 56): the contract's departures fixed, through the real
//! binary.
#![allow(clippy::unwrap_used)]

use std::process::Output;

/// Runs `woodpile simulate` on `text` written to a fresh temporary file.
fn simulate(text: &str) -> Output {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    std::process::Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .arg("simulate")
        .arg(&path)
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A soft left end's spring and dashpot would act on the striker (the left end's body): the
/// scene is refused, as one with a wall there is.
#[test]
fn a_striker_beside_a_soft_left_end_is_refused() {
    for left in [
        "{ spring = 1.0 }",
        "{ spring = 0.0, damping = 0.5 }",
        "\"fixed\"",
    ] {
        let out = simulate(&format!(
            "[chain]\nn = 20\nboundary = {{ left = {left}, right = \"free\" }}\n[striker]\nmass = 2.0\n[run]\nt_end = 10.0\n"
        ));
        assert_eq!(out.status.code(), Some(2), "{left}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("key `striker`: needs a free left end"),
            "{}",
            stderr(&out)
        );
        assert!(out.stdout.is_empty());
    }
}

/// One side of `chain.boundary` may be given alone; the other keeps the default wall, so the
/// one-sided table is the two-sided one with `"fixed"` written out.
#[test]
fn a_one_sided_boundary_keeps_a_wall_on_the_other_side() {
    let run = |boundary: &str| {
        let out = simulate(&format!(
            "[chain]\nn = 20\nboundary = {boundary}\n[impulse]\nsite = -5\n[run]\nt_end = 40.0\ntolerance = 1e-6\n"
        ));
        assert_eq!(out.status.code(), Some(0), "{boundary}: {}", stderr(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (v["R"].as_f64().unwrap(), v["T"].as_f64().unwrap())
    };
    assert_eq!(
        run("{ right = \"free\" }"),
        run("{ left = \"fixed\", right = \"free\" }")
    );
    assert_eq!(
        run("{ right = { spring = 0.5, damping = 0.1 } }"),
        run("{ left = \"fixed\", right = { spring = 0.5, damping = 0.1 } }")
    );
    assert_eq!(
        run("{ left = \"free\" }"),
        run("{ left = \"free\", right = \"fixed\" }")
    );
}

/// The as-built woodpile with a glass-sphere striker, run for `t_end` (TOML value).
fn woodpile(t_end: &str, sample_every: &str) -> String {
    format!(
        r#"[chain]
sites = [-20, 19]
boundary = {{ left = "free", right = "free" }}
[physical]
material = {{ youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }}
rod = {{ length = 0.020, diameter = 0.005 }}
[striker]
velocity = 1.98
sphere = {{ diameter = 0.010, material = {{ youngs_modulus = 70e9, poisson_ratio = 0.23, density = 2500.0 }} }}
[run]
t_end = {t_end}
sample_every = {sample_every}
tolerance = 1e-6
"#
    )
}

/// A physical scene's times may carry a unit: the run ends at that time in seconds, and the
/// same scene written in scaled time gives the same numbers.
#[test]
fn times_with_units_are_seconds_in_a_physical_scene() {
    let out = simulate(&woodpile("\"0.5 ms\"", "\"25 us\""));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let t_end_s = v["physical"]["t_end_s"].as_f64().unwrap();
    assert!((t_end_s - 0.5e-3).abs() < 1e-15, "{t_end_s}");
    // The same run in scaled time: t_end and sample_every over the scene's time scale.
    let scale = v["physical"]["time_scale_s"].as_f64().unwrap();
    let scaled = simulate(&woodpile(
        &format!("{:?}", 0.5e-3 / scale),
        &format!("{:?}", 25e-6 / scale),
    ));
    let w: serde_json::Value = serde_json::from_slice(&scaled.stdout).unwrap();
    // Equal to rounding: "25 us" is 25 × 1e-6 s, which need not be the double 25e-6.
    for share in ["R", "T", "E_tr", "S"] {
        let (a, b) = (v[share].as_f64().unwrap(), w[share].as_f64().unwrap());
        assert!((a - b).abs() <= 1e-12, "{share}: {a} against {b}");
    }
}

#[test]
fn a_time_with_a_unit_is_refused_where_it_cannot_be_read() {
    let cases = [
        (
            woodpile("\"1.5 kg\"", "1.0"),
            "key `run.t_end`: `kg` is not a unit of time",
        ),
        (
            woodpile("150.0", "\"2\""),
            "key `run.sample_every`: `2` has no unit",
        ),
        (
            "[run]\nt_end = \"1 ms\"\n".to_string(),
            "key `run.t_end`: `1 ms`: a time with a unit needs a [physical] scene",
        ),
        (
            "[run]\nt_end = true\n".to_string(),
            "a time with a unit such as",
        ),
    ];
    for (scene, expected) in cases {
        let out = simulate(&scene);
        assert_eq!(out.status.code(), Some(2), "{expected}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(expected),
            "{expected}: {}",
            stderr(&out)
        );
    }
}

/// The binary carries the example scenes: listed, printed, and runnable outside a clone.
#[test]
fn the_examples_are_listed_and_printed_without_a_clone() {
    let woodpile = |args: &[&str], dir: &std::path::Path| {
        std::process::Command::new(env!("CARGO_BIN_EXE_woodpile"))
            .args(args)
            .current_dir(dir)
            .output()
            .unwrap()
    };
    let dir = tempfile::tempdir().unwrap();
    let list = woodpile(&["example"], dir.path());
    assert_eq!(list.status.code(), Some(0));
    let listed = String::from_utf8_lossy(&list.stdout).into_owned();
    assert!(
        listed.contains("single_eps10") && listed.contains("woodpile_striker"),
        "{listed}"
    );
    let scene = woodpile(&["example", "single_eps10"], dir.path());
    let path = dir.path().join("single_eps10.toml");
    std::fs::write(&path, &scene.stdout).unwrap();
    let text = String::from_utf8_lossy(&scene.stdout).replace("t_end = 150.0", "t_end = 20.0");
    std::fs::write(&path, text).unwrap();
    let run = woodpile(&["simulate", "single_eps10.toml"], dir.path());
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let missing = woodpile(&["example", "nope"], dir.path());
    assert_eq!(missing.status.code(), Some(2));
    assert!(
        stderr(&missing).contains("the examples are single_eps10"),
        "{}",
        stderr(&missing)
    );
}

/// The note that the wave reached an end names its times as the scene gave them: in seconds
/// for a `[physical]` scene, whose scaled time the user never wrote.
#[test]
fn the_end_reached_note_of_an_si_scene_is_in_seconds() {
    let out = simulate(
        "[chain]\nsites = [-10, 9]\nboundary = \"free\"\n[impulse]\nsite = -10\n[physical]\ncontact = 2.47e9\nmass = 0.866e-3\nvelocity = 1.0\n[run]\nt_end = \"0.5 ms\"\n",
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let note = stderr(&out);
    assert!(
        note.contains("before t_end = 5.0000e-4 s (") && note.contains("in scaled time"),
        "{note}"
    );
}
