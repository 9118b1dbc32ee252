//! What a run does: definition errors, exact re-runs, shared and resumed points, results
//! independent of the thread count, failures as nulls, and stages side by side.
#![allow(clippy::unwrap_used)]

mod common;

use std::sync::atomic::Ordering;
use std::sync::Mutex;

use common::{
    load_error, Counter, Project, BEST, REDUCE, SWEEP, WORK_PRECISION, WORK_PRECISION_CHART,
};
use woodpile_files::layout::points_dir;
use woodpile_pipeline::events::Events;
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::status::State;
use woodpile_pipeline::{table, Pipeline, PipelineError};
use woodpile_points::PointStore;
use woodpile_stages::KINDS;

#[test]
fn definition_errors_name_the_file_and_key() {
    let sweep = |from: &str, to: &str| SWEEP.replace(from, to);
    let with_table = format!("{SWEEP}\n[scene.chain2]\nn = 3");
    // Each project that must not load (its stage files), and what its error must name.
    type Refused<'a> = (Vec<(&'a str, String)>, &'a [&'a str]);
    let projects: Vec<Refused> = vec![
        (
            vec![(
                "sweep",
                sweep("kind = \"sweep\"", "kind = \"sweep\"\ncolour = 1"),
            )],
            &["sweep.toml", "`colour`", "unknown key"],
        ),
        (
            vec![
                ("sweep", SWEEP.into()),
                ("r", REDUCE.replace("\"sweep\"", "\"swep\"")),
            ],
            &["r.toml", "inputs[0]", "swep"],
        ),
        (
            vec![
                ("sweep", SWEEP.into()),
                ("r", REDUCE.into()),
                ("rr", REDUCE.replace("\"sweep\"", "\"r\"")),
            ],
            &["rr.toml", "reduce reads a sweep"],
        ),
        (
            vec![("sweep", sweep("\"$eps\"", "\"$epsilon\""))],
            &["scene.defect[0].eps", "$epsilon"],
        ),
        (
            vec![("sweep", sweep("site = -6 }", "site = -60 }"))],
            &["sweep.toml", "scene.impulse.site"],
        ),
        (vec![("sweep", with_table)], &["sweep.toml", "chain2"]),
        (
            vec![
                ("sweep", SWEEP.into()),
                ("b", BEST.replace("[\"eps\"]", "[\"kappa\"]")),
            ],
            &["b.toml", "maximize.over", "kappa"],
        ),
        (
            vec![("sweep", sweep("kind = \"sweep\"", "kind = \"plot\""))],
            &["key `kind`", "plot"],
        ),
    ];
    for (stages, named) in &projects {
        let stages: Vec<(&str, &str)> = stages.iter().map(|(n, t)| (*n, t.as_str())).collect();
        let e = load_error(&stages);
        assert!(named.iter().all(|n| e.contains(n)), "{e}");
    }
    // A cycle is named whichever stage it is entered from.
    let e = load_error(&[
        ("a", "kind = \"reduce\"\ninputs = [\"b\"]"),
        ("b", "kind = \"reduce\"\ninputs = [\"a\"]"),
    ]);
    assert!(
        e.contains("inputs") && (e.contains("a -> b -> a") || e.contains("b -> a -> b")),
        "{e}"
    );
}

#[test]
fn a_second_run_does_nothing_and_an_edit_reruns_exactly_its_dependents() {
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE), ("best", BEST)]);
    let first = p.counted(&[]);
    assert_eq!(first.points.load(Ordering::SeqCst), 6);
    assert_eq!(first.started.lock().unwrap().len(), 3);

    let second = p.counted(&[]);
    assert_eq!(second.points.load(Ordering::SeqCst), 0);
    assert!(second.started.lock().unwrap().is_empty());

    // A read-out time is a reduction parameter: one stage re-runs, nothing is simulated.
    p.write("at_end", &REDUCE.replace("at = 12.0", "at = 10.0"));
    match p.state("at_end") {
        State::Stale(why) => assert_eq!(why, vec!["parameter at: 12.0 -> 10.0".to_string()]),
        other => panic!("{other:?}"),
    }
    assert_eq!(p.state("best"), State::Fresh);
    let third = p.counted(&[]);
    assert_eq!(*third.started.lock().unwrap(), vec!["at_end".to_string()]);
    assert_eq!(third.points.load(Ordering::SeqCst), 0);

    // A sweep parameter re-runs the sweep and everything downstream of it.
    p.write("sweep", &SWEEP.replace("dt = 0.02", "dt = 0.01"));
    match p.state("best") {
        State::Stale(why) => assert_eq!(why, vec!["upstream `sweep` changed".to_string()]),
        other => panic!("{other:?}"),
    }
    let fourth = p.counted(&[]);
    assert_eq!(fourth.started.lock().unwrap().len(), 3);
    assert_eq!(fourth.points.load(Ordering::SeqCst), 6);
}

