//! The pipeline end to end on tiny chains (n = 12, t = 12): what runs, what is reused, what is
//! reported, and that results do not depend on the thread count.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use woodpile_stages::KINDS;

use woodpile_pipeline::diff::{diff, DiffOptions, Tolerance};
use woodpile_pipeline::events::Events;
use woodpile_pipeline::layout::output_path;
use woodpile_pipeline::layout::points_dir;
use woodpile_pipeline::points::PointStore;
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::status::{state, State};
use woodpile_pipeline::{table, Pipeline, PipelineError};

/// Counts what a run did.
#[derive(Default)]
struct Counter {
    points: AtomicUsize,
    started: Mutex<Vec<String>>,
    warnings: Mutex<Vec<String>>,
}

impl Events for Counter {
    fn stage_started(&self, stage: &str, _: &str) {
        self.started.lock().unwrap().push(stage.to_string());
    }
    fn point_done(&self) {
        self.points.fetch_add(1, Ordering::SeqCst);
    }
    fn warn(&self, message: &str) {
        self.warnings.lock().unwrap().push(message.to_string());
    }
}

const SWEEP: &str = r#"
kind = "sweep"
[axes]
L = [0, 1]
eps = { from = 0.5, to = 1.5, step = 0.5 }
[scene]
chain = { n = 12 }
impulse = { site = -6 }
run = { t_end = 12.0, method = "rk4", dt = 0.02, sample_every = 2.0 }
[[scene.defect]]
site = 0
through = "$L"
eps = "$eps"
"#;

const REDUCE: &str = r#"
kind = "reduce"
inputs = ["sweep"]
at = 12.0
"#;

const BEST: &str = r#"
kind = "reduce"
inputs = ["sweep"]
[maximize]
over = ["eps"]
"#;

struct Project {
    _dir: tempfile::TempDir,
    pipeline: PathBuf,
    results: PathBuf,
}

impl Project {
    fn new(stages: &[(&str, &str)]) -> Project {
        let dir = tempfile::tempdir().unwrap();
        let pipeline = dir.path().join("pipeline");
        std::fs::create_dir_all(&pipeline).unwrap();
        for (name, text) in stages {
            std::fs::write(pipeline.join(format!("{name}.toml")), text).unwrap();
        }
        let results = dir.path().join("results");
        Project {
            _dir: dir,
            pipeline,
            results,
        }
    }

    fn write(&self, name: &str, text: &str) {
        std::fs::write(self.pipeline.join(format!("{name}.toml")), text).unwrap();
    }

    fn load(&self) -> Pipeline {
        Pipeline::load(&self.pipeline, KINDS).unwrap()
    }

    fn run(&self, targets: &[&str]) -> Counter {
        self.run_with(targets, false)
    }

    fn run_with(&self, targets: &[&str], force: bool) -> Counter {
        let events = Counter::default();
        let options = RunOptions {
            targets: targets.iter().map(|s| s.to_string()).collect(),
            force,
            dry_run: false,
            results: self.results.clone(),
            figures: self.results.join("figures"),
        };
        run(&self.load(), &options, &events).unwrap();
        events
    }

    fn state(&self, name: &str) -> State {
        let p = self.load();
        state(
            &p,
            &self.results,
            &self.results.join("figures"),
            p.stage(name).unwrap(),
        )
    }

    fn output(&self, name: &str) -> PathBuf {
        output_path(&self.results, name)
    }
}

fn load_error(stages: &[(&str, &str)]) -> String {
    let project = Project::new(stages);
    Pipeline::load(&project.pipeline, KINDS)
        .unwrap_err()
        .to_string()
}

#[test]
fn definition_errors_name_the_file_and_key() {
    let with = |extra: &str| format!("{SWEEP}\n{extra}");
    let e = load_error(&[(
        "sweep",
        &SWEEP.replace("kind = \"sweep\"", "kind = \"sweep\"\ncolour = 1"),
    )]);
    assert!(
        e.contains("sweep.toml") && e.contains("`colour`") && e.contains("unknown key"),
        "{e}"
    );
    let e = load_error(&[
        ("sweep", SWEEP),
        ("r", &REDUCE.replace("\"sweep\"", "\"swep\"")),
    ]);
    assert!(
        e.contains("r.toml") && e.contains("inputs[0]") && e.contains("swep"),
        "{e}"
    );
    let e = load_error(&[
        ("a", "kind = \"reduce\"\ninputs = [\"b\"]"),
        ("b", "kind = \"reduce\"\ninputs = [\"a\"]"),
    ]);
    assert!(
        e.contains("inputs") && (e.contains("a -> b -> a") || e.contains("b -> a -> b")),
        "{e}"
    );
    let e = load_error(&[
        ("sweep", SWEEP),
        ("r", REDUCE),
        ("rr", &REDUCE.replace("\"sweep\"", "\"r\"")),
    ]);
    assert!(
        e.contains("rr.toml") && e.contains("reduce reads a sweep"),
        "{e}"
    );
    let e = load_error(&[("sweep", &SWEEP.replace("\"$eps\"", "\"$epsilon\""))]);
    assert!(
        e.contains("scene.defect[0].eps") && e.contains("$epsilon"),
        "{e}"
    );
    let e = load_error(&[(
        "sweep",
        &SWEEP.replace("impulse = { site = -6 }", "impulse = { site = -60 }"),
    )]);
    assert!(
        e.contains("sweep.toml") && e.contains("scene.impulse.site"),
        "{e}"
    );
    let e = load_error(&[("sweep", &with("[scene.chain2]\nn = 3"))]);
    assert!(e.contains("sweep.toml") && e.contains("chain2"), "{e}");
    let e = load_error(&[
        ("sweep", SWEEP),
        ("b", &BEST.replace("[\"eps\"]", "[\"kappa\"]")),
    ]);
    assert!(
        e.contains("b.toml") && e.contains("maximize.over") && e.contains("kappa"),
        "{e}"
    );
    let e = load_error(&[(
        "sweep",
        &SWEEP.replace("kind = \"sweep\"", "kind = \"plot\""),
    )]);
    assert!(e.contains("key `kind`") && e.contains("plot"), "{e}");
}

