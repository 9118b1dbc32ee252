//! A researcher's own study: designs at fixed sites with listed values, the best design being
//! the best any search found, scene files by reference, variants and log-spaced axes.
#![allow(clippy::unwrap_used)]

mod common;

use common::Project;
use woodpile_files::layout::output_path;
use woodpile_pipeline::status::{state, State};
use woodpile_pipeline::variant::Set;
use woodpile_pipeline::{table, Pipeline};
use woodpile_stages::KINDS;

const DESIGN: &str = r#"
kind = "design"
seed = 3
budget = 30
refine = 6
objective = "E_tr"
verify_tolerance = 1e-7
[scene]
chain = { n = 12 }
impulse = { site = -6 }
run = { t_end = 12.0, method = "auto", tolerance = 1e-5 }
fractions = { region = [-1, 6] }
[space]
sites = { fixed = [0, 2, 5] }
eps = [0.5, 2.0, 8.0]
kappa = { min = 0.5, max = 2.0 }
"#;

/// A design at fixed sites with listed eps values: every row uses exactly those sites and
/// values, the best file holds the best design of any search, and the verification row
/// carries the error estimate the summary states.
#[test]
fn a_design_at_fixed_sites_writes_the_best_design_any_search_found() {
    let p = Project::new(&[("trap", DESIGN)]);
    p.run_with(&[], &[]).unwrap();
    let (frame, manifest) = table::read_with_manifest(&output_path(&p.results(), "trap")).unwrap();
    let search = table::str_column(&frame, "search").unwrap();
    // Sites and eps are list columns: one list per design.
    let list = |name: &str| -> Vec<Vec<f64>> {
        let column = frame.column(name).unwrap();
        (0..frame.height())
            .map(|i| match column.get(i).unwrap() {
                polars::prelude::AnyValue::List(s) => s
                    .cast(&polars::prelude::DataType::Float64)
                    .unwrap()
                    .f64()
                    .unwrap()
                    .into_no_null_iter()
                    .collect(),
                other => panic!("{name} row {i}: {other:?}"),
            })
            .collect()
    };
    assert!(list("sites").iter().all(|s| s == &[0.0, 2.0, 5.0]));
    for eps in list("eps") {
        assert!(eps.iter().all(|e| [0.5, 2.0, 8.0].contains(e)), "{eps:?}");
    }
    let e_tr = table::f64_column(&frame, "E_tr").unwrap();
    let best_any = (0..frame.height())
        .filter(|&i| search[i].as_deref().is_some_and(|s| s != "verification"))
        .filter_map(|i| e_tr[i])
        .fold(f64::NEG_INFINITY, f64::max);
    let summary = &manifest.summary;
    let verified = (0..frame.height())
        .find(|&i| search[i].as_deref() == Some("verification"))
        .unwrap();
    // The verified design is the best found, simulated again at the tighter tolerance.
    assert!((e_tr[verified].unwrap() - best_any).abs() < 1e-4);
    let estimate = table::f64_column(&frame, "error_estimate").unwrap()[verified];
    assert_eq!(estimate, summary["best_error_estimate"].as_f64());
    assert!(summary["best_search"].is_string());
    assert!(summary["baseline_beat_optimiser"].is_boolean());
    // The best file is that design and runs as it is.
    let best = woodpile_scene::load(&p.results().join("trap.best.toml")).unwrap();
    let out = woodpile_sim::simulation::simulate(&best.scenario, &mut ()).unwrap();
    assert_eq!(out.fractions.trapped, e_tr[verified].unwrap());
}

