//! Running stages: upstream first, only what is stale (or forced), each output written
//! atomically with its manifest.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};

use crate::error::{PipelineError, Result};
use crate::events::Events;
use crate::kind::{Context, Sharing};
use crate::lock::lock_results;
use crate::manifest::Manifest;
use crate::pipeline::Pipeline;
use crate::stage::Stage;
use crate::status::{state, State};
use crate::{sealed_files, table};
use woodpile_files::atomic;
use woodpile_files::key::code_version;
use woodpile_files::layout::{output_path, points_dir};
use woodpile_files::PointsDir;

/// How to run.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Stages to run (with everything upstream); empty means all.
    pub targets: Vec<String>,
    /// Re-run the targets (all stages if no targets) even when fresh. Points stay cached:
    /// they are content-addressed and checksummed, so re-simulating them would give the same
    /// bits.
    pub force: bool,
    /// Only say what would run and why.
    pub dry_run: bool,
    /// The results tree (stage tables and the point cache).
    pub results: PathBuf,
    /// Where render stages put their PNG and SVG files.
    pub figures: PathBuf,
}

/// One stage's part in a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The stage.
    pub stage: String,
    /// Whether it runs (or, in a dry run, would).
    pub runs: bool,
    /// Why it runs, or `fresh`.
    pub why: String,
    /// For sweeps that run: (points, of which cached).
    pub points: Option<(usize, usize)>,
    /// Scenes it simulated (0 for a stage that did not run, or simulates nothing).
    pub simulated: usize,
}

/// Runs (or plans) the pipeline; returns what each selected stage did. A run holds the
/// results tree's lock ([`crate::lock`]) throughout: a second run on the same tree waits.
///
/// Stages whose inputs are done run side by side on as many workers as the machine has cores,
/// within what each kind allows ([`Sharing`]): one parallel stage (a sweep) at a time, in
/// pipeline order, with single-threaded stages (reductions, optima, figures) beside it, and a
/// stage that times itself with nothing else. The results are the same bits in any order: each
/// stage reads only its finished inputs.
///
/// A stage that fails stops only the stages that read it: the others still run, and the run
/// then ends with [`PipelineError::Failed`] naming every failure, including the partial ones a
/// stage recorded in its table (a fit that did not converge).
pub fn run(pipeline: &Pipeline, options: &RunOptions, events: &dyn Events) -> Result<Vec<Step>> {
    let results = &options.results;
    for folder in [points_dir(results), results.join("parts")] {
        woodpile_files::layout::check_tree_folder(&folder)
            .map_err(|e| PipelineError::refused(&folder, e))?;
    }
    let points = PointsDir::new(points_dir(results));
    let selection = pipeline.selection(&options.targets)?;
    if options.dry_run {
        return selection
            .into_iter()
            .map(|stage| Ok(decide(pipeline, stage, options, &points, events)?.0))
            .collect();
    }
    let _lock = lock_results(results, events)?;
    let removed = points.sweep_stale_temps()
        + atomic::sweep_stale_temps(results)
        + atomic::sweep_stale_temps(&options.figures);
    if removed > 0 {
        events.warn(&format!(
            "removed {removed} temporary file(s) left by an interrupted run"
        ));
    }
    let board = Mutex::new(Board::new(&selection));
    let changed = Condvar::new();
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get().max(2));
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                while let Some(i) = next_job(&board, &changed, events) {
                    let stage = selection[i];
                    let work = || match decide(pipeline, stage, options, &points, events) {
                        Ok((step, true)) => {
                            match run_stage(pipeline, stage, &step.why, options, &points, events) {
                                Ok((partial, simulated)) => {
                                    (Some(Step { simulated, ..step }), Ok(partial))
                                }
                                Err(e) => (Some(step), Err(e)),
                            }
                        }
                        Ok((step, false)) => (Some(step), Ok(Vec::new())),
                        Err(e) => (None, Err(e)),
                    };
                    // A stage that panics fails like any other: the worker must still report
                    // it, or the workers waiting for it would wait forever.
                    let (step, outcome) =
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(work))
                            .unwrap_or_else(|panic| {
                                let what = panic
                                    .downcast_ref::<&str>()
                                    .map(|s| s.to_string())
                                    .or_else(|| panic.downcast_ref::<String>().cloned())
                                    .unwrap_or_default();
                                let e =
                                    PipelineError::stage(&stage.name, format!("panicked: {what}"));
                                (None, Err(e))
                            });
                    lock(&board).finish(i, step, outcome, events);
                    changed.notify_all();
                }
            });
        }
    });
    let board = board.into_inner().unwrap_or_else(PoisonError::into_inner);
    if let Some(fatal) = board.fatal {
        return Err(fatal);
    }
    if board.failures.is_empty() {
        Ok(board.steps.into_iter().flatten().collect())
    } else {
        Err(PipelineError::Failed {
            failures: board.failures,
        })
    }
}