#[test]
fn a_second_run_does_nothing_and_an_edit_reruns_exactly_its_dependents() {
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE), ("best", BEST)]);
    let first = p.run(&[]);
    assert_eq!(first.points.load(Ordering::SeqCst), 6);
    assert_eq!(first.started.lock().unwrap().len(), 3);

    let second = p.run(&[]);
    assert_eq!(second.points.load(Ordering::SeqCst), 0);
    assert!(second.started.lock().unwrap().is_empty());

    // A read-out time is a reduction parameter: one stage re-runs, nothing is simulated.
    p.write("at_end", &REDUCE.replace("at = 12.0", "at = 10.0"));
    match p.state("at_end") {
        State::Stale(why) => assert_eq!(why, vec!["parameter at: 12.0 -> 10.0".to_string()]),
        other => panic!("{other:?}"),
    }
    assert_eq!(p.state("best"), State::Fresh);
    let third = p.run(&[]);
    assert_eq!(*third.started.lock().unwrap(), vec!["at_end".to_string()]);
    assert_eq!(third.points.load(Ordering::SeqCst), 0);

    // A sweep parameter re-runs the sweep and everything downstream of it.
    p.write("sweep", &SWEEP.replace("dt = 0.02", "dt = 0.01"));
    match p.state("best") {
        State::Stale(why) => assert_eq!(why, vec!["upstream `sweep` changed".to_string()]),
        other => panic!("{other:?}"),
    }
    let fourth = p.run(&[]);
    assert_eq!(fourth.started.lock().unwrap().len(), 3);
    assert_eq!(fourth.points.load(Ordering::SeqCst), 6);
}

#[test]
fn overlapping_sweeps_share_points() {
    let wider = SWEEP.replace("L = [0, 1]", "L = [0, 1, 2]");
    let p = Project::new(&[("sweep", SWEEP), ("wider", &wider)]);
    let first = p.run(&["sweep"]);
    assert_eq!(first.points.load(Ordering::SeqCst), 6);
    let second = p.run(&["wider"]);
    assert_eq!(second.points.load(Ordering::SeqCst), 3, "only L = 2 is new");
    // --force re-runs the stage but reuses the content-addressed points.
    let forced = p.run_with(&["wider"], true);
    assert_eq!(*forced.started.lock().unwrap(), vec!["wider".to_string()]);
    assert_eq!(forced.points.load(Ordering::SeqCst), 0);
}

#[test]
fn an_interrupted_sweep_resumes_without_repeating_finished_points() {
    let p = Project::new(&[("sweep", SWEEP)]);
    p.run(&[]);
    let reference = std::fs::read(p.output("sweep")).unwrap();
    // What a kill -9 leaves: some points finished, no stage output, a temporary of a dead
    // writer (pid 0), and (worse than a kill can do) one damaged point file.
    std::fs::remove_file(p.output("sweep")).unwrap();
    let store = PointStore::new(points_dir(&p.results));
    let pipeline = p.load();
    let sweep = pipeline
        .stage("sweep")
        .unwrap()
        .get::<woodpile_stages::sweep::Sweep>()
        .unwrap();
    let points = sweep.points().unwrap();
    std::fs::remove_file(store.path(&points[1].0)).unwrap();
    std::fs::remove_file(store.path(&points[4].0)).unwrap();
    std::fs::write(store.path(&points[2].0), b"WPPT garbage").unwrap();
    let temp = store
        .path(&points[0].0)
        .with_file_name(".x.wppt~elsewhere~0~Ab3dEf6hIj9l.tmp");
    std::fs::write(&temp, b"half").unwrap();
    // Written by a machine that is gone: untouched for two days.
    std::fs::File::options()
        .write(true)
        .open(&temp)
        .unwrap()
        .set_modified(std::time::SystemTime::now() - std::time::Duration::from_secs(2 * 86400))
        .unwrap();

    let resumed = p.run(&[]);
    assert_eq!(resumed.points.load(Ordering::SeqCst), 3);
    assert!(!temp.exists());
    assert_eq!(std::fs::read(p.output("sweep")).unwrap(), reference);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let outputs: Vec<Vec<u8>> = [1, 2, 3]
        .into_iter()
        .map(|threads| {
            let p = Project::new(&[("sweep", SWEEP), ("best", BEST)]);
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| p.run(&[]));
            [
                std::fs::read(p.output("sweep")).unwrap(),
                std::fs::read(p.output("best")).unwrap(),
            ]
            .concat()
        })
        .collect();
    assert_eq!(outputs[0], outputs[1]);
    assert_eq!(outputs[0], outputs[2]);
}

