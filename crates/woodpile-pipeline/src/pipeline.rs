//! The DAG of stages in a pipeline directory: every `*.toml` file (in it or in a subdirectory)
//! is a stage named by its stem.
//! Loading checks what no single file can: inputs that name no stage, inputs of the wrong kind,
//! and cycles; then it orders the stages upstream first and computes every cache key.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use serde_json::json;

use crate::error::{PipelineError, Result};
use crate::kind::{Inputs, Registry};
use crate::stage::{Defaults, Stage};
use crate::variant::Set;
use woodpile_files::key::{code_version, Key};

/// A loaded, validated pipeline.
#[derive(Debug, Clone)]
pub struct Pipeline {
    dir: PathBuf,
    /// Upstream first.
    stages: Vec<Stage>,
    keys: Vec<Key>,
    index: HashMap<String, usize>,
}

impl Pipeline {
    /// Loads every stage file in `dir` and its subdirectories (one folder per figure, say):
    /// a stage is named by its file's stem, wherever it lies, so names must be unique.
    /// The kinds a stage may name are `kinds` (`woodpile_stages::KINDS`): the engine itself
    /// knows none.
    pub fn load(dir: &Path, kinds: &'static Registry) -> Result<Pipeline> {
        Pipeline::load_with(dir, kinds, &[])
    }

    /// [`Pipeline::load`], plus a variant of a stage for each stage named in `sets`: its file
    /// with those keys set, named `<stage>--<key>-<value>` ([`crate::variant::variant_name`]), so that it
    /// has its own key and its own output beside the original's.
    pub fn load_with(dir: &Path, kinds: &'static Registry, sets: &[Set]) -> Result<Pipeline> {
        if !dir.is_dir() {
            return Err(PipelineError::io(
                dir,
                "no stage folder here: a woodpile project has its stage files (*.toml) in `pipeline/` (or the folder that --pipeline, WOODPILE_PIPELINE or woodpile.toml names); `woodpile new study NAME` makes one",
            ));
        }
        let root = project_root(dir);
        let defaults = Defaults::load(dir)?;
        let mut files = Vec::new();
        stage_files(dir, &mut files)?;
        files.retain(|f| *f != dir.join(Defaults::FILE));
        files.sort();
        let mut stages = files
            .iter()
            .map(|f| Stage::load(f, &root, kinds, &defaults))
            .collect::<Result<Vec<_>>>()?;
        stages.extend(crate::variant::variants(
            &stages, sets, &root, kinds, &defaults,
        )?);
        let mut seen: HashMap<&str, &Path> = HashMap::new();
        for stage in &stages {
            if let Some(other) = seen.insert(&stage.name, &stage.file) {
                return Err(PipelineError::Syntax {
                    file: stage.file.clone(),
                    reason: format!(
                        "stage `{}` is defined twice: here and in {}",
                        stage.name,
                        other.display()
                    ),
                    source: None,
                });
            }
        }
        Pipeline::from_stages(dir, stages)
    }

    /// Validates and orders already parsed `stages`.
    pub fn from_stages(dir: &Path, stages: Vec<Stage>) -> Result<Pipeline> {
        let by_name: BTreeMap<&str, &Stage> = stages.iter().map(|s| (s.name.as_str(), s)).collect();
        for stage in &stages {
            check_names(stage, &by_name)?;
        }
        let order = topological_order(&stages)?;
        for stage in &stages {
            check_kinds(stage, &by_name)?;
        }
        check_claims_distinct(&stages)?;
        let mut stages: Vec<Option<Stage>> = stages.into_iter().map(Some).collect();
        let stages: Vec<Stage> = order.into_iter().filter_map(|i| stages[i].take()).collect();
        let index: HashMap<String, usize> = stages
            .iter()
            .enumerate()
            .map(|(i, s)| (s.name.clone(), i))
            .collect();
        let mut keys: Vec<Key> = Vec::with_capacity(stages.len());
        for stage in &stages {
            let inputs: BTreeMap<&str, &str> = stage
                .inputs
                .iter()
                .map(|name| (name.as_str(), keys[index[name]].as_str()))
                .collect();
            keys.push(Key::of(&json!({
                "kind": stage.kind,
                "params": stage.params.value(),
                "inputs": inputs,
                "code": code_version(),
            })));
        }
        Ok(Pipeline {
            dir: dir.to_path_buf(),
            stages,
            keys,
            index,
        })
    }

    /// The directory the stages came from.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Every stage, upstream first.
    pub fn stages(&self) -> &[Stage] {
        &self.stages
    }

