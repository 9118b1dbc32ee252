//! `woodpile run`, `woodpile status` and `woodpile diff`: the figure pipeline's commands.

use std::path::PathBuf;
use woodpile_stages::KINDS;

use woodpile_files::atomic;
use woodpile_files::layout::output_path;
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::shard::{merge, run_shard, Shard};
use woodpile_pipeline::slurm::SlurmJob;
use woodpile_pipeline::status::{state, State};
use woodpile_pipeline::variant::{variant_name, Set};
use woodpile_pipeline::{Pipeline, PipelineError};

use crate::project::Dirs;

use crate::progress::Progress;
use crate::reports::{RunReport, StageRun, StageStatus};
use crate::Failure;

/// Where the pipeline lives. Each folder comes from its flag, else its environment variable,
/// else the nearest `woodpile.toml`, else `pipeline/`, `results/`, `figures/` here.
#[derive(Debug, clap::Args)]
pub(crate) struct Locations {
    /// Directory of stage files [env: WOODPILE_PIPELINE] [default: pipeline].
    #[arg(long)]
    pipeline: Option<PathBuf>,
    /// Results tree: stage tables and the point cache [env: WOODPILE_RESULTS] [default: results].
    #[arg(long)]
    results: Option<PathBuf>,
    /// Where render stages write their PNG and SVG figures [env: WOODPILE_FIGURES] [default: figures].
    #[arg(long)]
    figures: Option<PathBuf>,
}

impl Locations {
    fn dirs(&self) -> Result<Dirs, Failure> {
        crate::project::resolve(
            self.pipeline.as_deref(),
            self.results.as_deref(),
            self.figures.as_deref(),
        )
        .map_err(Failure::input)
    }
}

/// Arguments of `woodpile run`.
#[derive(Debug, clap::Args)]
pub(crate) struct RunArgs {
    /// Stages to bring up to date (with everything upstream); none means all.
    stages: Vec<String>,
    /// Re-run the named stages (all, if none named) even when fresh.
    #[arg(long)]
    force: bool,
    /// List what would run and why; run nothing.
    #[arg(long)]
    dry_run: bool,
    /// Compute only shard I of N of one sweep into a part file (see `woodpile merge`). Inside
    /// a SLURM array job the shard comes from SLURM_ARRAY_TASK_ID / SLURM_ARRAY_TASK_COUNT.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    /// Take the shard from SLURM's array variables (SLURM_ARRAY_TASK_ID, _COUNT, _MIN): a
    /// plain `run` inside a SLURM job never shards unless asked.
    #[arg(long, conflicts_with = "shard")]
    shard_from_env: bool,
    /// Run a variant of a stage with a key of its file set, without editing it: `--set
    /// f4_fractions.at=120` runs `f4_fractions--at-120` (a value whose name would lose characters,
    /// such as `120.0`, is followed by a short hash), with its own key and output
    /// (repeatable; each stage named gets one variant).
    #[arg(long = "set", value_name = "STAGE.KEY=VALUE")]
    sets: Vec<String>,
    /// Print what ran (or would run) as one JSON object on stdout: `stages` (each with
    /// `stage`, `runs`, `why`, `points`, `cached`), `ran`, `fresh`, `scenes_simulated`,
    /// `seconds`. Progress still goes to stderr.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    at: Locations,
}

/// Arguments of `woodpile merge`.
#[derive(Debug, clap::Args)]
pub(crate) struct MergeArgs {
    /// The sharded sweep.
    stage: String,
    #[command(flatten)]
    at: Locations,
}

/// Arguments of `woodpile slurm`.
#[derive(Debug, clap::Args)]
pub(crate) struct SlurmArgs {
    /// The sweep to shard.
    stage: String,
    /// Array tasks (shards).
    #[arg(long)]
    tasks: usize,
    /// SLURM partition.
    #[arg(long)]
    partition: Option<String>,
    /// Time limit per task, SLURM syntax (e.g. 01:00:00).
    #[arg(long)]
    time: Option<String>,
    /// CPUs per task (rayon uses them all).
    #[arg(long, default_value_t = 1)]
    cpus: usize,
    /// Where to write the scripts (and, under logs/, the jobs' output).
    #[arg(long, default_value = "slurm")]
    out: PathBuf,
    #[command(flatten)]
    at: Locations,
}

/// Arguments of `woodpile status`.
#[derive(Debug, clap::Args)]
pub(crate) struct StatusArgs {
    /// Exit 1 unless every stage is fresh (CI: committed results must match the stage files).
    #[arg(long)]
    check: bool,
    /// Print the table as a JSON array of objects (`stage`, `kind`, `state`, `why`).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    at: Locations,
}

fn load(at: &Locations) -> Result<(Pipeline, Dirs), Failure> {
    load_with(at, &[])
}