/// Whether `stage` must run, and its [`Step`]: fresh stages are reported skipped, damaged
/// ones warned about.
fn decide(
    pipeline: &Pipeline,
    stage: &Stage,
    options: &RunOptions,
    points: &PointsDir,
    events: &dyn Events,
) -> Result<(Step, bool)> {
    let forced =
        options.force && (options.targets.is_empty() || options.targets.contains(&stage.name));
    let current = state(pipeline, &options.results, &options.figures, stage);
    let why = match (&current, forced) {
        (State::Fresh, false) => {
            // A dry run's caller lists every stage itself: no second line for this one.
            if !options.dry_run {
                events.stage_skipped(&stage.name);
            }
            let step = Step {
                stage: stage.name.clone(),
                runs: false,
                why: "fresh".into(),
                points: None,
                simulated: 0,
            };
            return Ok((step, false));
        }
        (State::Fresh, true) => "forced".to_string(),
        (State::Damaged(reason), _) => {
            if !options.dry_run {
                events.warn(&format!(
                    "stage `{}`: {reason}; computing it again",
                    stage.name
                ));
            }
            format!("damaged: {reason}")
        }
        (other, _) => format!("{}: {}", other.label(), other.why()),
    };
    let points = match stage.spec.points() {
        Some(grid) => Some((grid.count(), grid.cached(points)?)),
        None => None,
    };
    let step = Step {
        stage: stage.name.clone(),
        runs: true,
        why,
        points,
        simulated: 0,
    };
    Ok((step, true))
}

/// Runs a stage that [`decide`] found stale; returns the partial failures it recorded and the
/// scenes it simulated.
fn run_stage(
    pipeline: &Pipeline,
    stage: &Stage,
    why: &str,
    options: &RunOptions,
    points: &PointsDir,
    events: &dyn Events,
) -> Result<(Vec<String>, usize)> {
    events.stage_started(&stage.name, why);
    let (summary, partial, simulated) = execute(pipeline, stage, options, points, events)?;
    for failure in &partial {
        events.warn(&format!("stage `{}`: {failure}", stage.name));
    }
    events.stage_finished(&stage.name, &summary);
    let partial = partial
        .into_iter()
        .map(|f| format!("stage `{}`: {f}", stage.name))
        .collect();
    Ok((partial, simulated))
}

/// Where each selected stage of a run is, shared by the workers.
struct Board<'a> {
    stages: Vec<&'a Stage>,
    /// Selection index of each stage name.
    index: BTreeMap<&'a str, usize>,
    status: Vec<Status>,
    /// What each stage did, by selection index.
    steps: Vec<Option<Step>>,
    failures: Vec<String>,
    /// An error that is not one stage's (an unwritable results tree): no new stage starts.
    fatal: Option<PipelineError>,
    /// Stages running, and whether one of them is parallel or alone.
    busy: usize,
    busy_parallel: bool,
    busy_alone: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Status {
    Waiting,
    Running,
    Done,
    Failed,
}