    /// The stage called `name`.
    pub fn stage(&self, name: &str) -> Result<&Stage> {
        self.index
            .get(name)
            .map(|&i| &self.stages[i])
            .ok_or_else(|| PipelineError::UnknownStage {
                name: name.to_string(),
                known: self
                    .stages
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// The current cache key of `name` (which must exist).
    pub fn key(&self, name: &str) -> &Key {
        &self.keys[self.index[name]]
    }

    /// `targets` and everything upstream of them, upstream first; every stage if `targets` is
    /// empty.
    pub fn selection(&self, targets: &[String]) -> Result<Vec<&Stage>> {
        if targets.is_empty() {
            return Ok(self.stages.iter().collect());
        }
        let mut wanted = vec![false; self.stages.len()];
        let mut stack: Vec<usize> = Vec::new();
        for t in targets {
            self.stage(t)?;
            stack.push(self.index[t]);
        }
        while let Some(i) = stack.pop() {
            if !std::mem::replace(&mut wanted[i], true) {
                stack.extend(self.stages[i].inputs.iter().map(|n| self.index[n]));
            }
        }
        Ok(self
            .stages
            .iter()
            .zip(wanted)
            .filter(|(_, w)| *w)
            .map(|(s, _)| s)
            .collect())
    }
}

fn definition_error(stage: &Stage, key: &str, reason: impl Into<String>) -> PipelineError {
    PipelineError::Definition {
        file: stage.file.clone(),
        key: key.to_string(),
        reason: reason.into(),
        source: None,
    }
}

/// Every input names a stage, once.
fn check_names(stage: &Stage, by_name: &BTreeMap<&str, &Stage>) -> Result<()> {
    for (i, input) in stage.inputs.iter().enumerate() {
        if !by_name.contains_key(input.as_str()) {
            let known: Vec<&str> = by_name.keys().copied().collect();
            return Err(definition_error(
                stage,
                &format!("inputs[{i}]"),
                format!("no stage named `{input}` (stages: {})", known.join(", ")),
            ));
        }
        if stage.inputs[..i].contains(input) {
            return Err(definition_error(
                stage,
                &format!("inputs[{i}]"),
                format!("`{input}` is listed twice"),
            ));
        }
    }
    Ok(())
}

/// Every input is of a kind the stage can read.
/// The project root of a stage folder: its parent (scene files are named relative to it).
pub fn project_root(dir: &Path) -> PathBuf {
    match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Every `*.toml` under `dir`, recursively.
fn stage_files(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| PipelineError::io(dir, e))?;
    for entry in entries.flatten() {
        let path = entry.path();
        // The entry's own type: a symbolic link to a folder is not followed (a link to `.`
        // would make the walk endless).
        if entry.file_type().is_ok_and(|t| t.is_dir()) {
            stage_files(&path, out)?;
        } else if path.extension().is_some_and(|x| x == "toml") {
            // A stage file that is a link would bring a file from outside the project in as
            // stage parameters (and into its messages).
            if entry.file_type().is_ok_and(|t| t.is_symlink()) {
                return Err(PipelineError::Syntax {
                    file: path,
                    reason: "a symbolic link: stage files must be files of the pipeline folder"
                        .into(),
                    source: None,
                });
            }
            out.push(path);
        }
    }
    Ok(())
}

/// No two stages may claim the same file ([`crate::kind::Kind::claims`]): each would
/// overwrite the other's.
fn check_claims_distinct(stages: &[Stage]) -> Result<()> {
    let mut owner: BTreeMap<String, &str> = BTreeMap::new();
    for stage in stages {
        for (key, file) in stage.spec.claims() {
            if let Some(other) = owner.insert(file.clone(), stage.name.as_str()) {
                return Err(definition_error(
                    stage,
                    key,
                    format!("`{file}` is written by stage `{other}` too"),
                ));
            }
        }
    }
    Ok(())
}

/// The stage's kind checks its inputs (whose existence is already checked).
fn check_kinds(stage: &Stage, by_name: &BTreeMap<&str, &Stage>) -> Result<()> {
    stage
        .spec
        .check_inputs(stage, &Inputs { by_name })
        .map_err(|(key, reason)| definition_error(stage, &key, reason))
}

/// Stage indices, every stage after its inputs; a cycle is an error naming its path.
fn topological_order(stages: &[Stage]) -> Result<Vec<usize>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    let index: HashMap<&str, usize> = stages
        .iter()
        .enumerate()
        .map(|(i, s)| (s.name.as_str(), i))
        .collect();
    let mut marks = vec![Mark::New; stages.len()];
    let mut order = Vec::with_capacity(stages.len());
    let mut path: Vec<usize> = Vec::new();

    fn visit(
        i: usize,
        stages: &[Stage],
        index: &HashMap<&str, usize>,
        marks: &mut [Mark],
        path: &mut Vec<usize>,
        order: &mut Vec<usize>,
    ) -> Result<()> {
        match marks[i] {
            Mark::Done => return Ok(()),
            Mark::Open => {
                let start = path.iter().position(|&j| j == i).unwrap_or(0);
                let mut names: Vec<&str> = path[start..]
                    .iter()
                    .map(|&j| stages[j].name.as_str())
                    .collect();
                names.push(&stages[i].name);
                return Err(definition_error(
                    &stages[i],
                    "inputs",
                    format!("cycle: {}", names.join(" -> ")),
                ));
            }
            Mark::New => {}
        }
        marks[i] = Mark::Open;
        path.push(i);
        for input in &stages[i].inputs {
            visit(index[input.as_str()], stages, index, marks, path, order)?;
        }
        path.pop();
        marks[i] = Mark::Done;
        order.push(i);
        Ok(())
    }

    for i in 0..stages.len() {
        visit(i, stages, &index, &mut marks, &mut path, &mut order)?;
    }
    Ok(order)
}
