//! `reduce`'s `at` with a unit: a physical sweep read out at "50 us" is read at the sample
//! that many seconds in, and a time with a unit is refused where it has no one meaning.
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

#[test]
fn a_time_with_a_unit_reads_the_sample_that_many_seconds_in() {
    let p = Project::new(&[
        ("sweep", &sweep("")),
        (
            "reduce",
            "kind = \"reduce\"\ninputs = [\"sweep\"]\nat = \"50 us\"\n",
        ),
    ]);
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
        (
            "reduce",
            "kind = \"reduce\"\ninputs = [\"sweep\"]\nat = \"50 us\"\n",
        ),
    ]);
    let error = p.run(&[]).unwrap_err().to_string();
    assert!(error.contains("time scales"), "{error}");
    let error = common::load_error(&[
        ("sweep", &sweep("")),
        (
            "reduce",
            "kind = \"reduce\"\ninputs = [\"sweep\"]\nat = \"50 m\"\n",
        ),
    ]);
    assert!(error.contains("key `at`"), "{error}");
}
