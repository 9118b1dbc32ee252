//! The engine on its own, with a tiny kind of the test's (`note`: a one-row table and a text
//! file): `Context` is the one door to the tree, a stage's other files are sealed in its
//! manifest, a run reports what it did, and what is loaded or read from the tree is bounded
//! and never followed through links.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use polars::prelude::{Column, DataFrame};
use woodpile_pipeline::events::Silent;
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{Context, Inputs, Kind, KindCheck, Registry};
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::status::{state, State};
use woodpile_pipeline::{Output, Pipeline, PipelineError};

/// `kind = "note"` (any inputs): writes `text` to `<results>/<folder>/<stage>.txt` (declared), or, with
/// `stray = "name"`, to `<results>/name`, which it does not declare.
#[derive(Debug)]
struct Note {
    text: String,
    folder: String,
    stray: Option<String>,
}

impl Note {
    fn path(&self, results: &Path, stage: &str) -> PathBuf {
        results.join(&self.folder).join(format!("{stage}.txt"))
    }
}

impl Kind for Note {
    // A note may read any stage: the tests chain notes to see failures travel downstream.
    fn check_inputs(&self, _: &Stage, _: &Inputs<'_>) -> KindCheck {
        Ok(())
    }

    fn run(&self, ctx: &Context<'_>) -> woodpile_pipeline::Result<Output> {
        let path = match &self.stray {
            None => self.path(ctx.results, ctx.name()),
            Some(name) => ctx.results.join(name),
        };
        ctx.write_file(&path, self.text.as_bytes())?;
        let frame = DataFrame::new_infer_height(vec![Column::new("n".into(), [1_i64])]).unwrap();
        Ok(Output::table(frame, serde_json::json!({})))
    }

    fn files(&self, stage: &str, results: &Path, _: &Path) -> Vec<PathBuf> {
        vec![self.path(results, stage)]
    }
}

static KINDS: &Registry = &[("note", |f: &mut Fields<'_>, _| {
    Ok(Arc::new(Note {
        text: f.required("text")?,
        folder: f.optional("folder")?.unwrap_or_default(),
        stray: f.optional("stray")?,
    }))
})];

/// A project with one `note` stage whose file holds `body` (TOML keys of the stage).
fn project(body: &str) -> tempfile::TempDir {
    notes(&[("note", body)])
}

/// A project with a `note` stage per (name, body).
fn notes(stages: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("pipeline")).unwrap();
    for (name, body) in stages {
        let stage = format!("kind = \"note\"\n{body}\n");
        std::fs::write(dir.path().join(format!("pipeline/{name}.toml")), stage).unwrap();
    }
    dir
}

/// A run of every stage of the project in `dir`, into its own results and figures.
fn options(dir: &Path) -> RunOptions {
    RunOptions {
        targets: Vec::new(),
        force: false,
        dry_run: false,
        results: dir.join("results"),
        figures: dir.join("figures"),
    }
}

fn run_all(dir: &Path) -> woodpile_pipeline::Result<Pipeline> {
    let pipeline = Pipeline::load(&dir.join("pipeline"), KINDS)?;
    let options = options(dir);
    run(&pipeline, &options, &Silent)?;
    Ok(pipeline)
}

/// Runs every stage and names the ones that ran (the rest were fresh).
fn ran(dir: &Path) -> Vec<String> {
    let pipeline = Pipeline::load(&dir.join("pipeline"), KINDS).unwrap();
    let options = options(dir);
    let steps = run(&pipeline, &options, &Silent).unwrap();
    let mut names: Vec<String> = steps
        .into_iter()
        .filter(|s| s.runs)
        .map(|s| s.stage)
        .collect();
    names.sort();
    names
}

fn state_of(dir: &Path, pipeline: &Pipeline) -> State {
    let stage = pipeline.stage("note").unwrap();
    state(pipeline, &dir.join("results"), &dir.join("figures"), stage)
}

#[test]
fn a_declared_file_is_written_and_sealed_in_the_manifest() {
    let dir = project("text = \"hello\"\nfolder = \"notes\"");
    let pipeline = run_all(dir.path()).unwrap();
    let file = dir.path().join("results/notes/note.txt");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "hello");
    assert_eq!(state_of(dir.path(), &pipeline), State::Fresh);
    // The file is part of the stage: changed by hand, the stage is no longer fresh.
    std::fs::write(&file, "edited").unwrap();
    let edited = state_of(dir.path(), &pipeline);
    assert_ne!(edited, State::Fresh, "{edited:?}");
    run_all(dir.path()).unwrap();
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "hello");
}