fn load_with(at: &Locations, sets: &[Set]) -> Result<(Pipeline, Dirs), Failure> {
    let dirs = at.dirs()?;
    for (flag, dir) in [("--results", &dirs.results), ("--figures", &dirs.figures)] {
        if std::fs::metadata(dir).is_ok_and(|m| !m.is_dir()) {
            return Err(Failure::input(anyhow::anyhow!(
                "{flag} {}: not a directory",
                dir.display()
            )));
        }
    }
    let pipeline = Pipeline::load_with(&dirs.pipeline, KINDS, sets).map_err(Failure::input)?;
    Ok((pipeline, dirs))
}

fn stage_failure(e: PipelineError) -> Failure {
    match e {
        PipelineError::Definition { .. }
        | PipelineError::Syntax { .. }
        | PipelineError::UnknownStage { .. }
        | PipelineError::File(woodpile_files::FileError::Refused { .. }) => Failure::input(e),
        _ => Failure::simulation(e),
    }
}

/// The shard asked for: `--shard`, else a SLURM array task's variables when exactly one
/// stage is named.
fn requested_shard(args: &RunArgs) -> Result<Option<Shard>, Failure> {
    let bad = |reason: String| Failure::input(anyhow::anyhow!("--shard: {reason}"));
    let shard = match &args.shard {
        Some(text) => Some(Shard::parse(text).map_err(bad)?),
        None if args.shard_from_env => Some(
            Shard::from_slurm(|k| std::env::var(k).ok())
                .map_err(bad)?
                .ok_or_else(|| bad("--shard-from-env: SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT are not set".into()))?,
        ),
        None => None,
    };
    if shard.is_some() && (args.stages.len() != 1 || args.force || args.dry_run) {
        return Err(bad(
            "name exactly one sweep stage, without --force or --dry-run".into(),
        ));
    }
    Ok(shard)
}

