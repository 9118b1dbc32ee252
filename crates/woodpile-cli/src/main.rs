//! `woodpile`: the command line. The only place that prints or picks exit codes.
//!
//! Exit codes: 0 success; 1 `diff` found differences beyond tolerance; 2 bad input (unreadable
//! file, malformed or invalid scene or stage, bad arguments); 3 a computation failed (blow-up,
//! energy drift, tolerance not reachable, a stage that cannot produce its output). Errors
//! go to stderr as one `error: ...` line naming the file, key and reason.
#![allow(clippy::print_stdout)]

/// `println!` that ends the process quietly when the reader has gone (`woodpile status |
/// head`): std's `println!` panics on a broken pipe. The exit code is 141, a shell's code for
/// a process ended by SIGPIPE, so `set -o pipefail` still sees it. Control characters (from a
/// stage file's keys and values) are written escaped: a cloned project cannot draw on the
/// terminal, or fake a status.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        // Line by line: the text's own line breaks stay (a status table, indented JSON).
        let text = format!($($arg)*)
            .split('\n')
            .map(woodpile_files::input::escape_controls)
            .collect::<Vec<_>>()
            .join("\n");
        let mut out = std::io::stdout().lock();
        if let Err(e) = writeln!(out, "{text}") {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(141);
            }
            eprintln!("error: writing to stdout: {e}");
            std::process::exit(1);
        }
    }};
}
mod diff_cmd;
mod example_cmd;
mod new_study;
mod pipeline_cmd;
mod progress;
mod project;
mod reports;
mod simulate;
mod spectrum;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Granular chains with internal resonator defects: simulate scenes, reproduce the paper.
#[derive(Debug, Parser)]
#[command(name = "woodpile", version = version(), about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Simulate one scene file and print its energy fractions as one JSON object.
    Simulate(simulate::Args),
    /// Print an example scene (`woodpile example single_eps10 > scene.toml`), or list them.
    Example(example_cmd::Args),
    /// The scene's linear picture about its static state: bands, modes, transmission (JSON).
    Spectrum(spectrum::Args),
    /// Bring pipeline stages up to date: stale or missing ones only, upstream first.
    Run(pipeline_cmd::RunArgs),
    /// Show each stage as fresh, stale or missing, and why.
    Status(pipeline_cmd::StatusArgs),
    /// Join the parts of a sharded sweep (`run STAGE --shard I/N`) into its result.
    Merge(pipeline_cmd::MergeArgs),
    /// Write SLURM scripts for a sharded sweep: an array job and a merge job after it.
    Slurm(pipeline_cmd::SlurmArgs),
    /// Compare two result files or trees; exit 1 when they differ beyond tolerance.
    Diff(diff_cmd::DiffArgs),
    /// Make a new study folder that runs as written: `woodpile new study NAME`.
    New(new_study::Args),
    /// Decode one parquet file and exit (what `diff` runs on foreign files, in a child).
    #[command(hide = true)]
    ProbeTable(diff_cmd::ProbeArgs),
}

/// The package version and the numerics revision every cache key includes (`woodpile 0.1.0 r5`):
/// the one place a user reads the code version, so no document has to state it.
fn version() -> &'static str {
    static VERSION: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    VERSION
        .get_or_init(|| {
            woodpile_files::key::code_version()
                .trim_start_matches("woodpile ")
                .to_string()
        })
        .as_str()
}

/// A failure with the exit code it maps to.
pub(crate) struct Failure {
    code: u8,
    error: anyhow::Error,
}

impl Failure {
    /// A failure with its own exit code.
    pub(crate) fn new(code: u8, error: impl Into<anyhow::Error>) -> Self {
        Self {
            code,
            error: error.into(),
        }
    }

    /// Bad input: exit code 2.
    pub(crate) fn input(error: impl Into<anyhow::Error>) -> Self {
        Self {
            code: 2,
            error: error.into(),
        }
    }

    /// The computation failed: exit code 3.
    pub(crate) fn simulation(error: impl Into<anyhow::Error>) -> Self {
        Self {
            code: 3,
            error: error.into(),
        }
    }
}

fn main() -> ExitCode {
    quiet_decoder_panics();
    let cli = Cli::parse();
    if let Err(reason) = start_threads() {
        eprintln!("error: {reason}");
        return ExitCode::from(2);
    }
    let result = match cli.command {
        Command::Simulate(args) => simulate::run(&args),
        Command::Example(args) => example_cmd::run(&args),
        Command::Spectrum(args) => spectrum::run(&args),
        Command::Run(args) => pipeline_cmd::run_command(&args),
        Command::Status(args) => pipeline_cmd::status_command(&args),
        Command::Merge(args) => pipeline_cmd::merge_command(&args),
        Command::Slurm(args) => pipeline_cmd::slurm_command(&args),
        Command::New(args) => new_study::run(&args),
        Command::ProbeTable(args) => diff_cmd::probe_command(&args),
        Command::Diff(args) => match diff_cmd::diff_command(&args) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(1),
            Err(f) => Err(f),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            let line = woodpile_files::input::escape_controls(&one_line(&f.error));
            eprintln!("error: {line}");
            ExitCode::from(f.code)
        }
    }
}

/// Starts the worker threads now, so that a bad `RAYON_NUM_THREADS` (not a number, or more
/// threads than the system gives) is an input error rather than a panic deep inside a run;
/// the simulator is handed the environment's CPU choices first.
fn start_threads() -> Result<(), String> {
    woodpile_scene::cpu::apply_environment();
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = woodpile_scene::threads::asked_threads()? {
        builder = builder.num_threads(n);
    }
    builder
        .build_global()
        .map_err(|e| format!("cannot start the worker threads: {e}"))
}

/// The parquet decoder's worker threads (`polars-*`) panic on some damaged files; each such
/// panic is caught and reported as one error line naming the file, so its message and
/// backtrace are not printed as well. Every other panic is printed as usual.
fn quiet_decoder_panics() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let decoder = std::thread::current()
            .name()
            .is_some_and(|name| name.starts_with("polars"));
        if !decoder {
            default(info);
        }
    }));
}

/// The error and its causes on one line, each cause once: an error that already states its
/// source (`path: reason`) does not repeat it.
fn one_line(error: &anyhow::Error) -> String {
    let mut text = error.to_string();
    for cause in error.chain().skip(1) {
        let cause = cause.to_string();
        let cause = cause.trim_end();
        // Said already, whole or as its last part (a scene error under a stage key).
        let last = cause.rsplit(": ").next().unwrap_or(cause);
        if !text.contains(cause) && !text.contains(last) {
            text.push_str(": ");
            text.push_str(cause);
        }
    }
    text
}
