//! The other kinds end to end: optimize, report, kinetic series, work-precision and design.
#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;
use std::sync::atomic::Ordering;

use common::{
    design, load_error, load_error_after_reduce, single_defect_sweep_to, Project, BEST, REDUCE,
    REPORT, SWEEP, WORK_PRECISION, WORK_PRECISION_CHART,
};
use woodpile_files::layout::points_dir;
use woodpile_pipeline::status::State;
use woodpile_pipeline::table;

#[test]
fn optimize_refines_a_grid_maximum_between_grid_points() {
    let coarse = single_defect_sweep_to(3.0);
    let optimum = r#"
kind = "optimize"
inputs = ["at_end"]
over = ["eps"]
tolerance = 1e-7
"#;
    let p = Project::new(&[("sweep", &coarse), ("at_end", REDUCE), ("optimum", optimum)]);
    p.counted(&[]);
    let out = table::read(&p.output("optimum")).unwrap();
    let e_tr = table::f64_column(&out, "E_tr").unwrap();
    let eps = table::f64_column(&out, "eps").unwrap();
    let (grid, refined) = (e_tr[0].unwrap(), e_tr[1].unwrap());
    assert!(
        refined >= grid,
        "the search never ends below its start: {grid} -> {refined}"
    );
    assert!(
        (0.5..=3.0).contains(&eps[1].unwrap()),
        "stays inside the grid's box"
    );
    // Only float axes can be searched, and only through a plain reduce.
    let e = load_error(&[
        ("sweep", &coarse),
        ("at_end", REDUCE),
        ("optimum", &optimum.replace("[\"eps\"]", "[\"L\"]")),
    ]);
    assert!(
        e.contains("optimum.toml") && e.contains("integer axis"),
        "{e}"
    );
    let e = load_error(&[
        ("sweep", &coarse),
        ("best", BEST),
        ("optimum", &optimum.replace("at_end", "best")),
    ]);
    assert!(e.contains("maximises already"), "{e}");
}

/// The report reads numbers where its sources say, finds by scanning the read-out time where a
/// quoted number is met, and writes its Markdown beside `results/`.
#[test]
fn a_report_reads_and_scans_the_quoted_numbers() {
    // The "paper's" number: E_tr at t = 8, which the end-time read-out misses.
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE)]);
    p.counted(&[]);
    let sweep = table::read(&p.output("sweep")).unwrap();
    let column = |name: &str| table::f64_column(&sweep, name).unwrap();
    let (l, eps, t, e_tr) = (column("L"), column("eps"), column("t"), column("E_tr"));
    let row = |time: f64| {
        (0..sweep.height())
            .find(|&r| l[r] == Some(0.0) && eps[r] == Some(1.0) && t[r] == Some(time))
            .unwrap()
    };
    let at_8 = e_tr[row(8.0)].unwrap();
    let at_12 = e_tr[row(12.0)].unwrap();
    assert!(
        (at_8 - at_12).abs() > 1e-6,
        "the test needs two distinct read-outs"
    );

    p.write("report", &REPORT.replace("PAPER", &format!("{at_8:e}")));
    p.counted(&["report"]);
    let report = table::read(&p.output("report")).unwrap();
    assert_eq!(report.height(), 3);
    let value = table::f64_column(&report, "value").unwrap();
    let reproduces = table::f64_column(&report, "reproduces").unwrap();
    let closest = table::f64_column(&report, "scan_closest").unwrap();
    assert_eq!(value[0], Some(at_12));
    assert_eq!(reproduces[0], Some(0.0));
    assert_eq!(value[1], Some(at_8));
    assert_eq!(reproduces[1], Some(1.0));
    assert_eq!(closest[1], Some(8.0));
    let best = (0..sweep.height())
        .filter(|&r| t[r] == Some(12.0))
        .filter_map(|r| e_tr[r])
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(value[2], Some(best));

    let markdown = p.results().parent().unwrap().join("REPORT.md");
    let text = std::fs::read_to_string(&markdown).unwrap();
    assert!(
        text.starts_with("# Tiny report") && text.contains("| X1 |"),
        "{text}"
    );
    assert_eq!(p.state("report"), State::Fresh);
    std::fs::remove_file(&markdown).unwrap();
    assert!(matches!(p.state("report"), State::Stale(_)));
}

#[test]
fn a_report_source_must_be_an_input() {
    let report = REPORT
        .replace("PAPER", "0.1")
        .replace("inputs = [\"sweep\", \"at_end\"]", "inputs = [\"sweep\"]");
    let e = load_error_after_reduce("report", &report);
    assert!(
        e.contains("report.toml") && e.contains("quote[0].ours.stage") && e.contains("at_end"),
        "{e}"
    );
}

