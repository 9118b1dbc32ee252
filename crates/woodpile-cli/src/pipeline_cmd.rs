//! `woodpile run`, `woodpile status` and `woodpile diff`: the figure pipeline's commands.

use std::path::PathBuf;

use woodpile_pipeline::diff::{diff, DiffOptions, DiffReport, Tolerance};
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::status::{state, State};
use woodpile_pipeline::{Pipeline, PipelineError};

use crate::progress::Progress;
use crate::Failure;

/// Where the pipeline lives.
#[derive(Debug, clap::Args)]
pub(crate) struct Locations {
    /// Directory of stage files.
    #[arg(long, default_value = "pipeline")]
    pipeline: PathBuf,
    /// Results tree: stage tables and the point cache.
    #[arg(long, default_value = "results")]
    results: PathBuf,
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
    #[command(flatten)]
    at: Locations,
}

/// Arguments of `woodpile status`.
#[derive(Debug, clap::Args)]
pub(crate) struct StatusArgs {
    /// Exit 1 unless every stage is fresh (CI: committed results must match the stage files).
    #[arg(long)]
    check: bool,
    #[command(flatten)]
    at: Locations,
}

/// Arguments of `woodpile diff`.
#[derive(Debug, clap::Args)]
pub(crate) struct DiffArgs {
    /// A result file or tree.
    a: PathBuf,
    /// The result file or tree to compare with.
    b: PathBuf,
    /// Absolute tolerance of every column.
    #[arg(long, default_value_t = 0.0)]
    abs: f64,
    /// Relative tolerance of every column.
    #[arg(long, default_value_t = 0.0)]
    rel: f64,
    /// A column's own tolerance: COLUMN=ABS or COLUMN=ABS,REL (repeatable).
    #[arg(long = "tol", value_name = "COLUMN=ABS[,REL]")]
    tolerances: Vec<String>,
}

fn load(at: &Locations) -> Result<Pipeline, Failure> {
    Pipeline::load(&at.pipeline).map_err(Failure::input)
}

fn stage_failure(e: PipelineError) -> Failure {
    match e {
        PipelineError::Definition { .. }
        | PipelineError::Syntax { .. }
        | PipelineError::UnknownStage { .. } => Failure::input(e),
        _ => Failure::simulation(e),
    }
}

pub(crate) fn run_command(args: &RunArgs) -> Result<(), Failure> {
    let pipeline = load(&args.at)?;
    let options = RunOptions {
        targets: args.stages.clone(),
        force: args.force,
        dry_run: args.dry_run,
        results: args.at.results.clone(),
    };
    let progress = Progress::new();
    let steps = run(&pipeline, &options, &progress).map_err(stage_failure)?;
    if args.dry_run {
        for step in &steps {
            let points = step
                .points
                .map(|(n, cached)| {
                    format!(" [{n} scenes: {cached} cached, {} to simulate]", n - cached)
                })
                .unwrap_or_default();
            let verb = if step.runs { "would run" } else { "fresh    " };
            println!("{verb} {}: {}{points}", step.stage, step.why);
        }
    }
    Ok(())
}

pub(crate) fn status_command(args: &StatusArgs) -> Result<(), Failure> {
    let pipeline = load(&args.at)?;
    let width = pipeline
        .stages()
        .iter()
        .map(|s| s.name.len())
        .max()
        .unwrap_or(5);
    println!("{:width$}  {:7}  {:7}  why", "stage", "kind", "state");
    let mut not_fresh = 0;
    for stage in pipeline.stages() {
        let st = state(&pipeline, &args.at.results, stage);
        not_fresh += usize::from(st != State::Fresh);
        println!(
            "{:width$}  {:7}  {:7}  {}",
            stage.name,
            stage.spec.kind(),
            st.label(),
            st.why()
        );
    }
    if args.check && not_fresh > 0 {
        return Err(Failure::new(
            1,
            anyhow::anyhow!(
                "{not_fresh} stage(s) not fresh in {}: run `make figures`",
                args.at.results.display()
            ),
        ));
    }
    Ok(())
}

/// Exit 0 when A and B agree, 1 when they differ beyond tolerance.
pub(crate) fn diff_command(args: &DiffArgs) -> Result<bool, Failure> {
    let mut options = DiffOptions {
        default: Tolerance {
            abs: args.abs,
            rel: args.rel,
        },
        ..Default::default()
    };
    for spec in &args.tolerances {
        let (column, tol) = parse_tolerance(spec)
            .map_err(|reason| Failure::input(anyhow::anyhow!("--tol `{spec}`: {reason}")))?;
        options.columns.insert(column, tol);
    }
    let report = diff(&args.a, &args.b, &options).map_err(Failure::input)?;
    print_report(&report);
    Ok(report.agrees())
}

fn parse_tolerance(spec: &str) -> Result<(String, Tolerance), String> {
    let (column, values) = spec.split_once('=').ok_or("expected COLUMN=ABS[,REL]")?;
    let mut parts = values.split(',');
    let number = |s: Option<&str>| -> Result<f64, String> {
        s.unwrap_or("0")
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|x| *x >= 0.0)
            .ok_or_else(|| "tolerances are numbers >= 0".to_string())
    };
    let abs = number(parts.next())?;
    let rel = number(parts.next())?;
    Ok((column.to_string(), Tolerance { abs, rel }))
}

fn print_report(report: &DiffReport) {
    for p in &report.problems {
        println!("problem: {p}");
    }
    if !report.worst.is_empty() {
        println!(
            "{:<28} {:<16} {:>8} {:>24} {:>24} {:>10} {:>10} {:>8}",
            "file", "column", "row", "a", "b", "abs", "rel", "excess"
        );
        for d in &report.worst {
            println!(
                "{:<28} {:<16} {:>8} {:>24} {:>24} {:>10.3e} {:>10.3e} {:>8.2}",
                d.file, d.column, d.row, d.a, d.b, d.abs, d.rel, d.excess
            );
        }
    }
    println!(
        "{} files, {} values compared: {} beyond tolerance, {} structural problems -> {}",
        report.files,
        report.values,
        report.beyond,
        report.problems.len(),
        if report.agrees() { "AGREE" } else { "DIFFER" }
    );
}