#[test]
fn a_file_the_kind_does_not_declare_is_refused() {
    let dir = project("text = \"hello\"\nstray = \"stray.txt\"");
    let err = run_all(dir.path()).unwrap_err();
    assert!(matches!(err, PipelineError::Failed { .. }), "{err}");
    assert!(
        err.to_string().contains("which its kind does not declare"),
        "{err}"
    );
    assert!(!dir.path().join("results/stray.txt").exists());
    assert!(!dir.path().join("results/note.parquet").exists());
}

#[test]
fn a_folder_on_the_way_that_is_a_link_is_refused() {
    let dir = project("text = \"hello\"\nfolder = \"notes\"");
    let elsewhere = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("results")).unwrap();
    std::os::unix::fs::symlink(elsewhere.path(), dir.path().join("results/notes")).unwrap();
    let err = run_all(dir.path()).unwrap_err();
    assert!(err.to_string().contains("is a symbolic link"), "{err}");
    assert_eq!(std::fs::read_dir(elsewhere.path()).unwrap().count(), 0);
}

#[test]
fn a_damaged_table_is_never_fresh_and_a_run_recomputes_it() {
    let dir = project("text = \"hello\"");
    let pipeline = run_all(dir.path()).unwrap();
    let table = dir.path().join("results/note.parquet");
    let intact = std::fs::read(&table).unwrap();
    let mut damaged = intact.clone();
    damaged[intact.len() / 2] ^= 1;
    std::fs::write(&table, &damaged).unwrap();
    assert!(matches!(state_of(dir.path(), &pipeline), State::Damaged(_)));
    run_all(dir.path()).unwrap();
    assert_eq!(std::fs::read(&table).unwrap(), intact);
    assert_eq!(state_of(dir.path(), &pipeline), State::Fresh);
}

#[test]
fn a_failed_stage_stops_only_what_reads_it() {
    let dir = notes(&[
        ("broken", "text = \"x\"\nstray = \"stray.txt\""),
        ("reader", "text = \"y\"\ninputs = [\"broken\"]"),
        ("apart", "text = \"z\""),
    ]);
    let err = run_all(dir.path()).unwrap_err();
    let PipelineError::Failed { failures } = &err else {
        panic!("{err}");
    };
    assert_eq!(failures.len(), 2, "{failures:?}");
    assert!(failures
        .iter()
        .any(|f| f.contains("stage `reader` skipped: input `broken` failed")));
    let results = dir.path().join("results");
    assert!(!results.join("broken.parquet").exists() && !results.join("reader.parquet").exists());
    assert_eq!(
        std::fs::read_to_string(results.join("apart.txt")).unwrap(),
        "z"
    );
    assert!(results.join("apart.parquet").is_file());
}

/// A defaults file is copied into every stage of its kind, so it is bounded: a large one is
/// refused at load naming the file, before any stage is parsed.
#[test]
fn an_oversized_defaults_file_is_refused() {
    let dir = project("text = \"hello\"");
    let keys: String = (0..4000)
        .map(|i| format!("key_{i} = \"value {i}\"\n"))
        .collect();
    let defaults = dir.path().join("pipeline/defaults.toml");
    std::fs::write(defaults, format!("[note]\n{keys}")).unwrap();
    let e = Pipeline::load(&dir.path().join("pipeline"), KINDS).unwrap_err();
    let e = e.to_string();
    assert!(
        e.contains("defaults.toml") && e.contains("a defaults file may have"),
        "{e}"
    );
}

/// Stage files and the defaults file must be files of the pipeline folder, not links to files
/// elsewhere (which would enter the stage's parameters and messages).
#[cfg(unix)]
#[test]
fn linked_stage_files_are_refused() {
    for name in ["linked.toml", "defaults.toml"] {
        let dir = project("text = \"hello\"");
        let outside = tempfile::tempdir().unwrap();
        let target = outside.path().join("x.toml");
        std::fs::write(&target, "kind = \"note\"\ntext = \"x\"\n").unwrap();
        std::os::unix::fs::symlink(&target, dir.path().join("pipeline").join(name)).unwrap();
        let e = Pipeline::load(&dir.path().join("pipeline"), KINDS).unwrap_err();
        let e = e.to_string();
        assert!(e.contains(name) && e.contains("a symbolic link"), "{e}");
    }
}