#[test]
fn outputs_explain_themselves_and_reductions_read_the_series() {
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE), ("best", BEST)]);
    p.run(&[]);
    let manifest = table::read_manifest(&p.output("at_end")).unwrap().unwrap();
    assert_eq!(manifest.kind, "reduce");
    assert_eq!(manifest.key, p.load().key("at_end").as_str());
    assert_eq!(manifest.inputs["sweep"], p.load().key("sweep").as_str());
    let sweep = table::read_manifest(&p.output("sweep")).unwrap().unwrap();
    assert_eq!(sweep.summary["method"], "rk4");
    assert_eq!(sweep.summary["points"], 6);

    let series = table::read(&p.output("sweep")).unwrap();
    assert_eq!(series.height(), 6 * 7, "samples at t = 0, 2, ..., 12");
    let at_end = table::read(&p.output("at_end")).unwrap();
    let best = table::read(&p.output("best")).unwrap();
    let e_tr = table::f64_column(&at_end, "E_tr").unwrap();
    let best_e = table::f64_column(&best, "E_tr").unwrap();
    // best = max over the three eps of each L, in grid order.
    for (l, best) in best_e.iter().enumerate() {
        let max = e_tr[3 * l..3 * l + 3]
            .iter()
            .map(|x| x.unwrap())
            .fold(f64::MIN, f64::max);
        assert_eq!(best.unwrap(), max);
    }
    // Fractions partition the energy at every row.
    let (r, t) = (
        table::f64_column(&at_end, "R").unwrap(),
        table::f64_column(&at_end, "T").unwrap(),
    );
    for i in 0..6 {
        assert!((r[i].unwrap() + t[i].unwrap() + e_tr[i].unwrap() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn a_read_out_time_between_samples_is_a_clear_stage_error() {
    let p = Project::new(&[
        ("sweep", SWEEP),
        ("at_end", &REDUCE.replace("at = 12.0", "at = 11.0")),
    ]);
    let err = run(
        &p.load(),
        &RunOptions {
            results: p.results.clone(),
            ..Default::default()
        },
        &Counter::default(),
    )
    .unwrap_err();
    assert!(matches!(err, PipelineError::Failed { ref failures } if failures.len() == 1));
    assert!(err.to_string().contains("at = 11"), "{err}");
    assert!(!p.output("at_end").exists());
}

#[test]
fn failed_points_are_reported_never_written_as_numbers() {
    // RK4 at dt = 3 on a stiff resonator (eps = 1e-3) blows up.
    let stiff = SWEEP
        .replace(
            "eps = { from = 0.5, to = 1.5, step = 0.5 }",
            "eps = [0.001, 1.0]",
        )
        .replace("dt = 0.02", "dt = 1.0");
    let p = Project::new(&[("sweep", &stiff), ("best", BEST)]);
    let events = p.run(&[]);
    assert!(events
        .warnings
        .lock()
        .unwrap()
        .iter()
        .any(|w| w.contains("failed")));
    let frame = table::read(&p.output("sweep")).unwrap();
    let failure = table::str_column(&frame, "failure").unwrap();
    let e_tr = table::f64_column(&frame, "E_tr").unwrap();
    let failed_rows: Vec<usize> = (0..failure.len())
        .filter(|&i| failure[i].is_some())
        .collect();
    assert!(!failed_rows.is_empty());
    assert!(failed_rows.iter().all(|&i| e_tr[i].is_none()));
    // A group whose every point failed reports the failure, not a number.
    let best = table::read(&p.output("best")).unwrap();
    let (e_tr, failed, points, failure) = (
        table::f64_column(&best, "E_tr").unwrap(),
        table::f64_column(&best, "failed").unwrap(),
        table::f64_column(&best, "points").unwrap(),
        table::str_column(&best, "failure").unwrap(),
    );
    for i in 0..e_tr.len() {
        if failed[i] == points[i] {
            assert!(e_tr[i].is_none() && failure[i].is_some());
        } else {
            assert!(e_tr[i].is_some_and(f64::is_finite) && failure[i].is_none());
        }
    }
}

#[test]
fn diff_agrees_on_identical_trees_and_catches_a_perturbed_value() {
    let a = Project::new(&[("sweep", SWEEP), ("best", BEST)]);
    let b = Project::new(&[("sweep", SWEEP), ("best", BEST)]);
    a.run(&[]);
    b.run(&[]);
    let exact = DiffOptions::default();
    let report = diff(&a.results, &b.results, &exact).unwrap();
    assert!(report.agrees(), "{report:?}");
    assert_eq!(report.files, 2);

    perturb(&b.output("best"), "E_tr", 1e-6);
    let report = diff(&a.results, &b.results, &exact).unwrap();
    assert!(!report.agrees());
    assert_eq!(report.worst[0].column, "E_tr");
    let loose = DiffOptions {
        default: Tolerance {
            abs: 1e-5,
            rel: 0.0,
        },
        ..Default::default()
    };
    assert!(diff(&a.results, &b.results, &loose).unwrap().agrees());

    std::fs::remove_file(b.output("sweep")).unwrap();
    let report = diff(&a.results, &b.results, &loose).unwrap();
    assert!(report.problems.iter().any(|p| p.contains("sweep.parquet")));
}

#[test]
fn sharded_runs_merge_into_the_single_machine_result() {
    use woodpile_pipeline::shard::{merge, run_shard, Shard};
    let single = Project::new(&[("sweep", SWEEP)]);
    single.run(&[]);
    let sharded = Project::new(&[("sweep", SWEEP)]);
    let pipeline = sharded.load();
    let events = Counter::default();
    for i in [0, 2] {
        run_shard(
            &pipeline,
            "sweep",
            Shard::new(i, 4).unwrap(),
            &sharded.results,
            &events,
        )
        .unwrap();
    }
    // Incomplete: the error names the missing shards, and nothing is written.
    let err = merge(&pipeline, "sweep", &sharded.results, &Counter::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("2 of 4 shard(s) missing (1, 3;"), "{err}");
    assert!(!sharded.output("sweep").exists());
    // A part made with another N is a mismatch, not a silent mix.
    run_shard(
        &pipeline,
        "sweep",
        Shard::new(0, 3).unwrap(),
        &sharded.results,
        &events,
    )
    .unwrap();
    let err = merge(&pipeline, "sweep", &sharded.results, &Counter::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("different shard counts"), "{err}");
    std::fs::remove_dir_all(sharded.results.join("parts")).unwrap();

    for i in 0..4 {
        run_shard(
            &pipeline,
            "sweep",
            Shard::new(i, 4).unwrap(),
            &sharded.results,
            &events,
        )
        .unwrap();
    }
    // A shard re-run finds its part done and simulates nothing.
    let again = Counter::default();
    let rerun = run_shard(
        &pipeline,
        "sweep",
        Shard::new(1, 4).unwrap(),
        &sharded.results,
        &again,
    )
    .unwrap();
    assert!(rerun.already_done);
    assert_eq!(again.points.load(Ordering::SeqCst), 0);
    assert_eq!(
        merge(&pipeline, "sweep", &sharded.results, &Counter::default()).unwrap(),
        4
    );
    let report = diff(&single.results, &sharded.results, &DiffOptions::default()).unwrap();
    assert!(report.agrees(), "{report:?}");
    let (a, b) = (
        table::read_manifest(&single.output("sweep"))
            .unwrap()
            .unwrap(),
        table::read_manifest(&sharded.output("sweep"))
            .unwrap()
            .unwrap(),
    );
    assert_eq!(a, b, "the merged manifest is the single run's");
    assert_eq!(
        state(
            &pipeline,
            &sharded.results,
            &sharded.results,
            pipeline.stage("sweep").unwrap()
        ),
        State::Fresh
    );
}

#[test]
fn render_stages_draw_figures_and_keep_the_plotted_numbers() {
    let figure = r#"
kind = "render"
inputs = ["at_end"]
title = "test figure"
[lines]
x = "eps"
y = ["R", "E_tr"]
panels = "L"
x_label = "eps"
y_label = "fraction"
"#;
    let heat = r#"
kind = "render"
inputs = ["at_end"]
title = "test map"
[heatmap]
x = "eps"
y = "L"
z = "E_tr"
x_label = "eps"
y_label = "L"
z_label = "E_tr"
mark_max = true
"#;
    let p = Project::new(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        ("figure", figure),
        ("map", heat),
    ]);
    p.run(&[]);
    let figures = p.results.join("figures");
    for name in ["figure.png", "figure.svg", "map.png", "map.svg"] {
        assert!(figures.join(name).exists(), "{name}");
    }
    // The table holds exactly the plotted numbers: a row per curve point, per panel.
    let plotted = table::read(&p.output("figure")).unwrap();
    let names: Vec<String> = plotted
        .get_column_names()
        .iter()
        .map(|n| n.to_string())
        .collect();
    // Each number under the name of the column it was drawn from.
    assert_eq!(names, ["panel", "series", "eps", "R", "E_tr"]);
    let reduced = table::read(&p.output("at_end")).unwrap();
    assert_eq!(
        plotted.height(),
        2 * reduced.height(),
        "R and E_tr of every row"
    );
    let (x, y) = (
        table::f64_column(&plotted, "eps").unwrap(),
        table::f64_column(&plotted, "E_tr").unwrap(),
    );
    let series = table::str_column(&plotted, "series").unwrap();
    let (eps, e_tr) = (
        table::f64_column(&reduced, "eps").unwrap(),
        table::f64_column(&reduced, "E_tr").unwrap(),
    );
    let drawn: Vec<(Option<f64>, Option<f64>)> = (0..plotted.height())
        .filter(|&r| series[r].as_deref() == Some("E_tr"))
        .map(|r| (x[r], y[r]))
        .collect();
    for pair in eps.iter().zip(&e_tr) {
        assert!(drawn.contains(&(*pair.0, *pair.1)), "{pair:?} not drawn");
    }
    // A deleted figure makes its stage stale, and only that stage re-runs.
    std::fs::remove_file(figures.join("map.svg")).unwrap();
    assert!(matches!(p.state("map"), State::Stale(why) if why[0].contains("map.svg")));
    assert_eq!(*p.run(&[]).started.lock().unwrap(), vec!["map".to_string()]);
    let e = load_error(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        ("f", &figure.replace("[lines]", "[bars]")),
    ]);
    assert!(e.contains("f.toml") && e.contains("bars"), "{e}");
}

#[test]
fn fit_stages_fit_the_forms_and_report_the_papers_coefficients_on_our_data() {
    let fit = r#"
kind = "fit"
inputs = ["at_end"]
x = "eps"
where = { L = 1 }
[[model]]
name = "R"
y = "R"
form = "tanh"
start = [0.5, 0.5, 0.0]
paper = [0.5491, 0.0830, 0.0760]
"#;
    let wide = SWEEP.replace(
        "eps = { from = 0.5, to = 1.5, step = 0.5 }",
        "eps = { from = 0.5, to = 4.0, step = 0.5 }",
    );
    let p = Project::new(&[("sweep", &wide), ("at_end", REDUCE), ("fit", fit)]);
    p.run(&[]);
    let out = table::read(&p.output("fit")).unwrap();
    let col = |c: &str| table::f64_column(&out, c).unwrap()[0].unwrap();
    assert_eq!(col("n"), 8.0, "only the L = 1 rows");
    // The fitted curve reproduces the data it was fitted to: recompute its residual here.
    let data = table::read(&p.output("at_end")).unwrap();
    let (l, eps, r) = (
        table::f64_column(&data, "L").unwrap(),
        table::f64_column(&data, "eps").unwrap(),
        table::f64_column(&data, "R").unwrap(),
    );
    let (a, b, c) = (col("A"), col("B"), col("C"));
    let (mut ssr, mut norm) = (0.0, 0.0);
    for i in (0..l.len()).filter(|&i| l[i] == Some(1.0)) {
        ssr += (a * (b * eps[i].unwrap()).tanh() + c - r[i].unwrap()).powi(2);
        norm += r[i].unwrap().powi(2);
    }
    assert!((col("relative_error") - (ssr / norm).sqrt()).abs() < 1e-12);
    assert!(
        col("relative_error") <= col("paper_relative_error"),
        "LM beats any other coefficients"
    );
    assert!(col("se_A") > 0.0);
    let e = load_error(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        ("fit", &fit.replace("\"tanh\"", "\"cubic\"")),
    ]);
    assert!(e.contains("model[0].form") && e.contains("cubic"), "{e}");
}

