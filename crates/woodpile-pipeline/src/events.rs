//! What a running pipeline tells its caller, so that this crate never prints: the CLI turns
//! these into progress bars on a terminal and plain lines in CI logs.

/// Receives progress from a run. Called from worker threads, hence `Sync`.
pub trait Events: Sync {
    /// `stage` starts, for the reason given (`missing`, `parameter ... changed`, `forced`).
    fn stage_started(&self, _stage: &str, _why: &str) {}
    /// A sweep has `to_simulate` scenes to run; `cached` more were found in the point cache.
    fn simulating(&self, _stage: &str, _to_simulate: usize, _cached: usize) {}
    /// One scene finished (success or recorded failure).
    fn point_done(&self) {}
    /// `stage` wrote its output; `summary` is one line for the log.
    fn stage_finished(&self, _stage: &str, _summary: &str) {}
    /// `stage` was fresh and skipped.
    fn stage_skipped(&self, _stage: &str) {}
    /// A warning worth a line (failed points, removed temporaries).
    fn warn(&self, _message: &str) {}
}

/// Ignores everything (tests, library use).
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Events for Silent {}