/// Symbolic links to `.` in the stage folder or a results tree do not make a walk endless.
#[cfg(unix)]
#[test]
fn symlink_loops_are_not_followed() {
    let dir = project("text = \"hello\"");
    for name in ["x", "y"] {
        std::os::unix::fs::symlink(".", dir.path().join("pipeline").join(name)).unwrap();
    }
    let pipeline = run_all(dir.path()).unwrap();
    assert_eq!(pipeline.stages().len(), 1);
    let (results, copy) = (dir.path().join("results"), dir.path().join("copy"));
    std::fs::create_dir(&copy).unwrap();
    std::fs::copy(results.join("note.parquet"), copy.join("note.parquet")).unwrap();
    std::os::unix::fs::symlink(".", results.join("loop")).unwrap();
    std::os::unix::fs::symlink(".", copy.join("loop")).unwrap();
    let report = woodpile_pipeline::diff::diff(&results, &copy, &Default::default()).unwrap();
    assert!(report.agrees(), "{:?}", report.problems);
}

/// A FIFO, a link to /dev/zero or a directory in place of a table reads as damaged at once;
/// a run recomputes it.
#[cfg(unix)]
#[test]
fn non_regular_files_in_results_are_damaged_never_read() {
    let dir = project("text = \"hello\"");
    let pipeline = run_all(dir.path()).unwrap();
    let table = dir.path().join("results/note.parquet");
    std::fs::remove_file(&table).unwrap();
    let fifo = std::process::Command::new("mkfifo").arg(&table).status();
    if fifo.is_ok_and(|s| s.success()) {
        assert!(matches!(state_of(dir.path(), &pipeline), State::Damaged(_)));
        std::fs::remove_file(&table).unwrap();
    }
    std::fs::create_dir(&table).unwrap();
    assert!(matches!(state_of(dir.path(), &pipeline), State::Damaged(_)));
    std::fs::remove_dir(&table).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &table).unwrap();
    let state = state_of(dir.path(), &pipeline);
    assert!(
        matches!(state, State::Damaged(ref why) if why.contains("symbolic link")),
        "{state:?}"
    );
    assert!(woodpile_pipeline::table::read(&table).is_err());
    // The run refuses to treat the link as its table but replaces it by a real one.
    run_all(dir.path()).unwrap();
    assert_eq!(state_of(dir.path(), &pipeline), State::Fresh);
    assert!(std::fs::symlink_metadata(&table).unwrap().is_file());
}

/// A second run does nothing; an edited stage runs again with exactly what reads it, and a
/// stage apart from it stays fresh.
#[test]
fn a_second_run_does_nothing_and_an_edit_reruns_exactly_its_dependents() {
    let dir = notes(&[
        ("first", "text = \"a\""),
        ("second", "text = \"b\"\ninputs = [\"first\"]"),
        ("apart", "text = \"c\""),
    ]);
    assert_eq!(ran(dir.path()), ["apart", "first", "second"]);
    assert!(ran(dir.path()).is_empty());
    let edit = |name: &str, body: &str| {
        let stage = format!("kind = \"note\"\n{body}\n");
        std::fs::write(dir.path().join(format!("pipeline/{name}.toml")), stage).unwrap();
    };
    edit("second", "text = \"b2\"\ninputs = [\"first\"]");
    assert_eq!(ran(dir.path()), ["second"]);
    edit("first", "text = \"a2\"");
    assert_eq!(ran(dir.path()), ["first", "second"]);
}

/// Stage files may sit in folders below the pipeline's; the same name twice is an error that
/// names both files.
#[test]
fn stages_in_folders_load_and_a_name_twice_is_an_error() {
    let dir = project("text = \"hello\"");
    let folder = dir.path().join("pipeline/f1");
    std::fs::create_dir(&folder).unwrap();
    std::fs::write(folder.join("other.toml"), "kind = \"note\"\ntext = \"x\"\n").unwrap();
    let pipeline = Pipeline::load(&dir.path().join("pipeline"), KINDS).unwrap();
    assert_eq!(pipeline.stages().len(), 2);
    assert!(pipeline
        .stage("other")
        .unwrap()
        .file
        .ends_with("f1/other.toml"));
    std::fs::write(folder.join("note.toml"), "kind = \"note\"\ntext = \"y\"\n").unwrap();
    let e = Pipeline::load(&dir.path().join("pipeline"), KINDS).unwrap_err();
    let e = e.to_string();
    assert!(
        e.contains("defined twice") && e.contains("f1/note.toml"),
        "{e}"
    );
}