#[test]
fn the_product_approximation_evaluates_the_fitted_forms() {
    let single = SWEEP.replace("L = [0, 1]", "L = [0]").replace(
        "eps = { from = 0.5, to = 1.5, step = 0.5 }",
        "eps = { from = 0.5, to = 4.0, step = 0.5 }",
    );
    let fits = r#"
kind = "fit"
inputs = ["single_at_end"]
x = "eps"
[[model]]
name = "T1"
y = "T"
form = "power"
start = [0.5, -0.3, 0.2]
[[model]]
name = "R"
y = "R"
form = "tanh"
start = [0.5, 0.5, 0.0]
"#;
    let pair = r#"
kind = "sweep"
[axes]
eps1 = [1.0, 2.0]
eps2 = [1.0, 2.0]
[scene]
chain = { n = 12 }
impulse = { site = -6 }
run = { t_end = 12.0, method = "rk4", dt = 0.02, sample_every = 2.0 }
[[scene.defect]]
site = 0
eps = "$eps1"
[[scene.defect]]
site = 3
eps = "$eps2"
"#;
    let approx = r#"
kind = "approximate"
inputs = ["fits", "pair_at_end"]
transmission = "T1"
reflection = "R"
axes = ["eps1", "eps2"]
numerics = "E_tr"
"#;
    let p = Project::new(&[
        ("single", &single),
        ("single_at_end", &REDUCE.replace("\"sweep\"", "\"single\"")),
        ("fits", fits),
        ("pair", pair),
        ("pair_at_end", &REDUCE.replace("\"sweep\"", "\"pair\"")),
        ("approx", approx),
    ]);
    p.run(&[]);
    let f = table::read(&p.output("fits")).unwrap();
    let coef = |c: &str, row: usize| table::f64_column(&f, c).unwrap()[row].unwrap();
    let t1 = |x: f64| coef("A", 0) * x.powf(coef("B", 0)) + coef("C", 0);
    let r = |x: f64| coef("A", 1) * (coef("B", 1) * x).tanh() + coef("C", 1);
    let out = table::read(&p.output("approx")).unwrap();
    let col = |c: &str| table::f64_column(&out, c).unwrap();
    let (e1, e2, values, diag) = (col("eps1"), col("eps2"), col("approx"), col("on_diagonal"));
    assert_eq!(values.len(), 4);
    for i in 0..4 {
        let (a, b) = (e1[i].unwrap(), e2[i].unwrap());
        assert!((values[i].unwrap() - t1(a) * r(b) * r(a) * r(b)).abs() < 1e-14);
        assert_eq!(diag[i], Some(if a == b { 1.0 } else { 0.0 }));
    }
    assert!(
        col("approx_paper").iter().all(Option::is_none),
        "no paper coefficients given"
    );
    let manifest = table::read_manifest(&p.output("approx")).unwrap().unwrap();
    assert!(manifest.summary["relative_error"].as_f64().unwrap() > 0.0);
    let swapped = approx.replace("[\"fits\", \"pair_at_end\"]", "[\"pair_at_end\", \"fits\"]");
    let e = load_error(&[
        ("single", &single),
        ("single_at_end", &REDUCE.replace("\"sweep\"", "\"single\"")),
        ("fits", fits),
        ("pair", pair),
        ("pair_at_end", &REDUCE.replace("\"sweep\"", "\"pair\"")),
        ("approx", &swapped),
    ]);
    assert!(
        e.contains("approx.toml") && e.contains("expected [a fit stage, a reduce stage]"),
        "{e}"
    );
}

