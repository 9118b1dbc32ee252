//! The `spectrum` kind: a grid of scenes gives each point's table after its axes, frequencies
//! come in the stage's unit, and a bad request is refused at load naming its key.
#![allow(clippy::unwrap_used)]

mod common;

use common::Project;
use woodpile_pipeline::table;

/// The transmission of one resonator defect, at two couplings.
const TRANSMISSION: &str = r#"
kind = "spectrum"
table = "transmission"
frequencies = { min = 0.01, max = 0.3, points = 30 }
[axes]
kappa = [0.3, 0.6]
[scene]
chain = { n = 30, precompression = 1.0 }
defect = [{ site = 0, eps = 0.5, kappa = "$kappa" }]
"#;

#[test]
fn each_point_of_a_grid_has_its_own_rows() {
    let p = Project::new(&[("spectrum", TRANSMISSION)]);
    p.run(&[]).unwrap();
    let frame = table::read(&p.output("spectrum")).unwrap();
    assert_eq!(frame.height(), 60);
    let kappa = table::f64_column(&frame, "kappa").unwrap();
    let t = table::f64_column(&frame, "transmittance").unwrap();
    let f = table::f64_column(&frame, "frequency").unwrap();
    // The resonator blocks its own frequency ω0 = sqrt(κ/ε): the deepest row of each point.
    for (point, k) in [0.3, 0.6].into_iter().enumerate() {
        let rows = point * 30..point * 30 + 30;
        assert!(rows.clone().all(|r| kappa[r] == Some(k)));
        let deepest = rows
            .min_by(|&a, &b| t[a].unwrap().total_cmp(&t[b].unwrap()))
            .unwrap();
        let f0 = (k / 0.5_f64).sqrt() / std::f64::consts::TAU;
        assert!(
            (f[deepest].unwrap() - f0).abs() < 0.01,
            "κ {k}: {:?}",
            f[deepest]
        );
    }
}

#[test]
fn bad_requests_are_refused_at_load_naming_the_key() {
    let cases = [
        (
            TRANSMISSION.replace("max = 0.3", "max = 3.0"),
            "key `frequencies`",
        ),
        (
            TRANSMISSION.replace(
                "table = \"transmission\"",
                "table = \"bands\"\ncell = [-30, -29]",
            ),
            "key `cell`",
        ),
        (
            TRANSMISSION.replace("table = \"transmission\"", "table = \"phonons\""),
            "key `table`",
        ),
        (
            TRANSMISSION.replace("precompression = 1.0", "precompression = 0.0"),
            "sonic vacuum",
        ),
        (
            TRANSMISSION.replace(
                "table = \"transmission\"",
                "table = \"modes\"\nfrequency_unit = \"kHz\"",
            ),
            "key `frequency_unit`",
        ),
        (
            TRANSMISSION.replace("table = \"transmission\"", "table = \"modes\"\nprobe = 3"),
            "key `probe`",
        ),
    ];
    for (stage, expected) in cases {
        let p = Project::new(&[("spectrum", &stage)]);
        let e = p.run(&[]).unwrap_err().to_string();
        assert!(
            e.contains(expected) && e.contains("spectrum.toml"),
            "{expected}: {e}"
        );
    }
}
