//! The `calibrate` kind: a trace file of the project fitted for a scene's keys, the stage
//! keyed by the trace's bytes, and a bad trace refused naming the file.
#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;

use common::Project;
use woodpile_pipeline::status::State;
use woodpile_pipeline::table;

/// The known chain (`woodpile_calibrate::testing`), fitted for its dashpot from a trace.
const STAGE: &str = r#"
kind = "calibrate"
trace = "trace.csv"
[parameters]
"damping.contact" = { min = 100.0, max = 20000.0, start = 3000.0 }
[scene]
chain = { sites = [-10, 9], boundary = "free" }
impulse = { site = -10 }
physical = { contact = 2.47e9, mass = 0.866e-3, velocity = 1.0 }
defect = [{ site = 0, mass = 0.838e-3, resonator_mass = 0.894e-3, stiffness = 3.961e6, quality_factor = 30.0 }]
damping = { contact = 3000.0, law = "hertzian" }
run = { t_end = "0.3 ms", tolerance = 1e-6 }
"#;

/// The known scene's noiseless trace at rods -5 and 0 every 4 µs for 0.3 ms, as CSV.
fn trace_csv() -> String {
    let table: toml::Table = toml::from_str(woodpile_calibrate::testing::SCENE).unwrap();
    let truth = woodpile_scene::from_table(table, Path::new("truth.toml")).unwrap();
    let trace =
        woodpile_calibrate::synthetic::noisy_trace(&truth, &[-5, 0], 4e-6, 3e-4, 0.0, 1).unwrap();
    let mut csv = String::from("# a comment\nt,rod,velocity\n");
    for ((t, rod), v) in trace.t.iter().zip(&trace.rod).zip(&trace.velocity) {
        csv += &format!("{t:e},{rod},{v:e}\n");
    }
    csv
}

fn project(csv: &str) -> Project {
    let p = Project::new(&[]);
    std::fs::write(p.root().join("trace.csv"), csv).unwrap();
    p.write("calibration", STAGE);
    p
}

#[test]
fn a_trace_file_is_fitted_and_keys_its_stage() {
    let csv = trace_csv();
    let p = project(&csv);
    p.run(&[]).unwrap();
    let (frame, manifest) = table::read_with_manifest(&p.output("calibration")).unwrap();
    let names: Vec<String> = frame
        .get_column_names()
        .iter()
        .map(|n| n.to_string())
        .collect();
    assert_eq!(names, ["t", "rod", "velocity", "fitted", "residual"]);
    let estimate = &manifest.summary["estimates"][0];
    assert_eq!(estimate["key"], "damping.contact");
    let gamma = estimate["value"].as_f64().unwrap();
    assert!(
        (gamma / woodpile_calibrate::testing::GAMMA - 1.0).abs() < 1e-3,
        "{gamma}"
    );
    assert_eq!(p.state("calibration"), State::Fresh);
    std::fs::write(
        p.root().join("trace.csv"),
        csv.replacen("t,rod", "t, rod", 1),
    )
    .unwrap();
    assert!(matches!(p.state("calibration"), State::Stale(_)));
}

#[test]
fn a_bad_trace_is_refused_naming_the_file() {
    let broken = trace_csv().replacen(",0,", ",zero,", 1);
    let error = project(&broken).run(&[]).unwrap_err().to_string();
    assert!(
        error.contains("trace.csv") && error.contains("zero"),
        "{error}"
    );
    let p = Project::new(&[]);
    p.write("calibration", STAGE);
    let error = p.run(&[]).unwrap_err().to_string();
    assert!(error.contains("trace"), "{error}");
}
