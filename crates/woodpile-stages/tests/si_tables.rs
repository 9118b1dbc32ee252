//! Tables of physical scenes in SI: a sweep stage with `units = "SI"` gives its times in s and
//! its energies in J, each point by its own scales, and says so to `render`; `reduce`'s `at`
//! with a unit reads the sample that many seconds in, and a time with a unit is refused where
//! it has no one meaning.
#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;

use common::Project;
use woodpile_pipeline::table;

const SWEEP: &str = r#"
kind = "sweep"
[axes]
K = [3.0e6, 4.0e6]
[scene]
chain = { sites = [-10, 9], boundary = "free" }
impulse = { site = -10 }
physical = { contact = 2.47e9, mass = 0.866e-3, velocity = "$V" }
defect = [{ site = 0, mass = 0.838e-3, resonator_mass = 0.894e-3, stiffness = "$K" }]
run = { t_end = "0.1 ms", sample_every = "10 us", tolerance = 1e-6 }
"#;

fn sweep(velocity_axis: &str) -> String {
    SWEEP
        .replace("K = [", &format!("{velocity_axis}K = ["))
        .replace(
            "velocity = \"$V\"",
            if velocity_axis.is_empty() {
                "velocity = 1.0"
            } else {
                "velocity = \"$V\""
            },
        )
}

/// A reduce stage reading `sweep` at `at` (TOML: a number, or a quoted time with a unit).
fn reduce_at(at: &str) -> String {
    format!("kind = \"reduce\"\ninputs = [\"sweep\"]\nat = {at}\n")
}

/// `text`, a sweep stage, with `units = "SI"`.
fn in_si(text: &str) -> String {
    text.replace("kind = \"sweep\"", "kind = \"sweep\"\nunits = \"SI\"")
}

/// The scene of `SWEEP`'s point `K`, striker speed 1 m/s.
fn point_scene(stiffness: f64) -> woodpile_scene::Scene {
    let text = SWEEP
        .split("[scene]\n")
        .nth(1)
        .unwrap()
        .replace("$K", "")
        .replace("stiffness = \"\"", &format!("stiffness = {stiffness:e}"));
    woodpile_scene::parse(
        &text.replace("velocity = \"$V\"", "velocity = 1.0"),
        Path::new("s.toml"),
    )
    .unwrap()
}

#[test]
fn a_si_sweep_gives_seconds_and_joules_and_the_same_shares() {
    let si = in_si(&sweep(""));
    let p = Project::new(&[("scaled", &sweep("")), ("si", &si)]);
    p.run(&[]).unwrap();
    let (scaled, scaled_manifest) = table::read_with_manifest(&p.output("scaled")).unwrap();
    let (si, manifest) = table::read_with_manifest(&p.output("si")).unwrap();
    assert_eq!(manifest.summary["units"], "SI");
    assert_eq!(manifest.summary["column_units"]["t"], "s");
    assert_eq!(manifest.summary["column_units"]["E"], "J");
    assert_eq!(scaled_manifest.summary["column_units"]["t"], "scaled");
    let column = |frame, name| table::f64_column(frame, name).unwrap();
    for share in ["R", "T", "E_tr"] {
        assert_eq!(column(&scaled, share), column(&si, share), "{share}");
    }
    let stiffness = column(&si, "K");
    for (i, k) in stiffness.iter().enumerate() {
        let scales = point_scene(k.unwrap()).physical.unwrap().scales;
        let joules = scales.mass_kg * scales.velocity * scales.velocity;
        let t = (
            column(&scaled, "t")[i].unwrap(),
            column(&si, "t")[i].unwrap(),
        );
        assert!(
            (t.1 / (t.0 * scales.time_s()) - 1.0).abs() < 1e-12 || t.0 == 0.0,
            "{t:?}"
        );
        let e = (
            column(&scaled, "E")[i].unwrap(),
            column(&si, "E")[i].unwrap(),
        );
        assert!((e.1 / (e.0 * joules) - 1.0).abs() < 1e-12, "{e:?}");
    }
}

