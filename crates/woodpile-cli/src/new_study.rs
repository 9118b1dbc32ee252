//! `woodpile new study NAME`: a study folder that runs as written. A scene file, a sweep of
//! it over a log-spaced eps axis (the scene named by reference), a read-out of the fractions
//! and a figure, with a `woodpile.toml` so that every command works inside the folder with no
//! directory flags.

use std::path::{Path, PathBuf};

use anyhow::anyhow;

use crate::Failure;

/// Arguments of `woodpile new`.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// What to make: `study`.
    what: String,
    /// The new folder.
    name: PathBuf,
}

const SCENE: &str = r#"# The base scene of this study (the format: docs/scene.md of woodpile). Stages name it by
# reference and override what they vary.
[chain]
n = 60
boundary = "fixed"

[impulse]
site = -20
velocity = 1.0

[[defect]]
site = 0
eps = 1.0
kappa = 1.0

[run]
t_end = 80.0
method = "auto"
tolerance = 1e-6
sample_every = 1.0
"#;

const SWEEP: &str = r#"# The base scene's defect over 25 log-spaced mass ratios.
kind = "sweep"
description = "E_tr, R, T over eps for one defect at site 0"

[axes]
eps = { from = 0.1, to = 100.0, count = 25, log = true }

[scene]
file = "scenes/base.toml"
[[scene.defect]]
site = 0
eps = "$eps"
kappa = 1.0
"#;

const REDUCE: &str = r#"# The fractions at the end of the run.
kind = "reduce"
description = "fractions at t = 80"
inputs = ["sweep"]
at = 80.0
"#;

const FIGURE: &str = r#"kind = "render"
description = "R, T and E_tr against eps"
inputs = ["fractions"]
title = "one defect at site 0, read out at t = {fractions.params.at}"
# eps is log-spaced: a log axis spreads it evenly.
x_scale = "log"
[lines]
x = "eps"
y = ["R", "T", "E_tr"]
x_label = "\\varepsilon = m/M"
y_label = "energy fraction"
"#;

const DEFAULTS: &str = r#"# Not a stage: keys every stage of a kind starts from; a stage's own keys override them.
# Figures print at a journal's width (86 mm for one panel, 178 mm for more) with 8-pt text.
[render.style]
dpi = 300
font_pt = 8
legend = "best"

# How names are written in the figures (the tables keep the names).
[render.labels]
E_tr = "E_{tr}"
"#;

const PROJECT: &str = r#"# This folder is a woodpile project: `woodpile run`, `status` and `diff` work here (and in any
# folder below) without directory flags. Each key is a folder relative to this file.
pipeline = "pipeline"
results = "results"
figures = "figures"
"#;

const README: &str = r#"# A woodpile study

```sh
woodpile run            # simulate the sweep, read it out, draw figures/figure.png
woodpile status         # what is fresh or stale, and why
woodpile run --set fractions.at=40.0   # a variant without editing a file
```

`scenes/base.toml` is the scene; `pipeline/` holds the stages (sweep, reduce, render) and
`pipeline/defaults.toml` the figures' size, type and labels. Edit a stage and `woodpile run`
recomputes only what changed.
"#;

pub(crate) fn run(args: &Args) -> Result<(), Failure> {
    if args.what != "study" {
        return Err(Failure::input(anyhow!(
            "`woodpile new {}`: the only thing `new` makes is a `study`",
            args.what
        )));
    }
    let root = &args.name;
    if std::fs::symlink_metadata(root).is_ok() {
        return Err(Failure::input(anyhow!(
            "{}: already exists; name a new folder",
            root.display()
        )));
    }
    let files: [(&str, &str); 7] = [
        ("woodpile.toml", PROJECT),
        ("README.md", README),
        ("scenes/base.toml", SCENE),
        ("pipeline/sweep.toml", SWEEP),
        ("pipeline/fractions.toml", REDUCE),
        ("pipeline/figure.toml", FIGURE),
        ("pipeline/defaults.toml", DEFAULTS),
    ];
    for (name, text) in files {
        write(&root.join(name), text)?;
    }
    eprintln!(
        "new study in {}: cd there and run `woodpile run`",
        root.display()
    );
    Ok(())
}

fn write(path: &Path, text: &str) -> Result<(), Failure> {
    woodpile_files::atomic::write(path, text.as_bytes()).map_err(Failure::input)
}
