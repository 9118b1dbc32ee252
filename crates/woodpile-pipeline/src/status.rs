//! Is a stage's output fresh, stale or missing, and why: the stored manifest against the
//! stage's current definition.

use std::path::Path;

use crate::pipeline::Pipeline;
use crate::stage::Stage;
use crate::table::{self, Integrity};
use woodpile_files::key::{changed_paths, code_version};
use woodpile_files::layout::output_path;

/// Freshness of one stage output.
#[derive(Debug, Clone, PartialEq)]
pub enum State {
    /// The output exists and was computed from exactly the current definition.
    Fresh,
    /// The output exists but something it was computed from changed: the reasons.
    Stale(Vec<String>),
    /// No output yet.
    Missing,
    /// The output exists but its content does not match its manifest's checksum (or it has
    /// none to check): it must be computed again, whatever its key says.
    Damaged(String),
}

impl State {
    /// A short label: `fresh`, `stale`, `missing`.
    pub fn label(&self) -> &'static str {
        match self {
            State::Fresh => "fresh",
            State::Stale(_) => "stale",
            State::Missing => "missing",
            State::Damaged(_) => "damaged",
        }
    }

    /// One line saying why the stage must run (empty when fresh).
    pub fn why(&self) -> String {
        match self {
            State::Fresh => String::new(),
            State::Missing => "no output yet".into(),
            State::Stale(reasons) => reasons.join("; "),
            State::Damaged(reason) => reason.clone(),
        }
    }
}

/// The state of `stage` given the outputs under `results` (and, for render stages, the figure
/// files under `figures`).
///
/// The whole table is read and checked against its manifest's seal, and every other file the
/// stage wrote (figures, Markdown, a design's scene) against the checksum the manifest recorded
/// for it, so neither a damaged output nor a file from an abandoned edit is reported fresh
/// (the results are a few MB: this costs well under a second).
pub fn state(pipeline: &Pipeline, results: &Path, figures: &Path, stage: &Stage) -> State {
    let path = output_path(results, &stage.name);
    let stored = match table::read_checked_manifest(&path) {
        Ok(None) => return State::Missing,
        Ok(Some((_, Integrity::Damaged))) => {
            return State::Damaged(format!("output {}", table::DAMAGED))
        }
        Ok(Some((None, _))) => return State::Damaged("output has no `woodpile` manifest".into()),
        Ok(Some((Some(_), Integrity::Unchecked))) => {
            return State::Damaged("output has no seal to check its content against".into())
        }
        Ok(Some((Some(m), Integrity::Intact))) => m,
        Err(e) => return State::Damaged(format!("output unreadable ({e})")),
    };
    let key = pipeline.key(&stage.name);
    if stored.key == key.as_str() {
        let files = stage.spec.files(&stage.name, results, figures);
        let changed = crate::sealed_files::changed(&files, &stored.files);
        if !changed.is_empty() {
            return State::Stale(changed);
        }
        return State::Fresh;
    }
    let mut reasons = Vec::new();
    let code = code_version();
    if stored.code_version != code {
        reasons.push(format!(
            "code version changed: {} -> {code}",
            stored.code_version
        ));
    }
    for change in changed_paths(&stored.params, &stage.params.value()) {
        reasons.push(format!("parameter {change}"));
    }
    for input in &stage.inputs {
        match stored.inputs.get(input) {
            None => reasons.push(format!("new input `{input}`")),
            Some(k) if k != pipeline.key(input).as_str() => {
                reasons.push(format!("upstream `{input}` changed"))
            }
            Some(_) => {}
        }
    }
    for old in stored.inputs.keys() {
        if !stage.inputs.contains(old) {
            reasons.push(format!("input `{old}` removed"));
        }
    }
    if reasons.is_empty() {
        reasons.push(format!(
            "cache key changed: {} -> {}",
            &stored.key[..12.min(stored.key.len())],
            key.short()
        ));
    }
    State::Stale(reasons)
}
