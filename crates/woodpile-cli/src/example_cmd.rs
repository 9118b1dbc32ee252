//! `woodpile example [NAME]`: the example scenes the binary carries. Without a name, one line
//! per example; with one, its TOML on stdout, to save and edit (`woodpile example single_eps10
//! > scene.toml`), so a first run needs no clone of the repository.

use anyhow::anyhow;
use woodpile_scene::examples::{example, summary, EXAMPLES};

use crate::Failure;

/// Arguments of `woodpile example`.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The example to print (without one, the list).
    name: Option<String>,
}

pub(crate) fn run(args: &Args) -> Result<(), Failure> {
    let Some(name) = &args.name else {
        for (name, text) in EXAMPLES {
            say!("{name:<22}{}", summary(text));
        }
        return Ok(());
    };
    let text = example(name).map_err(|reason| Failure::input(anyhow!(reason)))?;
    say!("{}", text.trim_end());
    Ok(())
}