/// A kinetic sweep divides kinetic energy by the impact energy: at t = 0 all of it is the
/// striker's, left of the region. Its points are cached apart from the energy sweep's.
#[test]
fn a_kinetic_sweep_starts_with_the_impact_energy_left_of_the_region() {
    let kinetic = SWEEP.replace("kind = \"sweep\"", "kind = \"sweep\"\nseries = \"kinetic\"");
    let p = Project::new(&[("sweep", SWEEP), ("kinetic", &kinetic)]);
    let events = p.counted(&[]);
    assert_eq!(events.points.load(Ordering::SeqCst), 12);
    let frame = table::read(&p.output("kinetic")).unwrap();
    let t = table::f64_column(&frame, "t").unwrap();
    let r = table::f64_column(&frame, "R").unwrap();
    let e_tr = table::f64_column(&frame, "E_tr").unwrap();
    for row in (0..frame.height()).filter(|&i| t[i] == Some(0.0)) {
        assert_eq!(r[row], Some(1.0));
        assert_eq!(e_tr[row], Some(0.0));
    }
    let energy = table::read(&p.output("sweep")).unwrap();
    let r_energy = table::f64_column(&energy, "R").unwrap();
    // Later on potential energy exists, so the two series differ.
    assert!((0..frame.height()).any(|i| (r[i].unwrap() - r_energy[i].unwrap()).abs() > 1e-3));
}

/// A work-precision stage measures every setting against its reference: RK4's error falls
/// with its step at about its order on a smooth enough scene, and the chart draws one curve per
/// method.
#[test]
fn work_precision_measures_error_against_the_reference() {
    let p = Project::new(&[("wp", WORK_PRECISION), ("chart", WORK_PRECISION_CHART)]);
    p.counted(&[]);
    let frame = table::read(&p.output("wp")).unwrap();
    assert_eq!(frame.height(), 4);
    let error = table::f64_column(&frame, "error").unwrap();
    let wall = table::f64_column(&frame, "wall_ms").unwrap();
    let e = |i: usize| error[i].unwrap();
    assert!(e(0) > e(1) && e(1) > e(2), "{error:?}");
    // Halving dt divides RK4's error by at least 2^2.5 (the contact-limited order) on this scene.
    assert!(e(1) / e(2) > 5.0, "{error:?}");
    assert!(wall.iter().all(|w| w.is_some_and(|w| w > 0.0)));
    let manifest = table::read_manifest(&p.output("wp")).unwrap().unwrap();
    let reference = manifest.summary["references"][0]["E_tr"].as_f64().unwrap();
    let e_tr = table::f64_column(&frame, "E_tr").unwrap();
    assert!(((e_tr[2].unwrap() - reference).abs() - e(2)).abs() < 1e-15);
    assert_eq!(manifest.summary["runs"].as_u64(), Some(4));
    assert!(p.figures().join("chart.png").exists());
    assert_eq!(p.state("chart"), State::Fresh);
}

/// The design these tests search: 40 trials, refined 10 times, the best verified at 1e-8.
fn design_file() -> String {
    design(40, 10, 1e-6, 1e-8, "samples = 6, spreads = [0.01, 0.05]")
}

fn count_files(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .map(|e| {
                    if e.path().is_dir() {
                        count_files(&e.path())
                    } else {
                        1
                    }
                })
                .sum()
        })
        .unwrap_or(0)
}

