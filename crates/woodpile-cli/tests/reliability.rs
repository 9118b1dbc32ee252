//! Issue 55 (reliability, round 5) through the real binary: no number is printed as verified
//! unless every share is finite, in [0, 1] and sums to 1 (the rule of
//! `woodpile_sim::simulation::check_shares`), and the new physics keys' gaps are refused or
//! fixed.
#![allow(clippy::unwrap_used)]

use std::path::PathBuf;
use std::process::Output;

/// Runs `woodpile simulate` on `text` written to a fresh temporary file (kept with the
/// returned folder until the test ends).
fn simulate(text: &str) -> (Output, PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_woodpile"))
        .arg("simulate")
        .arg(&path)
        .output()
        .unwrap();
    (out, path, dir)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// C1: a precompression whose static overlap overflows (a wall contact of 1e-300, or a linear
/// law under 1e300) left every share NaN and was printed with exit 0 as conserved. It now exits
/// 3 naming the shares, prints no numbers, under every method.
#[test]
fn overflowing_precompression_exits_3_without_numbers() {
    let chains = [
        "[chain]\nn = 20\nprecompression = 1.0\nwall_contact = 1e-300\n",
        "[chain]\nn = 20\nexponent = 1.0\nprecompression = 1e300\n",
    ];
    let methods = [
        "method = \"auto\"\ntolerance = 1e-6",
        "method = \"rk4\"\ndt = 0.01",
        "method = \"verlet\"\ndt = 0.01",
        "method = \"dop853\"",
    ];
    for chain in chains {
        for method in methods {
            let scene = format!("{chain}[impulse]\nsite = -5\n[run]\nt_end = 5.0\n{method}\n");
            let (out, path, _dir) = simulate(&scene);
            let why = stderr(&out);
            assert_eq!(out.status.code(), Some(3), "{scene}\n{why}");
            assert!(out.stdout.is_empty(), "{scene}: printed {:?}", out.stdout);
            assert!(why.contains(&path.display().to_string()), "{why}");
            assert!(!why.contains("panicked"), "{why}");
        }
    }
}

/// C2: a κ ramp works on the chain and a damped chain's ledger has no term for it (shares
/// summed to 4.95, printed as verified). Refused at load, naming both keys.
#[test]
fn a_kappa_ramp_with_losses_is_refused_naming_both_keys() {
    let ramp = "[chain]\nn = 60\n[impulse]\nsite = -20\n[[defect]]\nsite = 0\neps = 1.0\nkappa = { k1 = 0.0, k2 = 2.5, t0 = 40.0, tau = 0.1 }\n";
    for (losses, key) in [
        ("[damping]\nground = 1e-300\n", "damping"),
        ("[damping]\ncontact = 0.01\n", "damping"),
        (
            "[[defect]]\nsite = 5\neps = 1.0\nquality_factor = 50.0\n",
            "defect[1].quality_factor",
        ),
    ] {
        let (out, path, _dir) = simulate(&format!("{ramp}{losses}[run]\nt_end = 60.0\n"));
        let why = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{losses}: {why}");
        for needle in [path.display().to_string().as_str(), "defect[0].kappa", key] {
            assert!(why.contains(needle), "{why:?} lacks {needle:?}");
        }
    }
}

/// D15: a defect on the first site with no `fractions.region` was refused as a region off the
/// chain; the default region is cut to the chain, and a chain without site 0 reads around its
/// middle.
#[test]
fn the_default_region_fits_any_chain() {
    for scene in [
        "[chain]\nsites = [0, 40]\n[impulse]\nsite = 20\n[[defect]]\nsite = 0\neps = 2.0\n[run]\nt_end = 30.0\n",
        "[chain]\nsites = [5, 60]\n[impulse]\nsite = 10\n[run]\nt_end = 20.0\n",
    ] {
        let (out, _path, _dir) = simulate(scene);
        assert_eq!(out.status.code(), Some(0), "{scene}: {}", stderr(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let sum: f64 = ["R", "T", "E_tr"].iter().map(|k| v[k].as_f64().unwrap()).sum();
        assert!((sum - 1.0).abs() < 1e-12, "{v}");
    }
}

/// A segment's mass or contact list longer than the segment was cut short without a word: it
/// is refused, naming the key.
#[test]
fn a_segment_list_longer_than_its_segment_is_refused() {
    for (segment, key) in [
        (
            "sites = [0, 2]\nmass = [1.0, 2.0, 3.0, 4.0]",
            "segment[0].mass",
        ),
        (
            "sites = [0, 2]\ncontact = [1.0, 2.0, 3.0]",
            "segment[0].contact",
        ),
    ] {
        let scene = format!("[chain]\nn = 20\n[[segment]]\n{segment}\n[run]\nt_end = 5.0\n");
        let (out, _path, _dir) = simulate(&scene);
        let why = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{why}");
        assert!(
            why.contains(key) && why.contains("values for a segment"),
            "{why}"
        );
    }
}

/// B8: many segments are checked for overlap in time linear in the chain (a quadratic check
/// took 29 s for 4·10⁵): 20,000 one-site segments and one overlapping pair at the end.
#[test]
fn many_segments_are_checked_for_overlap_at_once() {
    let n = 20_000;
    let mut scene = format!("[chain]\nsites = [0, {n}]\n[impulse]\nsite = 0\n");
    for site in 1..n {
        scene.push_str(&format!(
            "[[segment]]\nsites = [{site}, {site}]\nmass = 1.0\n"
        ));
    }
    scene.push_str("[[segment]]\nsites = [5, 7]\nmass = 2.0\n[run]\nt_end = 1.0\n");
    let (out, _path, _dir) = simulate(&scene);
    let why = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{why}");
    assert!(
        why.contains(&format!("segment[{}].sites", n - 1)) && why.contains("segment[4]"),
        "{why}"
    );
}

/// D16: a defect rod outside beam theory (a 1 mm stub of 5 mm, f1 = 2.8 MHz; a 10 m thick
/// rod, a 3.6-tonne resonator) was accepted silently; its slenderness is refused, naming the
/// key and the range.
#[test]
fn defect_rods_outside_beam_theory_are_refused() {
    let physical = "[chain]\nsites = [-20, 19]\nboundary = \"free\"\n[physical]\nvelocity = 1.0\nmaterial = { youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }\nrod = { length = 0.020, diameter = 0.005 }\n[impulse]\nsite = -20\n[run]\nt_end = 10.0\n";
    for rod in [
        "{ length = 0.001 }",
        "{ length = 0.040, diameter = 10.0 }",
        "{ length = 1.0, diameter = 0.005 }",
    ] {
        let (out, _path, _dir) =
            simulate(&format!("{physical}[[defect]]\nsite = 0\nrod = {rod}\n"));
        let why = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{rod}: {why}");
        assert!(
            why.contains("defect[0].rod.length") && why.contains("L/d"),
            "{why}"
        );
    }
    let (out, _path, _dir) = simulate(&format!(
        "{physical}[[defect]]\nsite = 0\nrod = {{ length = 0.040 }}\n"
    ));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

/// B9: `defaults.toml` is shared by the stages of its kind, not copied into each. A 58 KB
/// `[render.labels]` under 2,000 render stages took about 900 MB (each stage held the merged
/// table's parameters and its own parsed labels); `status` now runs in 300 MB of address space.
#[test]
fn a_large_defaults_file_is_shared_by_its_stages_not_copied() {
    let dir = tempfile::tempdir().unwrap();
    let pipeline = dir.path().join("pipeline");
    std::fs::create_dir(&pipeline).unwrap();
    let mut defaults = String::from("[render.labels]\n");
    for i in 0.. {
        if defaults.len() > 58_000 {
            break;
        }
        defaults.push_str(&format!("k{i} = \"label number {i} with some text\"\n"));
    }
    std::fs::write(pipeline.join("defaults.toml"), defaults).unwrap();
    std::fs::write(
        pipeline.join("s.toml"),
        "kind = \"sweep\"\n[scene]\nchain = { n = 10 }\nimpulse = { site = -5 }\nrun = { t_end = 5.0 }\n",
    )
    .unwrap();
    for i in 0..2000 {
        let stage = format!("kind = \"render\"\ninputs = [\"s\"]\ntitle = \"figure {i}\"\n[lines]\nx = \"t\"\ny = [\"R\"]\nx_label = \"t\"\ny_label = \"R\"\n");
        std::fs::write(pipeline.join(format!("r{i}.toml")), stage).unwrap();
    }
    let out = std::process::Command::new("sh")
        .current_dir(dir.path())
        .arg("-c")
        .arg(format!(
            "ulimit -v 300000; exec timeout 120 {} status",
            env!("CARGO_BIN_EXE_woodpile")
        ))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout)
            .matches("missing")
            .count(),
        2001
    );
}