/// A figure of a scaled sweep cannot label its time axis in µs; of an SI one it draws µs.
#[test]
fn a_figure_labels_a_sweep_in_the_units_its_table_has() {
    let figure = "kind = \"render\"\ninputs = [\"sweep\"]\ntitle = \"E\"\n[lines]\nx = \"t\"\ny = [\"E\"]\nx_label = \"t (µs)\"\ny_label = \"energy (mJ)\"\n";
    let p = Project::new(&[("sweep", &sweep("")), ("figure", figure)]);
    let error = p.run(&[]).unwrap_err().to_string();
    assert!(
        error.contains("names µs") && error.contains("scaled units"),
        "{error}"
    );
    let si = in_si(&sweep(""));
    let p = Project::new(&[("sweep", &si), ("figure", figure)]);
    p.run(&[]).unwrap();
    let table = table::read(&p.output("sweep")).unwrap();
    let drawn = table::read(&p.output("figure")).unwrap();
    let last = |frame, name| *table::f64_column(frame, name).unwrap().last().unwrap();
    let (t, t_drawn) = (last(&table, "t").unwrap(), last(&drawn, "t").unwrap());
    assert!(
        (t_drawn / (t * 1e6) - 1.0).abs() < 1e-12,
        "{t_drawn} µs against {t} s"
    );
    let (e, e_drawn) = (last(&table, "E").unwrap(), last(&drawn, "E").unwrap());
    assert!(
        (e_drawn / (e * 1e3) - 1.0).abs() < 1e-12,
        "{e_drawn} mJ against {e} J"
    );
}

#[test]
fn si_is_refused_on_a_scene_without_scales() {
    let scaled = "kind = \"sweep\"\nunits = \"SI\"\n[scene]\nchain = { sites = [-10, 9] }\nimpulse = { site = -10 }\nrun = { t_end = 5.0 }\n";
    let error = common::load_error(&[("sweep", scaled)]);
    assert!(
        error.contains("key `units`") && error.contains("[physical]"),
        "{error}"
    );
    let error = common::load_error(&[("sweep", &scaled.replace("\"SI\"", "\"si\""))]);
    assert!(error.contains("key `units`"), "{error}");
}

#[test]
fn a_time_with_a_unit_reads_the_sample_that_many_seconds_in() {
    let p = Project::new(&[("sweep", &sweep("")), ("reduce", &reduce_at("\"50 us\""))]);
    p.run(&[]).unwrap();
    let frame = table::read(&p.output("reduce")).unwrap();
    let t = table::f64_column(&frame, "t").unwrap();
    let scene = woodpile_scene::parse(
        "[chain]\nsites = [-10, 9]\n[impulse]\nsite = -10\n[physical]\ncontact = 2.47e9\nmass = 0.866e-3\nvelocity = 1.0\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let time_s = scene.physical.unwrap().scales.time_s();
    assert_eq!(t.len(), 2);
    for value in t {
        assert!(
            (value.unwrap() * time_s / 50e-6 - 1.0).abs() < 1e-9,
            "{value:?}"
        );
    }
}

#[test]
fn a_time_with_a_unit_is_refused_without_one_time_scale() {
    let p = Project::new(&[
        ("sweep", &sweep("V = [1.0, 2.0]\n")),
        ("reduce", &reduce_at("\"50 us\"")),
    ]);
    let error = p.run(&[]).unwrap_err().to_string();
    assert!(error.contains("time scales"), "{error}");
    let error = common::load_error(&[("sweep", &sweep("")), ("reduce", &reduce_at("\"50 m\""))]);
    assert!(error.contains("key `at`"), "{error}");
}

/// Over an SI sweep each point is read at its own seconds, so a sweep over the striker's
/// speed (one time scale a point) can be read at "50 us"; a bare number is refused there.
#[test]
fn an_si_sweep_is_read_at_seconds_whatever_its_points_time_scales() {
    let si = in_si(&sweep("V = [1.0, 2.0]\n"));
    let p = Project::new(&[("sweep", &si), ("reduce", &reduce_at("\"50 us\""))]);
    p.run(&[]).unwrap();
    let frame = table::read(&p.output("reduce")).unwrap();
    let t = table::f64_column(&frame, "t").unwrap();
    assert_eq!(t.len(), 4);
    for value in t {
        assert!((value.unwrap() / 50e-6 - 1.0).abs() < 1e-9, "{value:?}");
    }
    let p = Project::new(&[("sweep", &si), ("reduce", &reduce_at("5.0"))]);
    let error = p.run(&[]).unwrap_err().to_string();
    assert!(
        error.contains("is in SI") && error.contains("with a unit"),
        "{error}"
    );
}
