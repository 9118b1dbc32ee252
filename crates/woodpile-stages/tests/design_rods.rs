//! The design kind over defect rods (`[space] length`): a physical scene's defect rods placed
//! and cut by the search, eps and kappa derived from each rod, the best design written as an
//! SI scene with its bill of rods.
#![allow(clippy::unwrap_used)]

mod common;

use common::Project;
use woodpile_pipeline::table;

const RODS: &str = r#"
kind = "design"
seed = 7
budget = 20
refine = 4
objective = "E_tr"
verify_tolerance = 1e-6
[scene]
chain = { sites = [-20, 19], boundary = "free" }
physical = { velocity = 1.0, material = { youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }, rod = { length = 0.020, diameter = 0.005 } }
impulse = { site = -20 }
run = { t_end = 40.0, tolerance = 1e-5 }
fractions = { region = [-5, 4] }
[space]
sites = { fixed = [-4, 3] }
length = { min = "20 mm", max = "80 mm" }
"#;

#[test]
fn a_design_of_rod_lengths_writes_an_si_scene_and_its_bill_of_rods() {
    let p = Project::new(&[("rods", RODS)]);
    p.run(&[]).unwrap();
    let (frame, manifest) = table::read_with_manifest(&p.output("rods")).unwrap();
    let values = |column: &str, row: usize| -> Vec<f64> {
        let lists = frame.column(column).unwrap().list().unwrap().clone();
        let series = lists.get_as_series(row).unwrap();
        series.f64().unwrap().iter().flatten().collect()
    };
    for row in 0..frame.height() {
        let lengths = values("length", row);
        assert_eq!(lengths.len(), 2);
        assert!(
            lengths.iter().all(|x| (0.02..=0.08).contains(x)),
            "{lengths:?}"
        );
        assert!(values("eps", row).iter().all(|&e| e > 0.0), "derived eps");
    }
    let bill = manifest.summary["bill_of_rods"].as_array().unwrap();
    assert_eq!(bill.len(), 2);
    for rod in bill {
        let length = rod["length_m"].as_f64().unwrap();
        assert!((0.02..=0.08).contains(&length));
        assert!(rod["bending_f1_hz"].as_f64().unwrap() > 0.0);
        assert!(rod["resonator_mass_kg"].as_f64().unwrap() > 0.0);
    }
    let best = p.results().join("rods.best.toml");
    let scene = woodpile_scene::load(&best).unwrap();
    assert!(scene.physical.is_some());
    assert!(std::fs::read_to_string(&best).unwrap().contains("rod"));
}

#[test]
fn a_rod_space_refuses_eps_and_kappa() {
    let error = common::load_error(&[(
        "rods",
        &RODS.replace("length = {", "eps = [1.0]\nlength = {"),
    )]);
    assert!(error.contains("space.eps"), "{error}");
    let error = common::load_error(&[("rods", &RODS.replace("\"20 mm\"", "\"20 s\""))]);
    assert!(error.contains("length"), "{error}");
}

/// `vary` takes the design's best SI scene as it is and varies physical keys on it: each
/// defect rod's quality factor (inside the design's own `[[defect]]` list) and the run's
/// length in ms, its table in SI. The lossier rods lose more.
#[test]
fn a_rod_design_is_varied_over_physical_keys() {
    let vary = r#"
kind = "vary"
inputs = ["rods"]
units = "SI"
[axes]
Q = [10.0, 1000.0]
[set]
run = { t_end = "0.3 ms", tolerance = 1e-5 }
[set_each]
defect = { quality_factor = "$Q" }
"#;
    let p = Project::new(&[("rods", RODS), ("varied", vary)]);
    p.run(&[]).unwrap();
    let (frame, manifest) = table::read_with_manifest(&p.output("varied")).unwrap();
    assert_eq!(manifest.summary["column_units"]["t"], "s");
    let q = table::f64_column(&frame, "Q").unwrap();
    let trapped = table::f64_column(&frame, "E_tr").unwrap();
    let dissipated = table::f64_column(&frame, "D").unwrap();
    let last = |value: f64| {
        let rows: Vec<usize> = (0..q.len()).filter(|&i| q[i] == Some(value)).collect();
        let i = *rows.last().unwrap();
        (trapped[i].unwrap(), dissipated[i].unwrap())
    };
    let (lossy, nearly_lossless) = (last(10.0), last(1000.0));
    assert!(
        lossy.1 > nearly_lossless.1 && lossy.1 > 0.0,
        "{lossy:?} {nearly_lossless:?}"
    );
    let t = table::f64_column(&frame, "t").unwrap();
    let end = t.iter().flatten().fold(0.0_f64, |a, &b| a.max(b));
    assert!((end / 0.3e-3 - 1.0).abs() < 1e-9, "{end} s");
}