#[test]
fn spacetime_stages_record_velocities_on_the_requested_sites() {
    let field = r#"
kind = "spacetime"
[axes]
L = [0, 1]
[scene]
chain = { n = 12 }
impulse = { site = -6, velocity = 1.0 }
run = { t_end = 12.0, method = "rk4", dt = 0.02, sample_every = 2.0 }
[[scene.defect]]
site = 0
through = "$L"
eps = 2.0
[field]
sites = [-8, 8]
"#;
    let p = Project::new(&[("field", field)]);
    p.run(&[]);
    let out = table::read(&p.output("field")).unwrap();
    assert_eq!(out.height(), 2 * 7 * 17, "points x samples x sites");
    let (t, site, v) = (
        table::f64_column(&out, "t").unwrap(),
        table::f64_column(&out, "site").unwrap(),
        table::f64_column(&out, "velocity").unwrap(),
    );
    for i in 0..out.height() {
        let s = site[i].unwrap();
        assert!((-8.0..=8.0).contains(&s));
        if t[i] == Some(0.0) {
            assert_eq!(v[i].unwrap(), if s == -6.0 { 1.0 } else { 0.0 });
        }
    }
    let e = load_error(&[(
        "field",
        &field.replace("sites = [-8, 8]", "sites = [-80, 8]"),
    )]);
    assert!(e.contains("field.sites"), "{e}");
}

#[test]
fn optimize_refines_a_grid_maximum_between_grid_points() {
    let coarse = SWEEP.replace("L = [0, 1]", "L = [0]").replace(
        "eps = { from = 0.5, to = 1.5, step = 0.5 }",
        "eps = { from = 0.5, to = 3.0, step = 0.5 }",
    );
    let optimum = r#"
kind = "optimize"
inputs = ["at_end"]
over = ["eps"]
tolerance = 1e-7
"#;
    let p = Project::new(&[("sweep", &coarse), ("at_end", REDUCE), ("optimum", optimum)]);
    p.run(&[]);
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

/// Adds `delta` to the first value of `column` in the table at `path`, keeping its manifest.
fn perturb(path: &Path, column: &str, delta: f64) {
    let manifest = table::read_manifest(path).unwrap().unwrap();
    let mut frame = table::read(path).unwrap();
    let mut values = table::f64_column(&frame, column).unwrap();
    values[0] = values[0].map(|v| v + delta);
    frame
        .with_column(polars::prelude::Column::new(column.into(), values))
        .unwrap();
    table::write(path, frame, &manifest).unwrap();
}

const REPORT: &str = r#"
kind = "report"
inputs = ["sweep", "at_end"]
markdown = "REPORT.md"
title = "Tiny report"

[[quote]]
figure = "X1"
quantity = "E_tr at L = 0, eps = 1, end"
paper = PAPER
agree = 1e-12
as_run = "t = 12"
ours = { stage = "at_end", column = "E_tr", where = { L = 0, eps = 1.0 } }
[[quote.convention]]
name = "read-out time"
source = { stage = "sweep", column = "E_tr", where = { L = 0, eps = 1.0 }, scan = "t" }
[[quote.convention]]
name = "largest over the grid"
source = { stage = "at_end", column = "E_tr", max = "E_tr", locate = ["L", "eps"] }
"#;

/// The report reads numbers where its sources say, finds by scanning the read-out time where a
/// quoted number is met, and writes its Markdown beside `results/`.
#[test]
fn a_report_reads_and_scans_the_quoted_numbers() {
    // The "paper's" number: E_tr at t = 8, which the end-time read-out misses.
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE)]);
    p.run(&[]);
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
    p.run(&["report"]);
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

    let markdown = p.results.parent().unwrap().join("REPORT.md");
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
    let e = load_error(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        (
            "report",
            &REPORT
                .replace("PAPER", "0.1")
                .replace("inputs = [\"sweep\", \"at_end\"]", "inputs = [\"sweep\"]"),
        ),
    ]);
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
    let events = p.run(&[]);
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

const WORK_PRECISION: &str = r#"
kind = "workprecision"
repeats = 1
reference_tolerance = 1e-12
[[scene]]
name = "tiny"
chain = { n = 12 }
impulse = { site = -6 }
run = { t_end = 12.0 }
defect = [{ site = 0, eps = 2.0 }]
[[method]]
name = "rk4"
dt = [0.2, 0.1, 0.05]
[[method]]
name = "dop853"
tolerance = [1e-6]
"#;

const WORK_PRECISION_CHART: &str = r#"
kind = "render"
inputs = ["wp"]
title = "work-precision"
where = { scene = 0 }
[lines]
x = "log10_wall_ms"
y = ["log10_error"]
series = "method_index"
series_label = "method"
x_label = "log10 ms"
y_label = "log10 error"
"#;

/// A work-precision stage measures every setting against its reference: RK4's error falls
/// with its step at about its order on a smooth enough scene, and the chart draws one curve per
/// method.
#[test]
fn work_precision_measures_error_against_the_reference() {
    let p = Project::new(&[("wp", WORK_PRECISION), ("chart", WORK_PRECISION_CHART)]);
    p.run(&[]);
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
    assert!(p.results.join("figures").join("chart.png").exists());
    assert_eq!(p.state("chart"), State::Fresh);
}

/// A scene listed many times in one sweep (an axis value repeated) is simulated once, and two
/// threads writing its point never collide.
#[test]
fn a_point_repeated_in_one_sweep_is_simulated_once() {
    let repeated = format!("[{}]", vec!["1.5"; 40].join(", "));
    let sweep = SWEEP
        .replace("L = [0, 1]\n", "")
        .replace("{ from = 0.5, to = 1.5, step = 0.5 }", &repeated)
        .replace("through = \"$L\"\n", "");
    let p = Project::new(&[("sweep", &sweep)]);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let events = pool.install(|| p.run(&[]));
    assert_eq!(events.points.load(Ordering::SeqCst), 1);
    let frame = table::read(&p.output("sweep")).unwrap();
    let e_tr = table::f64_column(&frame, "E_tr").unwrap();
    let per_point = frame.height() / 40;
    for (i, value) in e_tr.iter().enumerate() {
        assert_eq!(*value, e_tr[i % per_point], "row {i}");
    }
}