/// The design stage searches, verifies its best design, and writes it as a scene file that
/// loads as it is and gives the verified number; the search depends on the seed alone (any
/// thread count), and a repeated search finds every trial in the point cache.
#[test]
fn a_design_stage_finds_verifies_and_writes_its_best_design() {
    let outputs: Vec<Vec<u8>> = [1, 2]
        .into_iter()
        .map(|threads| {
            let p = Project::new(&[("trap", &design_file())]);
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| p.counted(&[]));
            // The table and its manifest, but not the best file's checksum: the file names
            // its own path, which differs between the two projects.
            let checked = table::read_checked(&p.output("trap")).unwrap();
            let mut manifest = checked.manifest.unwrap();
            manifest.files.clear();
            manifest.checksum = None;
            let mut frame = checked.frame;
            let mut bytes = Vec::new();
            polars::prelude::ParquetWriter::new(&mut bytes)
                .finish(&mut frame)
                .unwrap();
            bytes.extend(manifest.to_json_text().into_bytes());
            bytes
        })
        .collect();
    assert!(
        outputs[0] == outputs[1],
        "the search depends on the seed alone"
    );

    let p = Project::new(&[("trap", &design_file())]);
    p.counted(&[]);
    let table = table::read(&p.output("trap")).unwrap();
    let search = table::str_column(&table, "search").unwrap();
    let e_tr = table::f64_column(&table, "E_tr").unwrap();
    let count = |s: &str| search.iter().filter(|x| x.as_deref() == Some(s)).count();
    assert_eq!(count("differential evolution"), 40);
    assert_eq!(count("random"), 40);
    assert_eq!(count("verification"), 1);
    assert_eq!(count("robustness ±5%"), 6);
    let verified = (0..table.height())
        .find(|&r| search[r].as_deref() == Some("verification"))
        .unwrap();
    let best_of = |keep: &dyn Fn(&str) -> bool| {
        (0..table.height())
            .filter(|&r| search[r].as_deref().is_some_and(keep))
            .filter_map(|r| e_tr[r])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let best_searched = best_of(&|s| s != "verification" && !s.starts_with("robustness"));
    let best_any = best_of(&|s| s != "verification");
    // The verified design is the best any evaluation found inside the space: at least the
    // searches' best (the baseline's included), at most the best of all (a robustness sample
    // counts only if its eps and kappa stayed in their ranges).
    let verified_e_tr = e_tr[verified].unwrap();
    assert!(verified_e_tr >= best_searched - 1e-5 && verified_e_tr <= best_any + 1e-5);

    let best = p.results().join("trap.best.toml");
    let scene = woodpile_scene::load(&best).unwrap();
    assert_eq!(scene.region_paper, [-1, 4]);
    let again = woodpile_sim::simulation::simulate(&scene.scenario, &mut ()).unwrap();
    assert_eq!(Some(again.fractions.trapped), e_tr[verified]);

    let points = count_files(&points_dir(&p.results()));
    p.counted_with(&["trap"], true);
    assert_eq!(
        count_files(&points_dir(&p.results())),
        points,
        "nothing simulated twice"
    );

    // A missing best design makes the stage stale.
    std::fs::remove_file(&best).unwrap();
    assert!(matches!(p.state("trap"), State::Stale(_)));
}

/// The optimum of [`single_defect_sweep_to`]`(3.0)` varied: squeezed by a precompression, and
/// struck by a body instead of given a velocity.
fn vary_project(vary: &str) -> Project {
    let coarse = single_defect_sweep_to(3.0);
    let optimum =
        "kind = \"optimize\"\ninputs = [\"at_end\"]\nover = [\"eps\"]\ntolerance = 1e-7\n";
    Project::new(&[
        ("sweep", &coarse),
        ("at_end", REDUCE),
        ("optimum", optimum),
        ("varied", vary),
    ])
}

const PRECOMPRESSED: &str = r#"
kind = "vary"
inputs = ["optimum"]
[axes]
F0 = [0.0, 0.5]
[set]
chain = { boundary = "fixed", precompression = "$F0" }
"#;

/// A vary stage simulates an optimum's best scene with `[set]` laid over it: at F0 = 0 it is
/// the best scene itself (the optimum's own E_tr, which the optimiser computed on its own), a
/// precompression changes it, and a striker's table carries S with R + T + E_tr + S = 1.
#[test]
fn vary_simulates_a_best_scene_with_set_laid_over_it() {
    let p = vary_project(PRECOMPRESSED);
    p.counted(&[]);
    let best = table::read(&p.output("optimum")).unwrap();
    let best_e_tr = table::f64_column(&best, "E_tr").unwrap()[1].unwrap();
    let out = table::read(&p.output("varied")).unwrap();
    let design = table::str_column(&out, "design").unwrap();
    assert!(design.iter().all(|d| d.as_deref() == Some("optimum")));
    let (f0, t) = (
        table::f64_column(&out, "F0").unwrap(),
        table::f64_column(&out, "t").unwrap(),
    );
    let e_tr = table::f64_column(&out, "E_tr").unwrap();
    let at_end = |f: f64| {
        (0..out.height())
            .find(|&r| f0[r] == Some(f) && t[r] == Some(12.0))
            .unwrap()
    };
    assert_eq!(
        e_tr[at_end(0.0)],
        Some(best_e_tr),
        "F0 = 0 is the best scene itself"
    );
    assert!(
        (e_tr[at_end(0.5)].unwrap() - best_e_tr).abs() > 1e-3,
        "a precompression changes it"
    );

    let struck = r#"
kind = "vary"
inputs = ["optimum"]
unset = ["impulse", "chain.n"]
[axes]
M = [1.0, 4.0]
[set]
chain = { sites = [-5, 12], boundary = { left = "free", right = "fixed" } }
striker = { mass = "$M", velocity = 1.0 }
"#;
    let p = vary_project(struck);
    p.counted(&[]);
    let out = table::read(&p.output("varied")).unwrap();
    let sum: Vec<f64> = ["R", "T", "E_tr", "S"]
        .iter()
        .map(|c| table::f64_column(&out, c).unwrap())
        .fold(vec![0.0; out.height()], |acc, col| {
            acc.iter().zip(col).map(|(a, x)| a + x.unwrap()).collect()
        });
    assert!(sum.iter().all(|s| (s - 1.0).abs() < 1e-9), "{sum:?}");
}

