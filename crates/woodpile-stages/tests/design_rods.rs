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