/// Replaces `path`'s first `column` value, keeping the manifest (and so its checksum) as it
/// was: a damaged data page that still decodes.
fn corrupt_keeping_manifest(path: &Path, column: &str) {
    use polars::prelude::*;
    let manifest = table::read_manifest(path).unwrap().unwrap();
    let mut frame = table::read(path).unwrap();
    let mut values = table::f64_column(&frame, column).unwrap();
    values[0] = values[0].map(|v| v + 0.25);
    frame
        .with_column(Column::new(column.into(), values))
        .unwrap();
    let metadata =
        KeyValueMetadata::from_static(vec![("woodpile".to_string(), manifest.to_json_text())]);
    let file = std::fs::File::create(path).unwrap();
    ParquetWriter::new(file)
        .with_key_value_metadata(Some(metadata))
        .finish(&mut frame)
        .unwrap();
}

#[test]
fn a_damaged_table_is_never_fresh_and_is_recomputed_before_it_is_read() {
    let p = Project::new(&[("sweep", SWEEP), ("best", BEST)]);
    p.run(&[]);
    let (sweep, best) = (
        std::fs::read(p.output("sweep")).unwrap(),
        std::fs::read(p.output("best")).unwrap(),
    );
    corrupt_keeping_manifest(&p.output("sweep"), "E_tr");
    assert!(
        matches!(p.state("sweep"), State::Damaged(ref why) if why.contains("seal")),
        "{:?}",
        p.state("sweep")
    );
    assert!(table::read(&p.output("sweep"))
        .unwrap_err()
        .to_string()
        .contains("seal"));
    // Forcing the downstream stage recomputes the damaged input first, with a warning.
    let events = p.run_with(&["best"], true);
    assert!(events
        .warnings
        .lock()
        .unwrap()
        .iter()
        .any(|w| w.contains("`sweep`") && w.contains("again")));
    assert_eq!(std::fs::read(p.output("sweep")).unwrap(), sweep);
    assert_eq!(std::fs::read(p.output("best")).unwrap(), best);

    // One flipped bit in any page (data, header or statistics) or in the manifest is never
    // fresh either; every such byte is tried.
    let footer = u32::from_le_bytes(sweep[sweep.len() - 8..sweep.len() - 4].try_into().unwrap());
    let pages = sweep.len() - 8 - footer as usize;
    let manifest_text = table::read_manifest(&p.output("sweep"))
        .unwrap()
        .unwrap()
        .to_json_text();
    let manifest_at = sweep
        .windows(manifest_text.len())
        .position(|w| w == manifest_text.as_bytes())
        .unwrap();
    let offsets = (0..pages).chain(manifest_at..manifest_at + manifest_text.len());
    for offset in offsets {
        let mut bytes = sweep.clone();
        bytes[offset] ^= 0x04;
        std::fs::write(p.output("sweep"), &bytes).unwrap();
        assert!(
            !matches!(p.state("sweep"), State::Fresh),
            "a flip at byte {offset} of {} went unnoticed",
            sweep.len()
        );
    }
}

#[test]
fn a_report_writes_only_markdown_inside_the_tree_and_never_over_a_file_it_did_not_write() {
    let report = REPORT.replace("PAPER", "0.1");
    for (markdown, expected) in [
        ("../../x.md", "inside the project"),
        ("/tmp/x.md", "inside the project"),
        ("results/sweep.parquet", "must end in `.md`"),
        ("figures/f.png", "must end in `.md`"),
    ] {
        let e = load_error(&[
            ("sweep", SWEEP),
            ("at_end", REDUCE),
            (
                "report",
                &report.replace("\"REPORT.md\"", &format!("\"{markdown}\"")),
            ),
        ]);
        assert!(
            e.contains("report.toml") && e.contains("`markdown`") && e.contains(expected),
            "{markdown}: {e}"
        );
    }
    let e = load_error(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        ("report", &report),
        ("report2", &report),
    ]);
    assert!(
        e.contains("report2.toml") && e.contains("written by stage `report`"),
        "{e}"
    );

    // A hand-written file of that name is not overwritten; the report's own file is.
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE), ("report", &report)]);
    let markdown = p.results.parent().unwrap().join("REPORT.md");
    std::fs::write(&markdown, "mine").unwrap();
    let options = RunOptions {
        targets: vec![],
        force: false,
        dry_run: false,
        results: p.results.clone(),
        figures: p.results.join("figures"),
    };
    let e = run(&p.load(), &options, &Counter::default()).unwrap_err();
    assert!(e.to_string().contains("did not write"), "{e}");
    assert_eq!(std::fs::read_to_string(&markdown).unwrap(), "mine");
    std::fs::remove_file(&markdown).unwrap();
    p.run(&[]);
    p.run_with(&["report"], true);
    assert!(std::fs::read_to_string(&markdown)
        .unwrap()
        .starts_with("# Tiny report"));
}

#[test]
fn diff_reports_changed_types_and_missing_manifests_and_refuses_unknown_columns() {
    use polars::prelude::*;
    let a = Project::new(&[("sweep", SWEEP)]);
    let b = Project::new(&[("sweep", SWEEP)]);
    a.run(&[]);
    b.run(&[]);
    // `steps` (integers) rewritten as floats, without a manifest.
    let mut frame = table::read(&b.output("sweep")).unwrap();
    let steps = frame
        .column("steps")
        .unwrap()
        .cast(&DataType::Float64)
        .unwrap();
    frame.with_column(steps).unwrap();
    let file = std::fs::File::create(b.output("sweep")).unwrap();
    ParquetWriter::new(file).finish(&mut frame).unwrap();
    let report = diff(&a.results, &b.results, &DiffOptions::default()).unwrap();
    assert!(!report.agrees());
    assert!(
        report
            .problems
            .iter()
            .any(|p| p.contains("`steps`") && p.contains("f64")),
        "{:?}",
        report.problems
    );
    assert!(
        report
            .problems
            .iter()
            .any(|p| p.contains("no `woodpile` manifest")),
        "{:?}",
        report.problems
    );
    let mut options = DiffOptions::default();
    options.columns.insert("nope".into(), Tolerance::default());
    let e = diff(&a.results, &a.results, &options).unwrap_err();
    assert!(e.to_string().contains("`nope`"), "{e}");
}

