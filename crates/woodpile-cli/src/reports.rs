//! What `woodpile run --json` and `woodpile status --json` print: the contract Python's
//! `Pipeline.run` and `.status` read (docs/python.md), as types, so that a field cannot be
//! renamed or dropped in one place and not the other.

use serde::Serialize;

/// `run --json`: what ran (or would run, with `--dry-run`) and what it cost.
#[derive(Debug, Serialize)]
pub(crate) struct RunReport {
    /// Whether nothing was run, only decided.
    pub dry_run: bool,
    /// Every stage of the selection, upstream first.
    pub stages: Vec<StageRun>,
    /// How many stages ran (or would run).
    pub ran: usize,
    /// How many were fresh.
    pub fresh: usize,
    /// Scenes simulated by this run (0 for a dry run).
    pub scenes_simulated: u64,
    /// Wall time of the run.
    pub seconds: f64,
}

/// One stage of a run.
#[derive(Debug, Serialize)]
pub(crate) struct StageRun {
    /// Its name.
    pub stage: String,
    /// Whether it ran (or would run).
    pub runs: bool,
    /// Why it ran, or why it is fresh.
    pub why: String,
    /// For a grid of scenes: how many points, and how many the cache held.
    pub points: Option<usize>,
    pub cached: Option<usize>,
}

/// One row of `status --json`.
#[derive(Debug, Serialize)]
pub(crate) struct StageStatus {
    /// Its name.
    pub stage: String,
    /// Its kind's name.
    pub kind: &'static str,
    /// `fresh`, `stale`, `missing` or `damaged`.
    pub state: &'static str,
    /// Why it is not fresh (empty when it is).
    pub why: String,
}
