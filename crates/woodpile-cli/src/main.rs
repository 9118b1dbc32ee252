//! `woodpile`: the command line. The only place that prints or picks exit codes.
//!
//! Exit codes: 0 success; 2 bad input (unreadable file, malformed or invalid scene, bad
//! arguments); 3 the simulation failed (blow-up, energy drift, tolerance not reachable). Errors
//! go to stderr as one `error: ...` line naming the file, key and reason.
#![allow(clippy::print_stdout)]

mod simulate;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Granular chains with internal resonator defects: simulate scenes, reproduce the paper.
#[derive(Debug, Parser)]
#[command(name = "woodpile", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Simulate one scene file and print its energy fractions as one JSON object.
    Simulate(simulate::Args),
}

/// A failure with the exit code it maps to.
pub(crate) struct Failure {
    code: u8,
    error: anyhow::Error,
}

impl Failure {
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
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Simulate(args) => simulate::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("error: {:#}", f.error);
            ExitCode::from(f.code)
        }
    }
}