/// What a vary stage refuses: an input that found no best scene, a placeholder naming no axis
/// (at load), and a key to unset that the best scene does not have (when it runs).
#[test]
fn vary_refuses_what_it_cannot_vary() {
    let e = load_error(&[
        ("sweep", SWEEP),
        ("varied", &PRECOMPRESSED.replace("optimum", "sweep")),
    ]);
    assert!(
        e.contains("varied.toml") && e.contains("optimize or design stages"),
        "{e}"
    );
    let e = load_error(&[
        ("sweep", SWEEP),
        ("varied", &PRECOMPRESSED.replace("\"$F0\"", "\"$F1\"")),
    ]);
    assert!(
        e.contains("set.chain.precompression") && e.contains("`$F1` names no axis"),
        "{e}"
    );
    let p = vary_project(&PRECOMPRESSED.replace("[axes]", "unset = [\"run.sample_evry\"]\n[axes]"));
    let e = p.run(&[]).unwrap_err().to_string();
    assert!(
        e.contains("`run.sample_evry` names no key of `optimum`'s best scene"),
        "{e}"
    );
}

/// A design with three resonators on three listed sites evaluates only three-resonator
/// designs, and its best file holds one (it evaluated one- and two-resonator designs, and
/// wrote a two-resonator best).
#[test]
fn a_design_evaluates_only_designs_of_its_space() {
    let file = design(30, 6, 1e-6, 1e-8, "samples = 4, spreads = [0.05]").replace(
        "resonators = [1, 2]\nsites = [0, 3]",
        "resonators = [3, 3]\nsites = [0, 2, 4]",
    );
    let p = Project::new(&[("trap", &file)]);
    p.run(&[]).unwrap();
    let out = table::read(&p.output("trap")).unwrap();
    let counts = table::f64_column(&out, "resonators").unwrap();
    assert!(counts.iter().all(|c| *c == Some(3.0)), "{counts:?}");
    let best = std::fs::read_to_string(p.results().join("trap.best.toml")).unwrap();
    assert_eq!(best.matches("[[defect]]").count(), 3, "{best}");
}

/// A design's site range is bounded before anything lists it (`[0, 4000000000]` and the
/// extremes of i64 allocated without end, even for `woodpile status`).
#[test]
fn a_design_site_range_is_bounded() {
    for range in [
        "[0, 4000000000]",
        "[-9223372036854775808, 9223372036854775807]",
    ] {
        let file = design(30, 6, 1e-6, 1e-8, "samples = 4, spreads = [0.05]")
            .replace("sites = [0, 3]", &format!("sites = {range}"));
        let e = load_error(&[("trap", &file)]);
        assert!(
            e.contains("space.sites") && e.contains("at most 10000 sites"),
            "{e}"
        );
    }
}

