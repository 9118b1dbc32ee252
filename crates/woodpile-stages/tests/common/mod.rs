//! A project in a temporary folder (`pipeline/`, `results/`, `figures/`), for the test files
//! that run stages end to end.
#![allow(dead_code, clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use woodpile_stages::KINDS;

use woodpile_files::layout::output_path;
use woodpile_pipeline::events::{Events, Silent};
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::shard::{run_shard, Shard, ShardRun};
use woodpile_pipeline::status::{state, State};
use woodpile_pipeline::variant::Set;
use woodpile_pipeline::Pipeline;

pub struct Project {
    dir: tempfile::TempDir,
}

impl Project {
    /// Shard `index` of `count` of the sweep stage `stage`, into this project's results.
    pub fn shard(
        &self,
        pipeline: &Pipeline,
        stage: &str,
        (index, count): (usize, usize),
        events: &dyn Events,
    ) -> woodpile_pipeline::Result<ShardRun> {
        let shard = Shard::new(index, count).unwrap();
        run_shard(pipeline, stage, shard, &self.results(), events)
    }

    /// A project with these stage files (`name`, text).
    pub fn new(stages: &[(&str, &str)]) -> Project {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("pipeline")).unwrap();
        let p = Project { dir };
        for (name, text) in stages {
            p.write(name, text);
        }
        p
    }
    pub fn root(&self) -> &Path {
        self.dir.path()
    }
    pub fn pipeline(&self) -> PathBuf {
        self.root().join("pipeline")
    }
    pub fn results(&self) -> PathBuf {
        self.root().join("results")
    }
    pub fn figures(&self) -> PathBuf {
        self.root().join("figures")
    }
    pub fn write(&self, name: &str, text: &str) {
        std::fs::write(self.pipeline().join(format!("{name}.toml")), text).unwrap();
    }
    /// Runs `targets` (all when empty) with variants `sets`; the pipeline that ran.
    pub fn run_with(&self, sets: &[Set], targets: &[&str]) -> woodpile_pipeline::Result<Pipeline> {
        let pipeline = Pipeline::load_with(&self.pipeline(), KINDS, sets)?;
        let options = RunOptions {
            targets: targets.iter().map(|s| s.to_string()).collect(),
            force: false,
            dry_run: false,
            results: self.results(),
            figures: self.figures(),
        };
        run(&pipeline, &options, &Silent)?;
        Ok(pipeline)
    }
    pub fn run(&self, targets: &[&str]) -> woodpile_pipeline::Result<()> {
        self.run_with(&[], targets).map(|_| ())
    }
    pub fn state(&self, name: &str) -> State {
        let p = Pipeline::load(&self.pipeline(), KINDS).unwrap();
        state(&p, &self.results(), &self.figures(), p.stage(name).unwrap())
    }
    pub fn output(&self, name: &str) -> PathBuf {
        output_path(&self.results(), name)
    }
    /// The pipeline as it is on disk.
    pub fn load(&self) -> Pipeline {
        Pipeline::load(&self.pipeline(), KINDS).unwrap()
    }
    /// Runs `targets` (all when empty), which must succeed, and says what ran.
    pub fn counted(&self, targets: &[&str]) -> Counter {
        self.counted_with(targets, false)
    }
    /// [`Project::counted`], re-running the targets even when fresh if `force`.
    pub fn counted_with(&self, targets: &[&str], force: bool) -> Counter {
        let events = Counter::default();
        let options = RunOptions {
            targets: targets.iter().map(|s| s.to_string()).collect(),
            force,
            dry_run: false,
            results: self.results(),
            figures: self.figures(),
        };
        let steps = run(&self.load(), &options, &events).unwrap();
        let simulated = steps.iter().map(|s| s.simulated).sum();
        events
            .simulated
            .store(simulated, std::sync::atomic::Ordering::SeqCst);
        events
    }
}

/// Counts what a run did.
#[derive(Default)]
pub struct Counter {
    pub points: AtomicUsize,
    /// The scenes the run's steps say they simulated.
    pub simulated: AtomicUsize,
    pub started: Mutex<Vec<String>>,
    pub warnings: Mutex<Vec<String>>,
}

impl Counter {
    /// Whether a warning mentioned `text`.
    pub fn warned(&self, text: &str) -> bool {
        self.warnings
            .lock()
            .unwrap()
            .iter()
            .any(|w| w.contains(text))
    }
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

impl Project {
    /// A project of [`single_defect_sweep`], its reduction at the end (`at_end`) and `more`.
    pub fn reducing(more: &[(&str, &str)]) -> Project {
        let sweep = single_defect_sweep();
        let mut stages = vec![("sweep", sweep.as_str()), ("at_end", REDUCE)];
        stages.extend_from_slice(more);
        Project::new(&stages)
    }
}

/// Why a project of [`SWEEP`], its reduction at the end (`at_end`) and the stage `name` of
/// `text` does not load.
pub fn load_error_after_reduce(name: &str, text: &str) -> String {
    load_error(&[("sweep", SWEEP), ("at_end", REDUCE), (name, text)])
}

/// Why a project of these stage files does not load.
pub fn load_error(stages: &[(&str, &str)]) -> String {
    let project = Project::new(stages);
    Pipeline::load(&project.pipeline(), KINDS)
        .unwrap_err()
        .to_string()
}

mod stage_files;
#[allow(unused_imports)] // each test file uses its own share of the fixtures
pub use stage_files::*;
