//! What a stage kind is: the [`Kind`] trait every kind implements, and [`KINDS`], the one list
//! of them. A new kind is one module (its parameters, `parse`, and `impl Kind`) plus one line
//! in [`KINDS`]: parsing, the unknown-kind error, the DAG's input checks, running, freshness
//! and the generated reference (`docs/stage-kinds.md`) all go through these two.

use std::any::Any;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use polars::prelude::DataFrame;

use crate::error::Result;
use crate::events::Events;
use crate::fields::Fields;
use crate::manifest::Manifest;
use crate::pipeline::Pipeline;
use crate::points::PointStore;
use crate::stage::Stage;
use crate::status::output_path;
use crate::{table, Output};

/// A stage kind: its parameters, and what it does with them.
pub trait Kind: std::fmt::Debug + Send + Sync + Any {
    /// Checks the stage's inputs against their kinds (`inputs` reaches them by name). The
    /// error is (key, reason); the caller names the stage file.
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck;

    /// Computes the stage's table (and writes any files of its own).
    fn run(&self, ctx: &Context<'_>) -> Result<Output>;

    /// Files the stage writes besides its table: a stage is fresh only when they exist.
    fn files(&self, _stage: &str, _results: &Path, _figures: &Path) -> Vec<PathBuf> {
        Vec::new()
    }

    /// How the stage shares the machine with the other stages of a run ([`Sharing`]).
    fn sharing(&self) -> Sharing {
        Sharing::Shared
    }
}

/// How a stage shares the machine with the other stages a run has ready at the same time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sharing {
    /// Mostly one thread: runs beside anything (reductions, fits, figures, single scenes).
    Shared,
    /// Keeps every core busy by itself (a sweep's scenes, the design search): one such stage
    /// at a time, in pipeline order, so that a sweep whose scenes an earlier one shares (F5
    /// and F4) finds them cached instead of simulating them again alongside it.
    Parallel,
    /// Times itself: runs with nothing else, so that its timings are one quiet core's.
    Alone,
}

/// The outcome of [`Kind::check_inputs`]: `Err((key, reason))`.
pub type KindCheck = std::result::Result<(), (String, String)>;

/// Parses a kind's keys; `inputs` are the stage's inputs.
pub(crate) type Parse = fn(&mut Fields<'_>, &[String]) -> Result<Arc<dyn Kind>>;

/// Every kind, in pipeline order: its name in stage files, and its parser. Each kind is
/// documented by its module (`src/kinds/<name>.rs`), from which `docs/stage-kinds.md` is generated.
pub(crate) const KINDS: &[(&str, Parse)] = &[
    ("sweep", |f, _| Ok(Arc::new(crate::sweep::Sweep::parse(f)?))),
    ("spacetime", |f, _| {
        Ok(Arc::new(crate::spacetime::SpaceTime::parse(f)?))
    }),
    ("reduce", |f, _| {
        Ok(Arc::new(crate::reduce::Reduce::parse(f)?))
    }),
    ("optimize", |f, _| {
        Ok(Arc::new(crate::optimize::Optimize::parse(f)?))
    }),
    ("fit", |f, _| Ok(Arc::new(crate::fit::FitStage::parse(f)?))),
    ("approximate", |f, _| {
        Ok(Arc::new(crate::approximate::Approximate::parse(f)?))
    }),
    ("render", |f, i| {
        Ok(Arc::new(crate::render::Render::parse(f, i)?))
    }),
    ("report", |f, _| {
        Ok(Arc::new(crate::report::Report::parse(f)?))
    }),
    ("workprecision", |f, _| {
        Ok(Arc::new(crate::workprecision::WorkPrecision::parse(f)?))
    }),
    ("stability", |f, _| {
        Ok(Arc::new(crate::stability::Stability::parse(f)?))
    }),
    ("design", |f, _| {
        Ok(Arc::new(crate::design::Design::parse(f)?))
    }),
];

/// The name of every kind, in pipeline order.
pub fn names() -> impl Iterator<Item = &'static str> {
    KINDS.iter().map(|(name, _)| *name)
}

/// The other stages of a pipeline, as a stage's input check sees them.
pub struct Inputs<'a> {
    pub(crate) by_name: &'a BTreeMap<&'a str, &'a Stage>,
}

impl Inputs<'_> {
    /// The stage called `name` (an input check runs after every input was found).
    pub fn stage(&self, name: &str) -> Option<&Stage> {
        self.by_name.get(name).copied()
    }

    /// Stage `name` as kind `K`, if it is one.
    pub fn get<K: Kind>(&self, name: &str) -> Option<&K> {
        self.stage(name)?.get::<K>()
    }

    /// The kind name of stage `name`.
    pub fn kind_of(&self, name: &str) -> &str {
        self.stage(name).map_or("unknown", |s| s.kind)
    }
}

/// A check that the stage reads nothing: the kinds that compute from their own parameters.
pub fn no_inputs(stage: &Stage) -> KindCheck {
    match stage.inputs.is_empty() {
        true => Ok(()),
        false => Err((
            "inputs".into(),
            format!("a {} stage reads no other stage", stage.kind),
        )),
    }
}

/// What a running stage may use.
pub struct Context<'a> {
    /// The stage.
    pub stage: &'a Stage,
    /// The pipeline it belongs to.
    pub pipeline: &'a Pipeline,
    /// The results tree.
    pub results: &'a Path,
    /// Where figures go.
    pub figures: &'a Path,
    /// The point cache.
    pub store: &'a PointStore,
    /// Progress.
    pub events: &'a dyn Events,
}

impl Context<'_> {
    /// The stage's name.
    pub fn name(&self) -> &str {
        &self.stage.name
    }

    /// The table of input `name`, checked against its seal.
    pub fn input(&self, name: &str) -> Result<DataFrame> {
        table::read(&output_path(self.results, name))
    }

    /// The table of input `name` with its manifest.
    pub fn input_with_manifest(&self, name: &str) -> Result<(DataFrame, Manifest)> {
        table::read_with_manifest(&output_path(self.results, name))
    }
}