/// A sweep may vary any damping key: its table has `D` on every row (0 where the axis sets the
/// damping to zero, whose point is the undamped scene itself), R + T + E_tr + D = 1 on every
/// row, and a reduce carries D. A vary's `[set_each]` damps every resonator of a best scene.
#[test]
fn damping_keys_sweep_reduce_and_vary() {
    let damped = SWEEP
        .replace("L = [0, 1]", "L = [0]\ngamma = [0.0, 0.05]")
        .replace(
            "method = \"rk4\", dt = 0.02",
            "method = \"rk4-contact\", dt = 0.01",
        )
        .replace(
            "[[scene.defect]]",
            "damping = { contact = \"$gamma\" }\n[[scene.defect]]",
        );
    let p = Project::new(&[("sweep", &damped), ("at_end", REDUCE)]);
    p.counted(&[]);
    let out = table::read(&p.output("sweep")).unwrap();
    let column = |name: &str| table::f64_column(&out, name).unwrap();
    let (gamma, d) = (column("gamma"), column("D"));
    let shares: Vec<Vec<Option<f64>>> = ["R", "T", "E_tr", "D"].map(column).to_vec();
    for row in 0..out.height() {
        let sum: f64 = shares.iter().map(|c| c[row].unwrap()).sum();
        assert!((sum - 1.0).abs() < 1e-6, "row {row}: {sum}");
        if gamma[row] == Some(0.0) {
            assert_eq!(d[row], Some(0.0));
        }
    }
    assert!((0..out.height()).any(|r| d[r].unwrap() > 0.01));
    let reduced = table::read(&p.output("at_end")).unwrap();
    let lost = table::f64_column(&reduced, "D").unwrap();
    assert_eq!(lost.len(), 6);
    assert!(lost.iter().any(|x| x.unwrap() > 0.01));

    let quality = r#"
kind = "vary"
inputs = ["optimum"]
[axes]
Q = [1e6, 2.0]
[set]
run = { method = "rk4-contact", dt = 0.01 }
[set_each]
defect = { quality_factor = "$Q" }
"#;
    let p = vary_project(quality);
    p.counted(&[]);
    let out = table::read(&p.output("varied")).unwrap();
    let (q, t) = (
        table::f64_column(&out, "Q").unwrap(),
        table::f64_column(&out, "t").unwrap(),
    );
    let d = table::f64_column(&out, "D").unwrap();
    let at_end = |value: f64| {
        (0..out.height())
            .find(|&r| q[r] == Some(value) && t[r] == Some(12.0))
            .unwrap()
    };
    assert!(d[at_end(1e6)].unwrap() < 1e-3 && d[at_end(2.0)].unwrap() > 0.01);
    let e = vary_project(&quality.replace("defect = {", "segment = {"))
        .run(&[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("set_each: `segment` is not an array of tables"),
        "{e}"
    );
}

/// A design's `each_resonator` lays defect keys on every resonator it places: a design
/// searched under damped resonators writes them into its best scene. The keys the design
/// itself sets are refused.
#[test]
fn a_design_places_damped_resonators() {
    let damped = design(20, 0, 1e-6, 1e-7, "samples = 2, spreads = [0.01]").replacen(
        "kind = \"design\"",
        "kind = \"design\"\neach_resonator = { damping = 0.05 }",
        1,
    );
    let p = Project::new(&[("trap", &damped)]);
    p.counted(&[]);
    let best: toml::Table =
        toml::from_str(&std::fs::read_to_string(p.results().join("trap.best.toml")).unwrap())
            .unwrap();
    let defects = best["defect"].as_array().unwrap();
    assert!(!defects.is_empty());
    assert!(defects
        .iter()
        .all(|d| d["damping"].as_float() == Some(0.05)));
    let e = load_error(&[("trap", &damped.replace("damping = 0.05", "eps = 2.0"))]);
    assert!(e.contains("each_resonator.eps"), "{e}");
}

/// A spacetime stage maps an optimize stage's best scene as it maps a design stage's, and
/// says what to write when it is not wired to it.
#[test]
fn a_spacetime_stage_maps_an_optimize_stages_best_scene() {
    let coarse = single_defect_sweep_to(3.0);
    let optimum =
        "kind = \"optimize\"\ninputs = [\"at_end\"]\nover = [\"eps\"]\ntolerance = 1e-6\n";
    let map = "kind = \"spacetime\"\ndesign = \"optimum\"\ninputs = [\"optimum\"]\n[field]\nsites = [-3, 3]\n";
    let stages = [
        ("sweep", coarse.as_str()),
        ("at_end", REDUCE),
        ("optimum", optimum),
        ("map", map),
    ];
    let p = Project::new(&stages);
    p.counted(&[]);
    let out = table::read(&p.output("map")).unwrap();
    assert!(out.height() > 0);
    let unwired = map.replace("inputs = [\"optimum\"]\n", "");
    let e = load_error(&[stages[0], stages[1], stages[2], ("map", &unwired)]);
    assert!(e.contains("inputs = [\"optimum\"]"), "{e}");
    let wrong = map.replace("\"optimum\"", "\"at_end\"");
    let e = load_error(&[stages[0], stages[1], stages[2], ("map", &wrong)]);
    assert!(e.contains("names a reduce stage"), "{e}");
}
