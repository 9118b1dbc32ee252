//! Running stages: upstream first, only what is stale (or forced), each output written
//! atomically with its manifest.

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::atomic;
use crate::canonical::code_version;
use crate::error::{PipelineError, Result};
use crate::events::Events;
use crate::kind::Context;
use crate::lock::lock_results;
use crate::manifest::Manifest;
use crate::pipeline::Pipeline;
use crate::points::PointStore;
use crate::stage::Stage;
use crate::status::{output_path, state, State};
use crate::sweep::points_dir;
use crate::sweep::Sweep;
use crate::table;

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
}

/// Runs (or plans) the pipeline; returns what each selected stage did. A run holds the
/// results tree's lock ([`crate::lock`]) throughout: a second run on the same tree waits.
///
/// A stage that fails stops only the stages that read it: the others still run, and the run
/// then ends with [`PipelineError::Failed`] naming every failure, including the partial ones a
/// stage recorded in its table (a fit that did not converge).
pub fn run(pipeline: &Pipeline, options: &RunOptions, events: &dyn Events) -> Result<Vec<Step>> {
    let results = &options.results;
    let store = PointStore::new(points_dir(results));
    let _lock = match options.dry_run {
        true => None,
        false => Some(lock_results(results, events)?),
    };
    if !options.dry_run {
        let removed = store.sweep_stale_temps()
            + atomic::sweep_stale_temps(results)
            + atomic::sweep_stale_temps(&options.figures);
        if removed > 0 {
            events.warn(&format!(
                "removed {removed} temporary file(s) left by an interrupted run"
            ));
        }
    }
    let mut steps = Vec::new();
    // Stages that failed (or were skipped because an input failed), and every failure.
    let mut failed: Vec<&str> = Vec::new();
    let mut failures: Vec<String> = Vec::new();
    for stage in pipeline.selection(&options.targets)? {
        if let Some(input) = stage.inputs.iter().find(|i| failed.contains(&i.as_str())) {
            let why = format!("skipped: input `{input}` failed");
            events.warn(&format!("stage `{}` {why}", stage.name));
            failures.push(format!("stage `{}` {why}", stage.name));
            failed.push(&stage.name);
            steps.push(Step {
                stage: stage.name.clone(),
                runs: false,
                why,
                points: None,
            });
            continue;
        }
        let forced =
            options.force && (options.targets.is_empty() || options.targets.contains(&stage.name));
        let current = state(pipeline, results, &options.figures, stage);
        let why = match (&current, forced) {
            (State::Fresh, false) => {
                // A dry run's caller lists every stage itself: no second line for this one.
                if !options.dry_run {
                    events.stage_skipped(&stage.name);
                }
                steps.push(Step {
                    stage: stage.name.clone(),
                    runs: false,
                    why: "fresh".into(),
                    points: None,
                });
                continue;
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
        let points = match stage.get::<Sweep>() {
            Some(sweep) => Some((sweep.count(), sweep.cached(&store)?)),
            None => None,
        };
        steps.push(Step {
            stage: stage.name.clone(),
            runs: true,
            why: why.clone(),
            points,
        });
        if options.dry_run {
            continue;
        }
        events.stage_started(&stage.name, &why);
        match execute(pipeline, stage, options, &store, events) {
            Ok((summary, partial)) => {
                for failure in &partial {
                    events.warn(&format!("stage `{}`: {failure}", stage.name));
                }
                failures.extend(
                    partial
                        .into_iter()
                        .map(|f| format!("stage `{}`: {f}", stage.name)),
                );
                events.stage_finished(&stage.name, &summary);
            }
            // A stage that cannot produce its output stops only what depends on it.
            Err(e @ PipelineError::Stage { .. }) => {
                events.warn(&e.to_string());
                failures.push(e.to_string());
                failed.push(&stage.name);
            }
            Err(e) => return Err(e),
        }
    }
    if failures.is_empty() {
        Ok(steps)
    } else {
        Err(PipelineError::Failed { failures })
    }
}

fn execute(
    pipeline: &Pipeline,
    stage: &Stage,
    options: &RunOptions,
    store: &PointStore,
    events: &dyn Events,
) -> Result<(String, Vec<String>)> {
    let results = &options.results;
    let output = stage.spec.run(&Context {
        stage,
        pipeline,
        results,
        figures: &options.figures,
        store,
        events,
    })?;
    let manifest = manifest_for(pipeline, stage, output.summary.clone());
    let rows = output.frame.height();
    table::write(&output_path(results, &stage.name), output.frame, &manifest)?;
    let count = |k: &str| output.summary.get(k).and_then(|v| v.as_u64());
    let line = match (count("points"), count("failed")) {
        (Some(points), Some(failed)) => format!("{rows} rows, {points} points, {failed} failed"),
        _ => format!("{rows} rows"),
    };
    Ok((line, output.failures))
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
        params: stage.params.clone(),
        inputs: stage
            .inputs
            .iter()
            .map(|i| (i.clone(), pipeline.key(i).to_string()))
            .collect::<BTreeMap<_, _>>(),
        summary,
        checksum: None,
    }
}