#[test]
fn overlapping_sweeps_share_points() {
    let wider = SWEEP.replace("L = [0, 1]", "L = [0, 1, 2]");
    let p = Project::new(&[("sweep", SWEEP), ("wider", &wider)]);
    let first = p.counted(&["sweep"]);
    assert_eq!(first.points.load(Ordering::SeqCst), 6);
    let second = p.counted(&["wider"]);
    assert_eq!(second.points.load(Ordering::SeqCst), 3, "only L = 2 is new");
    // --force re-runs the stage but reuses the content-addressed points.
    let forced = p.counted_with(&["wider"], true);
    assert_eq!(*forced.started.lock().unwrap(), vec!["wider".to_string()]);
    assert_eq!(forced.points.load(Ordering::SeqCst), 0);
    // What each run's steps report as simulated is what it simulated.
    let simulated = [&first, &second, &forced].map(|c| c.simulated.load(Ordering::SeqCst));
    assert_eq!(simulated, [6, 3, 0]);
}

#[test]
fn an_interrupted_sweep_resumes_without_repeating_finished_points() {
    let p = Project::new(&[("sweep", SWEEP)]);
    p.counted(&[]);
    let reference = std::fs::read(p.output("sweep")).unwrap();
    // What a kill -9 leaves: some points finished, no stage output, a temporary of a dead
    // writer (pid 0), and (worse than a kill can do) one damaged point file.
    std::fs::remove_file(p.output("sweep")).unwrap();
    let store = PointStore::new(points_dir(&p.results()));
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

    let resumed = p.counted(&[]);
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
            pool.install(|| p.counted(&[]));
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
    p.counted(&[]);
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
            results: p.results().clone(),
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
    let events = p.counted(&[]);
    assert!(events.warned("failed"));
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
    let events = pool.install(|| p.counted(&[]));
    assert_eq!(events.points.load(Ordering::SeqCst), 1);
    let frame = table::read(&p.output("sweep")).unwrap();
    let e_tr = table::f64_column(&frame, "E_tr").unwrap();
    let per_point = frame.height() / 40;
    for (i, value) in e_tr.iter().enumerate() {
        assert_eq!(*value, e_tr[i % per_point], "row {i}");
    }
}

#[test]
fn every_run_sweeps_leftover_temporaries_even_when_all_is_fresh() {
    let p = Project::new(&[("sweep", SWEEP)]);
    p.counted(&[]);
    // Another machine's temporary, two days old; and one of a process on this machine that
    // has ended (pid 0 is never a user process) cannot be named without the host, so the
    // foreign one stands for both rules here (the atomic module tests the other).
    let figures = p.figures();
    std::fs::create_dir_all(&figures).unwrap();
    let stale = figures.join(".f.png~elsewhere~12~Ab3dEf6hIj9l.tmp");
    let file = std::fs::File::create(&stale).unwrap();
    let two_days = std::time::Duration::from_secs(2 * 24 * 3600);
    file.set_modified(std::time::SystemTime::now() - two_days)
        .unwrap();
    drop(file);
    let events = p.counted(&[]);
    assert!(!stale.exists());
    assert!(
        events.started.lock().unwrap().is_empty(),
        "nothing was stale"
    );
    assert!(events.warned("temporary"));
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

/// The kinds are listed once: the unknown-kind error names every one of them.
#[test]
fn an_unknown_kind_lists_every_kind() {
    let e = load_error(&[("x", "kind = \"plot\"")]);
    for kind in woodpile_stages::names() {
        assert!(e.contains(kind), "{kind} missing from: {e}");
    }
    assert!(woodpile_stages::names().any(|k| k == "design"));
}

/// Errors keep their causes: a scene the scene crate rejects, a file the OS cannot read. A stage
/// file the TOML parser rejects is reported by line and column without the parser's error as
/// a source: its text quotes the file, which may be anything (`/proc/self/environ`).
#[test]
fn errors_keep_their_sources() {
    use std::error::Error;
    let p = Project::new(&[("sweep", &SWEEP.replace("from = 0.5, to", "from = -0.5, to"))]);
    let e = Pipeline::load(&p.pipeline(), KINDS).unwrap_err();
    assert!(e.to_string().contains("scene.defect[0].eps"), "{e}");
    let scene = e
        .source()
        .and_then(|s| s.downcast_ref::<woodpile_scene::SceneError>());
    assert!(
        matches!(scene, Some(woodpile_scene::SceneError::Invalid { key, .. }) if key == "defect[0].eps"),
        "{scene:?}"
    );
    let p = Project::new(&[("sweep", "kind = \"sweep\"\n[scene\n")]);
    let e = Pipeline::load(&p.pipeline(), KINDS).unwrap_err();
    assert!(
        e.to_string().contains("line 2, column") && e.source().is_none(),
        "{e}"
    );
    let e = table::read(&p.results().join("absent.parquet")).unwrap_err();
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
    let pipeline = Pipeline::load(&p.pipeline(), KINDS).unwrap();
    let options = RunOptions {
        results: p.results().clone(),
        figures: p.figures(),
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
    again.counted(&[]);
    for name in ["sweep", "sweep_b", "reduce", "best"] {
        let a = table::read(&p.output(name)).unwrap();
        let b = table::read(&again.output(name)).unwrap();
        assert!(a.equals_missing(&b), "{name} differs");
    }
}