impl<'a> Board<'a> {
    fn new(stages: &[&'a Stage]) -> Self {
        Self {
            stages: stages.to_vec(),
            index: stages
                .iter()
                .enumerate()
                .map(|(i, s)| (s.name.as_str(), i))
                .collect(),
            status: vec![Status::Waiting; stages.len()],
            steps: vec![None; stages.len()],
            failures: Vec::new(),
            fatal: None,
            busy: 0,
            busy_parallel: false,
            busy_alone: false,
        }
    }

    fn finished(&self) -> bool {
        self.busy == 0
            && (self.fatal.is_some() || self.status.iter().all(|s| *s != Status::Waiting))
    }

    /// The first waiting stage, in pipeline order, whose inputs are done and which may start
    /// beside the running ones; marks stages whose input failed as skipped on the way.
    fn take_ready(&mut self, events: &dyn Events) -> Option<usize> {
        if self.fatal.is_some() || self.busy_alone {
            return None;
        }
        for i in 0..self.stages.len() {
            if self.status[i] != Status::Waiting {
                continue;
            }
            let stage = self.stages[i];
            let input_status = |name: &String| {
                self.index
                    .get(name.as_str())
                    .map_or(Status::Done, |&j| self.status[j])
            };
            if let Some(input) = stage
                .inputs
                .iter()
                .find(|n| input_status(n) == Status::Failed)
            {
                let why = format!("skipped: input `{input}` failed");
                events.warn(&format!("stage `{}` {why}", stage.name));
                self.failures.push(format!("stage `{}` {why}", stage.name));
                self.status[i] = Status::Failed;
                self.steps[i] = Some(Step {
                    stage: stage.name.clone(),
                    runs: false,
                    why,
                    points: None,
                    simulated: 0,
                });
                continue;
            }
            if !stage.inputs.iter().all(|n| input_status(n) == Status::Done) {
                continue;
            }
            let sharing = stage.spec.sharing();
            let allowed = match sharing {
                Sharing::Shared => true,
                Sharing::Parallel => !self.busy_parallel,
                Sharing::Alone => self.busy == 0,
            };
            if !allowed {
                continue;
            }
            self.status[i] = Status::Running;
            self.busy += 1;
            self.busy_parallel |= sharing == Sharing::Parallel;
            self.busy_alone |= sharing == Sharing::Alone;
            return Some(i);
        }
        None
    }

    /// Records what stage `i` did.
    fn finish(
        &mut self,
        i: usize,
        step: Option<Step>,
        outcome: Result<Vec<String>>,
        events: &dyn Events,
    ) {
        let stage = self.stages[i];
        self.busy -= 1;
        match stage.spec.sharing() {
            Sharing::Shared => {}
            Sharing::Parallel => self.busy_parallel = false,
            Sharing::Alone => self.busy_alone = false,
        }
        self.steps[i] = step;
        match outcome {
            Ok(partial) => {
                self.failures.extend(partial);
                self.status[i] = Status::Done;
            }
            // A stage that cannot produce its output stops only what depends on it.
            Err(e @ PipelineError::Stage { .. }) => {
                events.warn(&e.to_string());
                self.failures.push(e.to_string());
                self.status[i] = Status::Failed;
            }
            Err(e) => {
                self.status[i] = Status::Failed;
                self.fatal.get_or_insert(e);
            }
        }
    }
}

fn lock<'b, 'a>(board: &'b Mutex<Board<'a>>) -> MutexGuard<'b, Board<'a>> {
    board.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Waits for a stage this worker may run; `None` when the run is over.
fn next_job(board: &Mutex<Board<'_>>, changed: &Condvar, events: &dyn Events) -> Option<usize> {
    let mut guard = lock(board);
    loop {
        if guard.finished() {
            changed.notify_all();
            return None;
        }
        if let Some(i) = guard.take_ready(events) {
            return Some(i);
        }
        guard = changed.wait(guard).unwrap_or_else(PoisonError::into_inner);
    }
}

fn execute(
    pipeline: &Pipeline,
    stage: &Stage,
    options: &RunOptions,
    points: &PointsDir,
    events: &dyn Events,
) -> Result<(String, Vec<String>, usize)> {
    let results = &options.results;
    let upstream = pipeline
        .selection(std::slice::from_ref(&stage.name))?
        .into_iter()
        .filter(|s| s.name != stage.name)
        .collect();
    let root = crate::pipeline::project_root(pipeline.dir());
    let output = stage.spec.run(&Context {
        stage,
        upstream,
        root: &root,
        results,
        figures: &options.figures,
        points,
        events,
    })?;
    let mut manifest = manifest_for(pipeline, stage, output.summary.clone());
    // The table comes last and records what every other file of the stage now holds: a run
    // stopped before it leaves the stage stale, never fresh with someone else's figure.
    manifest.files =
        sealed_files::record(&stage.spec.files(&stage.name, results, &options.figures))?;
    let rows = output.frame.height();
    table::write(&output_path(results, &stage.name), output.frame, &manifest)?;
    let line = match output.points {
        Some(stats) => format!(
            "{rows} rows, {} points, {} failed",
            stats.points, stats.failed
        ),
        None => format!("{rows} rows"),
    };
    Ok((line, output.failures, output.simulated))
}

/// The manifest of `stage`'s output as computed from the current definitions.
pub(crate) fn manifest_for(
    pipeline: &Pipeline,
    stage: &Stage,
    summary: serde_json::Value,
) -> Manifest {
    Manifest {
        stage: stage.name.clone(),
        kind: stage.kind.to_string(),
        key: pipeline.key(&stage.name).to_string(),
        code_version: code_version(),
        params: stage.params.value(),
        inputs: stage
            .inputs
            .iter()
            .map(|i| (i.clone(), pipeline.key(i).to_string()))
            .collect::<BTreeMap<_, _>>(),
        summary,
        files: BTreeMap::new(),
        checksum: None,
    }
}