/// `woodpile run`: one shard of a sweep, or the selected stages (and `--set` variants) brought
/// up to date, then what ran told as JSON, a dry run's plan, or a summary line.
pub(crate) fn run_command(args: &RunArgs) -> Result<(), Failure> {
    let sets = args
        .sets
        .iter()
        .map(|text| {
            Set::parse(text)
                .map_err(|reason| Failure::input(anyhow::anyhow!("--set `{text}`: {reason}")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let (pipeline, dirs) = load_with(&args.at, &sets)?;
    if let Some(shard) = requested_shard(args)? {
        return run_one_shard(&pipeline, &args.stages[0], shard, &dirs);
    }
    // With --set, the variants are what runs (with their inputs), besides any stage named.
    let mut targets = args.stages.clone();
    for set in &sets {
        let name = variant_name(&set.stage, &sets);
        if !targets.contains(&name) {
            targets.push(name);
        }
    }
    let options = RunOptions {
        targets,
        force: args.force,
        dry_run: args.dry_run,
        results: dirs.results.clone(),
        figures: dirs.figures.clone(),
    };
    let started = std::time::Instant::now();
    let steps = run(&pipeline, &options, &Progress::new()).map_err(stage_failure)?;
    let scenes: usize = steps.iter().map(|s| s.simulated).sum();
    let report = RunReport {
        dry_run: args.dry_run,
        stages: steps.iter().map(StageRun::of).collect(),
        ran: steps.iter().filter(|s| s.runs).count(),
        fresh: steps.iter().filter(|s| !s.runs).count(),
        scenes_simulated: scenes as u64,
        seconds: started.elapsed().as_secs_f64(),
    };
    if args.json {
        say!(
            "{}",
            crate::reports::json_text(&report, false).map_err(Failure::simulation)?
        );
    } else if args.dry_run {
        say_plan(&report);
    }
    if !args.dry_run {
        eprintln!(
            "woodpile run: {} stage(s) run, {} fresh, {} scene(s) simulated, {:.1} s",
            report.ran, report.fresh, report.scenes_simulated, report.seconds
        );
    }
    Ok(())
}

/// `run STAGE --shard I/N`: that shard's points into its part file.
fn run_one_shard(
    pipeline: &Pipeline,
    stage: &str,
    shard: Shard,
    dirs: &Dirs,
) -> Result<(), Failure> {
    let done = run_shard(pipeline, stage, shard, &dirs.results, &Progress::new())
        .map_err(stage_failure)?;
    let what = if done.already_done {
        "already done"
    } else {
        "written"
    };
    eprintln!(
        "shard {shard} of `{stage}` ({} points): {what}: {}",
        done.points,
        done.part.display()
    );
    Ok(())
}

/// A dry run's plan: what would run and why, with the scenes a grid would simulate.
fn say_plan(report: &RunReport) {
    for step in &report.stages {
        let points = match (step.points, step.cached) {
            (Some(n), Some(cached)) => {
                format!(" [{n} scenes: {cached} cached, {} to simulate]", n - cached)
            }
            _ => String::new(),
        };
        if step.runs {
            say!("would run {}: {}{points}", step.stage, step.why);
        } else {
            say!("fresh     {}", step.stage);
        }
    }
}

pub(crate) fn merge_command(args: &MergeArgs) -> Result<(), Failure> {
    let (pipeline, dirs) = load(&args.at)?;
    let parts =
        merge(&pipeline, &args.stage, &dirs.results, &Progress::new()).map_err(stage_failure)?;
    eprintln!(
        "merged {parts} parts of `{}` into {}",
        args.stage,
        output_path(&dirs.results, &args.stage).display()
    );
    Ok(())
}

pub(crate) fn slurm_command(args: &SlurmArgs) -> Result<(), Failure> {
    let (pipeline, dirs) = load(&args.at)?;
    let stage = pipeline.stage(&args.stage).map_err(Failure::input)?;
    let Some(grid) = stage.spec.points() else {
        return Err(Failure::input(anyhow::anyhow!(
            "`{}` is a {} stage: only sweeps are sharded",
            stage.name,
            stage.kind
        )));
    };
    let points = grid.count();
    if args.tasks == 0 || args.cpus == 0 {
        return Err(Failure::input(anyhow::anyhow!(
            "--tasks and --cpus must be at least 1"
        )));
    }
    if args.tasks > points {
        return Err(Failure::input(anyhow::anyhow!(
            "--tasks {}: more tasks than the sweep's {points} points; use at most one task per point",
            args.tasks
        )));
    }
    let absolute = |p: &PathBuf| -> Result<PathBuf, Failure> {
        std::path::absolute(p).map_err(|e| Failure::input(anyhow::anyhow!("{}: {e}", p.display())))
    };
    let binary = std::env::current_exe()
        .map_err(|e| Failure::input(anyhow::anyhow!("cannot locate the woodpile binary: {e}")))?;
    let workdir = absolute(&PathBuf::from("."))?;
    let out = absolute(&args.out)?;
    let logs = out.join("logs");
    let job = SlurmJob {
        stage: &stage.name,
        tasks: args.tasks,
        partition: args.partition.as_deref(),
        time: args.time.as_deref(),
        cpus: args.cpus,
        binary: &binary,
        workdir: &workdir,
        pipeline: &absolute(&dirs.pipeline)?,
        results: &absolute(&dirs.results)?,
        logs: &logs,
    };
    job.validate()
        .map_err(|reason| Failure::input(anyhow::anyhow!(reason)))?;
    let array = out.join(format!("{}.array.sbatch", stage.name));
    let merge = out.join(format!("{}.merge.sbatch", stage.name));
    let submit = out.join(format!("{}.submit.sh", stage.name));
    let write =
        |path: &PathBuf, text: String| atomic::write(path, text.as_bytes()).map_err(Failure::input);
    write(&array, job.array_script())?;
    write(&merge, job.merge_script())?;
    write(&submit, job.submit_script(&array, &merge))?;
    std::fs::create_dir_all(&logs)
        .map_err(|e| Failure::input(anyhow::anyhow!("{}: {e}", logs.display())))?;
    say!("{}", array.display());
    say!("{}", merge.display());
    say!("{}", submit.display());
    eprintln!("submit with: bash {}", submit.display());
    Ok(())
}

pub(crate) fn status_command(args: &StatusArgs) -> Result<(), Failure> {
    let (pipeline, dirs) = load(&args.at)?;
    let width = pipeline
        .stages()
        .iter()
        .map(|s| s.name.len())
        .max()
        .unwrap_or(5);
    let states: Vec<(&woodpile_pipeline::stage::Stage, State)> = pipeline
        .stages()
        .iter()
        .map(|stage| (stage, state(&pipeline, &dirs.results, &dirs.figures, stage)))
        .collect();
    let not_fresh = states.iter().filter(|(_, st)| *st != State::Fresh).count();
    if args.json {
        let rows: Vec<StageStatus> = states
            .iter()
            .map(|(stage, st)| StageStatus {
                stage: stage.name.clone(),
                kind: stage.kind,
                state: st.label(),
                why: st.why(),
            })
            .collect();
        say!(
            "{}",
            crate::reports::json_text(&rows, false).map_err(Failure::simulation)?
        );
    } else {
        say!("{:width$}  {:11}  {:7}  why", "stage", "kind", "state");
        for (stage, st) in &states {
            say!(
                "{:width$}  {:11}  {:7}  {}",
                stage.name,
                stage.kind,
                st.label(),
                st.why()
            );
        }
    }
    if args.check && not_fresh > 0 {
        return Err(Failure::new(
            1,
            anyhow::anyhow!(
                "{not_fresh} stage(s) not fresh in {}: run `make figures`",
                dirs.results.display()
            ),
        ));
    }
    Ok(())
}
