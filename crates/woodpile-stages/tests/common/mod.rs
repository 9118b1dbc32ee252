//! A project in a temporary folder (`pipeline/`, `results/`, `figures/`), for the test files
//! that run stages end to end.
#![allow(dead_code, clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use woodpile_stages::KINDS;

use woodpile_pipeline::events::Silent;
use woodpile_pipeline::layout::output_path;
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::status::{state, State};
use woodpile_pipeline::variant::Set;
use woodpile_pipeline::Pipeline;

pub struct Project {
    dir: tempfile::TempDir,
}

impl Project {
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
}
