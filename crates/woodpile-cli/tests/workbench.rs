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