#[test]
fn every_run_sweeps_leftover_temporaries_even_when_all_is_fresh() {
    let p = Project::new(&[("sweep", SWEEP)]);
    p.run(&[]);
    // Another machine's temporary, two days old; and one of a process on this machine that
    // has ended (pid 0 is never a user process) cannot be named without the host, so the
    // foreign one stands for both rules here (the atomic module tests the other).
    let figures = p.results.join("figures");
    std::fs::create_dir_all(&figures).unwrap();
    let stale = figures.join(".f.png~elsewhere~12~Ab3dEf6hIj9l.tmp");
    let file = std::fs::File::create(&stale).unwrap();
    let two_days = std::time::Duration::from_secs(2 * 24 * 3600);
    file.set_modified(std::time::SystemTime::now() - two_days)
        .unwrap();
    drop(file);
    let events = p.run(&[]);
    assert!(!stale.exists());
    assert!(
        events.started.lock().unwrap().is_empty(),
        "nothing was stale"
    );
    assert!(events
        .warnings
        .lock()
        .unwrap()
        .iter()
        .any(|w| w.contains("temporary")));
}

#[test]
fn grids_too_large_to_plan_are_refused_at_load_with_their_size() {
    let huge = SWEEP.replace(
        "L = [0, 1]",
        "L = { from = 0, to = 9999, step = 1 }\nx = { from = 0, to = 999, step = 1 }",
    );
    let e = load_error(&[("sweep", &huge)]);
    assert!(
        e.contains("sweep.toml") && e.contains("30000000 points"),
        "{e}"
    );
    let fine = SWEEP.replace("sample_every = 2.0", "sample_every = 0.0001");
    let fine = fine.replace("to = 1.5, step = 0.5", "to = 1000.5, step = 0.5");
    let e = load_error(&[("sweep", &fine)]);
    assert!(e.contains("sweep.toml") && e.contains("GB"), "{e}");
}

/// A composite figure draws panels from several inputs, with marks, a diverging map and a
/// title that quotes an input's parameters; a quote of a stage that is not an input, or an
/// unknown panel input, is refused at load.
#[test]
fn composite_figures_draw_several_inputs_and_quote_their_parameters() {
    let composite = r#"
kind = "render"
inputs = ["sweep", "at_end"]
title = "read out at t = {at_end.params.at}, tolerance {sweep.summary.tolerance}"
columns = 2
same_colour_scale = true

[[panel]]
input = "at_end"
title = "fractions at L = 0"
where = { L = 0 }
mark = [{ x = 1.0, label = "eps = 1" }]
[panel.lines]
x = "eps"
y = ["R", "T", "E_tr"]
x_label = "eps"
y_label = "fraction"

[[panel]]
input = "sweep"
where = { L = 1 }
[panel.heatmap]
x = "t"
y = "eps"
z = "E_tr"
colours = "diverging"
x_label = "t"
y_label = "eps"
z_label = "E_tr"
"#;
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE), ("both", composite)]);
    p.run(&[]);
    let manifest = table::read_manifest(&p.output("both")).unwrap().unwrap();
    assert_eq!(
        manifest.summary["title"],
        "read out at t = 12, tolerance 0.00000001"
            .replace("0.00000001", &woodpile_plot::tick(&1e-8))
            .as_str()
    );
    assert_eq!(manifest.summary["panels"], 2);
    let svg = std::fs::read_to_string(p.results.join("figures/both.svg")).unwrap();
    assert!(svg.contains("read out at t = 12") && svg.contains("eps = 1"));
    // The read-out time is in the title: changing it re-renders with the new value.
    p.write("at_end", &REDUCE.replace("at = 12.0", "at = 10.0"));
    p.run(&[]);
    let manifest = table::read_manifest(&p.output("both")).unwrap().unwrap();
    assert!(manifest.summary["title"]
        .as_str()
        .unwrap()
        .starts_with("read out at t = 10,"));

    let e = load_error(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        (
            "both",
            &composite.replace("{at_end.params.at}", "{other.params.at}"),
        ),
    ]);
    assert!(
        e.contains("both.toml") && e.contains("`title`") && e.contains("other"),
        "{e}"
    );
    let e = load_error(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        (
            "both",
            &composite.replace("input = \"sweep\"", "input = \"nope\""),
        ),
    ]);
    assert!(e.contains("panel[1].input") && e.contains("nope"), "{e}");
    let e = load_error(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        (
            "both",
            &composite.replace("[[panel]]\ninput = \"sweep\"", "[wrong]\ninput = \"sweep\""),
        ),
    ]);
    assert!(e.contains("both.toml"), "{e}");
}

/// A fit that cannot converge is a row with its reason; the stages after it still run, the
/// report shows the failure, and the run ends with an error naming it.
#[test]
fn a_failed_fit_is_a_row_the_run_goes_on_and_ends_naming_it() {
    let fits = r#"
kind = "fit"
inputs = ["at_end"]
x = "eps"
[[model]]
name = "good"
y = "E_tr"
form = "tanh"
start = [0.1, 1.0, 0.0]
[[model]]
name = "hopeless"
y = "E_tr"
form = "power"
start = [1.0, 1.0, 0.0]
x_range = [100.0, 200.0]
"#;
    let report = r#"
kind = "report"
inputs = ["fits"]
markdown = "REPORT.md"
title = "Fits"
[[quote]]
figure = "X"
quantity = "A of the good fit"
paper = 0.1
agree = 1.0
as_run = "tanh"
ours = { stage = "fits", column = "A", where = { model = "good" } }
[[quote.convention]]
name = "the hopeless fit"
source = { stage = "fits", column = "A", where = { model = "hopeless" } }
"#;
    let p = Project::new(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        ("fits", fits),
        ("report", report),
    ]);
    let options = RunOptions {
        results: p.results.clone(),
        figures: p.results.join("figures"),
        ..Default::default()
    };
    let e = run(&p.load(), &options, &Counter::default()).unwrap_err();
    let PipelineError::Failed { failures } = &e else {
        panic!("{e}")
    };
    assert!(
        failures[0].contains("`fits`") && failures[0].contains("hopeless"),
        "{e}"
    );
    let table = table::read(&p.output("fits")).unwrap();
    let failure = table::str_column(&table, "failure").unwrap();
    let a = table::f64_column(&table, "A").unwrap();
    assert_eq!(failure[0], None);
    assert!(a[0].is_some());
    assert!(failure[1].as_deref().unwrap().contains("at least 4 points"));
    assert_eq!(a[1], None);
    let markdown = std::fs::read_to_string(p.results.parent().unwrap().join("REPORT.md")).unwrap();
    assert!(
        markdown.contains("**failed**") && markdown.contains("at least 4 points"),
        "{markdown}"
    );
}

