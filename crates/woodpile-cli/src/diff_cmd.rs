//! `woodpile diff`: two result files or trees compared column by column, with tolerances.

use std::path::PathBuf;

use woodpile_pipeline::diff::{diff, DiffOptions, DiffReport, Tolerance};

use crate::Failure;

/// How many beyond-tolerance differences `diff` lists without `--all`.
const LISTED: usize = 20;

/// Arguments of `woodpile diff`.
#[derive(Debug, clap::Args)]
pub(crate) struct DiffArgs {
    /// A result file or tree.
    a: PathBuf,
    /// The result file or tree to compare with.
    b: PathBuf,
    /// Absolute tolerance of every column (a number >= 0, or inf).
    #[arg(long, default_value_t = 0.0, value_parser = tolerance_value)]
    abs: f64,
    /// Relative tolerance of every column (a number >= 0, or inf).
    #[arg(long, default_value_t = 0.0, value_parser = tolerance_value)]
    rel: f64,
    /// A column's own tolerance: COLUMN=ABS or COLUMN=ABS,REL (repeatable).
    #[arg(long = "tol", value_name = "COLUMN=ABS[,REL]")]
    tolerances: Vec<String>,
    /// A column not to compare (repeatable).
    #[arg(long = "ignore", value_name = "COLUMN")]
    ignore: Vec<String>,
    /// Compare key columns (scene_key) too: content hashes, which differ after any parameter change.
    #[arg(long)]
    keys: bool,
    /// List every differing column, within tolerance too, not only the first beyond it.
    #[arg(long)]
    all: bool,
}

/// Arguments of the hidden `woodpile probe-table PATH`.
#[derive(Debug, clap::Args)]
pub(crate) struct ProbeArgs {
    /// The parquet file to decode.
    path: PathBuf,
}

/// `woodpile probe-table PATH`: decodes the file whole, and nothing else. `diff` runs it in a
/// child process on files that are not sealed woodpile tables, so that a file that makes the
/// decoder abort ends the child, not the comparison.
pub(crate) fn probe_command(args: &ProbeArgs) -> Result<(), Failure> {
    woodpile_pipeline::table::read_checked(&args.path)
        .map(|_| ())
        .map_err(Failure::input)
}

/// Decodes `path` in a child `woodpile probe-table`: the reason it cannot be read, if any.
fn probe_in_child(path: &std::path::Path) -> Result<(), String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot find woodpile itself: {e}"))?;
    let out = std::process::Command::new(exe)
        .arg("probe-table")
        .arg(path)
        .stdin(std::process::Stdio::null())
        .output()
        .map_err(|e| format!("cannot start a decoder process: {e}"))?;
    if out.status.success() {
        return Ok(());
    }
    let said = String::from_utf8_lossy(&out.stderr);
    let line = said.lines().rev().find(|l| l.starts_with("error: "));
    Err(match (line, out.status.code()) {
        (Some(line), Some(_)) => {
            let reason = line.trim_start_matches("error: ");
            let own = format!("{}: ", path.display());
            reason.strip_prefix(&own).unwrap_or(reason).to_string()
        }
        _ => "the parquet decoder failed on it (it ended the process decoding it)".into(),
    })
}

/// Exit 0 when A and B agree, 1 when they differ beyond tolerance.
pub(crate) fn diff_command(args: &DiffArgs) -> Result<bool, Failure> {
    let mut options = DiffOptions {
        default: Tolerance {
            abs: args.abs,
            rel: args.rel,
        },
        ignore: args.ignore.iter().cloned().collect(),
        compare_keys: args.keys,
        probe: Some(probe_in_child),
        ..Default::default()
    };
    for spec in &args.tolerances {
        let (column, tol) = parse_tolerance(spec)
            .map_err(|reason| Failure::input(anyhow::anyhow!("--tol `{spec}`: {reason}")))?;
        if options.columns.insert(column.clone(), tol).is_some() {
            return Err(Failure::input(anyhow::anyhow!(
                "--tol `{spec}`: column `{column}` was given a tolerance already"
            )));
        }
    }
    let report = diff(&args.a, &args.b, &options).map_err(Failure::input)?;
    print_report(&report, args.all);
    Ok(report.agrees())
}

/// A tolerance flag's value: a number >= 0 (inf allowed), never negative or NaN.
fn tolerance_value(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| *x >= 0.0)
        .ok_or_else(|| format!("`{text}` is not a tolerance (a number >= 0 or inf)"))
}

fn parse_tolerance(spec: &str) -> Result<(String, Tolerance), String> {
    const FORM: &str = "expected COLUMN=ABS or COLUMN=ABS,REL";
    let (column, values) = spec.split_once('=').ok_or(FORM)?;
    if column.trim().is_empty() {
        return Err(format!("no column name; {FORM}"));
    }
    let parts: Vec<&str> = values.split(',').collect();
    if parts.len() > 2 {
        return Err(format!("{} numbers; {FORM}", parts.len()));
    }
    let abs = tolerance_value(parts[0])?;
    let rel = parts.get(1).map_or(Ok(0.0), |r| tolerance_value(r))?;
    Ok((column.trim().to_string(), Tolerance { abs, rel }))
}

fn print_report(report: &DiffReport, all: bool) {
    for p in &report.parameters {
        say!("parameter: {p}");
    }
    for p in &report.problems {
        say!("problem: {p}");
    }
    if !report.skipped.is_empty() {
        let names: Vec<&str> = report.skipped.iter().map(String::as_str).collect();
        say!(
            "not compared: {} (--keys, or drop --ignore, to compare)",
            names.join(", ")
        );
    }
    let beyond = report.worst.iter().filter(|d| d.excess > 1.0).count();
    let shown: Vec<_> = if all {
        report.worst.iter().collect()
    } else {
        report.worst.iter().take(beyond.min(LISTED)).collect()
    };
    if !shown.is_empty() {
        say!(
            "{:<28} {:<16} {:>8} {:>24} {:>24} {:>10} {:>10} {:>8}",
            "file",
            "column",
            "row",
            "a",
            "b",
            "abs",
            "rel",
            "excess"
        );
        for d in &shown {
            say!(
                "{:<28} {:<16} {:>8} {:>24} {:>24} {:>10.3e} {:>10.3e} {:>8.2}",
                d.file,
                d.column,
                d.row,
                d.a,
                d.b,
                d.abs,
                d.rel,
                d.excess
            );
        }
    }
    let hidden = report.worst.len() - shown.len();
    if hidden > 0 {
        say!(
            "... {hidden} more differing column(s){} (--all lists them)",
            if beyond > shown.len() {
                ""
            } else {
                " within tolerance"
            }
        );
    }
    say!(
        "{} files, {} values compared: {} beyond tolerance, {} structural problems -> {}",
        report.files,
        report.values,
        report.beyond,
        report.problems.len(),
        if report.agrees() { "AGREE" } else { "DIFFER" }
    );
}
