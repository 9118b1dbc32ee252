//! `woodpile spectrum` through the real binary: its JSON, its tables, and its refusals with
//! exit codes that name the flag or key.
#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::process::Output;

/// A precompressed chain -30..30 with one linear resonator at site 0.
const ONE_DEFECT: &str =
    "[chain]\nn = 30\nprecompression = 1.0\n[[defect]]\nsite = 0\neps = 0.5\nkappa = 0.3\n";

/// Runs `woodpile spectrum` on `text` (written to `scene.toml` in `dir`) with `args`.
fn spectrum(dir: &Path, text: &str, args: &[&str]) -> Output {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    std::process::Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .arg("spectrum")
        .arg(&path)
        .args(args)
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn prints_the_picture_and_writes_its_tables() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    // A stale table of a part this scene has not (no dashpots) is removed, not left beside
    // the new ones.
    std::fs::create_dir_all(&out_dir).unwrap();
    std::fs::write(out_dir.join("damped.parquet"), b"stale").unwrap();
    let out = spectrum(
        dir.path(),
        ONE_DEFECT,
        &["--out", out_dir.to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["frequency_unit"], "1/time");
    assert_eq!(json["transmission"]["region"], serde_json::json!([0, 0]));
    assert_eq!(json["modes"]["complete"], true);
    for part in ["bands", "wavenumber", "modes", "shapes", "transmission"] {
        assert!(out_dir.join(format!("{part}.parquet")).is_file(), "{part}");
    }
    assert!(!out_dir.join("damped.parquet").exists());
    assert!(!out_dir.join("measured.parquet").exists());
}

#[test]
fn refusals_exit_2_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&str], &str); 5] = [
        ("[chain]\nn = 30\n", &[], "sonic vacuum"),
        (
            ONE_DEFECT,
            &["--cell", "-30,-29"],
            "--cell: the cell does not repeat",
        ),
        (
            ONE_DEFECT,
            &["--cell", "a,b"],
            "--cell `a,b`: expected LO,HI",
        ),
        (
            ONE_DEFECT,
            &["--from", "0.1", "--to", "1.0"],
            "--from/--to/--points: [0.1, 1]",
        ),
        (
            ONE_DEFECT,
            &["--measure"],
            "run.sample_every: 1.0000 is too coarse",
        ),
    ];
    for (scene, args, expected) in cases {
        let out = spectrum(dir.path(), scene, args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(expected),
            "{args:?}: {}",
            stderr(&out)
        );
        assert!(out.stdout.is_empty(), "{args:?}: no numbers with an error");
    }
}