/// Stage files may sit in folders (one per figure); a stage is named by its stem wherever it
/// lies, so the same name twice is an error naming both files.
#[test]
fn stages_in_folders_load_and_a_name_twice_is_an_error() {
    let p = Project::new(&[("at_end", REDUCE)]);
    let folder = p.pipeline.join("f1");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("sweep.toml"), SWEEP).unwrap();
    let pipeline = p.load();
    assert_eq!(pipeline.stages().len(), 2);
    assert!(pipeline
        .stage("sweep")
        .unwrap()
        .file
        .ends_with("f1/sweep.toml"));
    std::fs::write(p.pipeline.join("sweep.toml"), SWEEP).unwrap();
    let e = Pipeline::load(&p.pipeline, KINDS).unwrap_err().to_string();
    assert!(
        e.contains("defined twice") && e.contains("f1/sweep.toml"),
        "{e}"
    );
}

const DESIGN: &str = r#"
kind = "design"
seed = 7
budget = 40
refine = 10
objective = "E_tr"
verify_tolerance = 1e-8
robustness = { samples = 6, spreads = [0.01, 0.05] }
[scene]
chain = { n = 12 }
impulse = { site = -6 }
run = { t_end = 12.0, method = "auto", tolerance = 1e-6 }
fractions = { region = [-1, 4] }
[space]
resonators = [1, 2]
sites = [0, 3]
eps = { min = 0.1, max = 10.0, log = true }
kappa = { min = 0.5, max = 2.0 }
"#;

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
            let p = Project::new(&[("trap", DESIGN)]);
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| p.run(&[]));
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

    let p = Project::new(&[("trap", DESIGN)]);
    p.run(&[]);
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
    let best_searched = (0..table.height())
        .filter(|&r| search[r].as_deref().is_some_and(|s| s != "verification"))
        .filter_map(|r| e_tr[r])
        .fold(f64::NEG_INFINITY, f64::max);
    // The verified design is the best any evaluation found (the baseline's and the
    // robustness samples' included).
    assert!((e_tr[verified].unwrap() - best_searched).abs() < 1e-5);

    let best = p.results.join("trap.best.toml");
    let scene = woodpile_scene::load(&best).unwrap();
    assert_eq!(scene.region_paper, [-1, 4]);
    let again = woodpile_sim::run::simulate(&scene.scenario, &mut ()).unwrap();
    assert_eq!(Some(again.fractions.trapped), e_tr[verified]);

    let points = count_files(&points_dir(&p.results));
    p.run_with(&["trap"], true);
    assert_eq!(
        count_files(&points_dir(&p.results)),
        points,
        "nothing simulated twice"
    );

    // A missing best design makes the stage stale.
    std::fs::remove_file(&best).unwrap();
    assert!(matches!(p.state("trap"), State::Stale(_)));
}

/// The kinds are listed once: the unknown-kind error names every one of them.
#[test]
fn an_unknown_kind_lists_every_kind() {
    let e = load_error(&[("x", "kind = \"plot\"")]);
    for kind in woodpile_stages::names() {
        assert!(e.contains(kind), "{kind} missing from: {e}");
    }
    assert!(woodpile_stages::names().any(|k| k == "design"));
}

/// Errors keep their causes: a scene the scene crate rejects, a stage file the TOML parser
/// rejects, a file the OS cannot read.
#[test]
fn errors_keep_their_sources() {
    use std::error::Error;
    let p = Project::new(&[("sweep", &SWEEP.replace("from = 0.5, to", "from = -0.5, to"))]);
    let e = Pipeline::load(&p.pipeline, KINDS).unwrap_err();
    assert!(e.to_string().contains("scene.defect[0].eps"), "{e}");
    let scene = e
        .source()
        .and_then(|s| s.downcast_ref::<woodpile_scene::SceneError>());
    assert!(
        matches!(scene, Some(woodpile_scene::SceneError::Invalid { key, .. }) if key == "defect[0].eps"),
        "{scene:?}"
    );
    let p = Project::new(&[("sweep", "kind = \"sweep\"\n[scene\n")]);
    let e = Pipeline::load(&p.pipeline, KINDS).unwrap_err();
    assert!(e.source().is_some_and(|s| s.is::<toml::de::Error>()), "{e}");
    let e = table::read(&p.results.join("absent.parquet")).unwrap_err();
    assert!(e.source().is_some_and(|s| s.is::<std::io::Error>()), "{e}");
}

/// Records which stages run at the same time.
#[derive(Default)]
struct Overlaps {
    running: Mutex<Vec<String>>,
    /// Every pair seen running together, and the most seen at once.
    together: Mutex<Vec<(String, String)>>,
}

impl Events for Overlaps {
    fn stage_started(&self, stage: &str, _: &str) {
        let mut running = self.running.lock().unwrap();
        let mut together = self.together.lock().unwrap();
        for other in running.iter() {
            together.push((other.clone(), stage.to_string()));
        }
        running.push(stage.to_string());
    }
    fn stage_finished(&self, stage: &str, _: &str) {
        self.running.lock().unwrap().retain(|s| s != stage);
    }
}

/// Independent stages run side by side, within what their kinds allow: a stage that times
/// itself (work precision) runs with nothing else, and two sweeps never run together (the
/// second may need the first's points). The results are those of a run one stage at a time.
#[test]
fn stages_run_side_by_side_within_their_kinds_limits() {
    let other_sweep = SWEEP.replace("L = [0, 1]", "L = [2, 3]");
    let stages = [
        ("sweep", SWEEP),
        ("sweep_b", other_sweep.as_str()),
        ("reduce", REDUCE),
        ("best", BEST),
        ("wp", WORK_PRECISION),
        ("chart", WORK_PRECISION_CHART),
    ];
    let p = Project::new(&stages);
    let events = Overlaps::default();
    let pipeline = Pipeline::load(&p.pipeline, KINDS).unwrap();
    let options = RunOptions {
        results: p.results.clone(),
        figures: p.results.join("figures"),
        ..RunOptions::default()
    };
    run(&pipeline, &options, &events).unwrap();
    let together = events.together.lock().unwrap().clone();
    for (a, b) in &together {
        assert!(a != "wp" && b != "wp", "work precision ran beside {a} {b}");
        assert!(
            !(a.starts_with("sweep") && b.starts_with("sweep")),
            "two sweeps ran together"
        );
    }
    // The same tables as a run that starts again from nothing: the order changed no bit.
    let again = Project::new(&stages);
    again.run(&[]);
    for name in ["sweep", "sweep_b", "reduce", "best"] {
        let a = table::read(&p.output(name)).unwrap();
        let b = table::read(&again.output(name)).unwrap();
        assert!(a.equals_missing(&b), "{name} differs");
    }
}