/// A sweep names its scene file and overrides what it varies, on a log-spaced axis; editing
/// the file makes it stale; a variant runs beside it with its own key and output.
#[test]
fn scene_files_by_reference_variants_and_log_axes() {
    let sweep = r#"
kind = "sweep"
axes = { eps = { from = 0.1, to = 10.0, count = 5, log = true } }
[scene]
file = "scenes/base.toml"
defect = [{ site = 0, eps = "$eps" }]
"#;
    let reduce = "kind = \"reduce\"\ninputs = [\"sweep\"]\nat = 10.0\n";
    let p = Project::new(&[("sweep", sweep), ("at_end", reduce)]);
    std::fs::create_dir_all(p.root().join("scenes")).unwrap();
    let base = "[chain]\nn = 10\n[impulse]\nsite = -5\n[[defect]]\nsite = 3\neps = 1.0\n[run]\nt_end = 10.0\nmethod = \"rk4\"\ndt = 0.02\n";
    std::fs::write(p.root().join("scenes/base.toml"), base).unwrap();
    let pipeline = p.run_with(&[], &[]).unwrap();
    let table = table::read(&output_path(&p.results(), "at_end")).unwrap();
    let eps = table::f64_column(&table, "eps").unwrap();
    assert_eq!(
        eps,
        [
            Some(0.1),
            Some(0.316227766017),
            Some(1.0),
            Some(3.16227766017),
            Some(10.0)
        ]
    );
    // The override replaced the file's defects: one defect at 0.
    let params = pipeline.stage("sweep").unwrap().params.value();
    assert_eq!(params["scene"]["defect"].as_array().unwrap().len(), 1);
    assert_eq!(params["scene"]["chain"]["n"], 10);

    std::fs::write(
        p.root().join("scenes/base.toml"),
        base.replace("t_end = 10.0", "t_end = 12.0"),
    )
    .unwrap();
    let pipeline = Pipeline::load(&p.root().join("pipeline"), KINDS).unwrap();
    let st = state(
        &pipeline,
        &p.results(),
        &p.root().join("figures"),
        pipeline.stage("sweep").unwrap(),
    );
    assert!(
        matches!(st, State::Stale(ref why) if why.iter().any(|w| w.contains("scene.run.t_end"))),
        "{st:?}"
    );
    std::fs::write(p.root().join("scenes/base.toml"), base).unwrap();

    let set = Set::parse("at_end.at=6.0").unwrap();
    let name = woodpile_pipeline::variant::variant_name("at_end", std::slice::from_ref(&set));
    assert!(name.starts_with("at_end--at-6_0-"), "{name}");
    p.run_with(std::slice::from_ref(&set), &[&name]).unwrap();
    let variant = table::read(&output_path(&p.results(), &name)).unwrap();
    assert!(table::f64_column(&variant, "t")
        .unwrap()
        .iter()
        .all(|t| *t == Some(6.0)));
    let original = table::read(&output_path(&p.results(), "at_end")).unwrap();
    assert!(table::f64_column(&original, "t")
        .unwrap()
        .iter()
        .all(|t| *t == Some(10.0)));
}

/// Optimize within explicit bounds from several starts: R, T and the error estimate on every
/// row, a sensitivity and an edge flag per axis, whether the starts agree, and the optimum as a
/// scene file that gives its number.
#[test]
fn optimize_with_bounds_and_starts_reports_what_a_user_needs() {
    let sweep = r#"
kind = "sweep"
[axes]
eps = [0.5, 1.0, 2.0, 4.0]
[scene]
chain = { n = 12 }
impulse = { site = -6 }
run = { t_end = 12.0, method = "auto", tolerance = 1e-5 }
[[scene.defect]]
site = 0
eps = "$eps"
"#;
    let reduce = "kind = \"reduce\"\ninputs = [\"sweep\"]\nat = 12.0\n";
    let optimize = r#"
kind = "optimize"
inputs = ["at_end"]
over = ["eps"]
tolerance = 1e-7
bounds = { eps = [0.5, 3.0] }
starts = 2
"#;
    let p = Project::new(&[("sweep", sweep), ("at_end", reduce), ("best", optimize)]);
    p.run_with(&[], &[]).unwrap();
    let (frame, manifest) = table::read_with_manifest(&output_path(&p.results(), "best")).unwrap();
    assert_eq!(frame.height(), 4);
    for column in [
        "start",
        "R",
        "T",
        "E_tr",
        "error_estimate",
        "sensitivity_eps",
        "edge_eps",
    ] {
        assert!(frame.column(column).is_ok(), "{column}");
    }
    let eps = table::f64_column(&frame, "eps").unwrap();
    assert!(
        eps.iter().flatten().all(|e| (0.5..=3.0).contains(e)),
        "{eps:?}"
    );
    let summary = &manifest.summary;
    assert_eq!(summary["starts"], 2);
    assert!(summary["starts_agree"].is_boolean() && summary["sharp"].is_boolean());
    assert_eq!(summary["box"][0]["hi"], 3.0);
    let best = woodpile_scene::load(&p.results().join("best.best.toml")).unwrap();
    let out = woodpile_sim::simulation::simulate(&best.scenario, &mut ()).unwrap();
    assert_eq!(out.fractions.trapped, summary["refined"].as_f64().unwrap());
}
