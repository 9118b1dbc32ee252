//! What a stage kind is to the engine: the [`Kind`] trait, the [`Registry`] of kinds a
//! pipeline is loaded with, and the [`Stage`] that pairs a stage file with its kind (read from
//! its file by `stage.rs`). The engine names no kind: parsing, the unknown-kind error, the
//! DAG's input checks, running, freshness, dry-run counts and shards all go through these.

use std::any::Any;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use polars::prelude::DataFrame;

use crate::error::{PipelineError, Result};
use crate::events::Events;
use crate::fields::Fields;
use crate::manifest::Manifest;
use crate::table;
use woodpile_files::layout::output_path;
use woodpile_files::{PointStats, PointsDir};

/// A stage kind: its parameters, and what it does with them.
pub trait Kind: std::fmt::Debug + Send + Sync + Any {
    /// Checks the stage's inputs against their kinds (`inputs` reaches them by name). The
    /// error is (key, reason); the caller names the stage file. By default a kind reads no
    /// other stage: it computes from its own parameters ([`no_inputs`]).
    fn check_inputs(&self, stage: &Stage, _inputs: &Inputs<'_>) -> KindCheck {
        no_inputs(stage)
    }

    /// Computes the stage's table (and writes any files of its own).
    fn run(&self, ctx: &Context<'_>) -> Result<Output>;

    /// Files the stage writes besides its table: a stage is fresh only when they exist.
    fn files(&self, _stage: &str, _results: &Path, _figures: &Path) -> Vec<PathBuf> {
        Vec::new()
    }

    /// Files under the project that the stage alone may write, as (key, path relative to the
    /// project): loading refuses two stages that claim the same one.
    fn claims(&self) -> Vec<(&'static str, String)> {
        Vec::new()
    }

    /// How the stage shares the machine with the other stages of a run ([`Sharing`]).
    fn sharing(&self) -> Sharing {
        Sharing::Shared
    }

    /// The stage as a grid of independent points, if it is one: what a dry run counts and what
    /// `--shard` splits across machines.
    fn points(&self) -> Option<&dyn PointGrid> {
        None
    }
}

/// Where a grid's points are computed: for which stage (named in events and warnings), with
/// which point cache, and whom to tell of progress.
#[derive(Clone, Copy)]
pub struct PointsAt<'a> {
    /// The stage's name.
    pub stage: &'a str,
    /// The point directory the points are loaded from and saved to.
    pub points: &'a PointsDir,
    /// Progress and warnings.
    pub events: &'a dyn Events,
}

/// A kind whose table is a block of rows per point of a grid, each point computed on its own
/// and cached in the [`PointsDir`].
pub trait PointGrid {
    /// How many points.
    fn count(&self) -> usize;

    /// How many of them `points` already holds.
    fn cached(&self, points: &PointsDir) -> Result<usize>;

    /// Computes what the directory lacks among the points `indices` (increasing) and returns their
    /// rows (with a `point` column) and statistics: the whole table, or one shard's part.
    fn run_points(&self, at: PointsAt<'_>, indices: &[usize]) -> Result<(DataFrame, PointStats)>;

    /// The manifest summary of the whole grid, given the statistics of all its points.
    fn summary(&self, stats: &PointStats) -> Result<serde_json::Value>;
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

/// The [`KindCheck`] failure of a stage whose `inputs` are not what its kind reads: `why`
/// says what it reads.
pub fn wrong_inputs(why: impl Into<String>) -> KindCheck {
    Err(("inputs".into(), why.into()))
}

/// Parses a kind's keys; `inputs` are the stage's inputs.
pub type Parse = fn(&mut Fields<'_>, &[String]) -> Result<Arc<dyn Kind>>;

/// The kinds a pipeline may use, in pipeline order: each one's name in stage files and its
/// parser. The engine is given one ([`crate::Pipeline::load`]); `woodpile_stages::KINDS` is
/// the paper's.
pub type Registry = [(&'static str, Parse)];

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
        false => wrong_inputs(format!("a {} stage reads no other stage", stage.kind)),
    }
}

/// A parsed stage file.
#[derive(Debug, Clone)]
pub struct Stage {
    /// The name: the file stem.
    pub name: String,
    /// The file it came from.
    pub file: PathBuf,
    /// Free text for `woodpile status` and the README.
    pub description: String,
    /// Upstream stages, in the order given.
    pub inputs: Vec<String>,
    /// Its kind's name (one of the registry's).
    pub kind: &'static str,
    /// What it does: the kind's parameters and behaviour.
    pub spec: Arc<dyn Kind>,
    /// The file's content without `description`, over its kind's defaults: what the key
    /// hashes ([`crate::params::Params::value`]).
    pub params: crate::params::Params,
}

impl Stage {
    /// The stage's parameters as kind `K`, if it is one.
    pub fn get<K: Kind>(&self) -> Option<&K> {
        let any: &dyn std::any::Any = self.spec.as_ref();
        any.downcast_ref::<K>()
    }
}

/// What a running stage may use.
pub struct Context<'a> {
    /// The stage.
    pub stage: &'a Stage,
    /// Every stage upstream of it (reached through [`Context::upstream`]).
    pub(crate) upstream: Vec<&'a Stage>,
    /// The project's root, which data files a stage names (`trace = "data/x.csv"`) are
    /// relative to.
    pub root: &'a Path,
    /// The results tree.
    pub results: &'a Path,
    /// Where figures go.
    pub figures: &'a Path,
    /// The point cache.
    pub points: &'a PointsDir,
    /// Progress.
    pub events: &'a dyn Events,
}

impl Context<'_> {
    /// The stage's name.
    pub fn name(&self) -> &str {
        &self.stage.name
    }

    /// The definition of stage `name`, which must be upstream of this one (an input, or an
    /// input's input): a stage reads the parameters of what it depends on, nothing else.
    pub fn upstream(&self, name: &str) -> Result<&Stage> {
        match self.upstream.iter().find(|s| s.name == name) {
            Some(stage) => Ok(stage),
            None => Err(PipelineError::stage(
                &self.stage.name,
                format!("`{name}` is not upstream of this stage"),
            )),
        }
    }

    /// The table of input `name`, checked against its seal.
    pub fn input(&self, name: &str) -> Result<DataFrame> {
        table::read(&output_path(self.results, name))
    }

    /// The table of input `name` with its manifest.
    pub fn input_with_manifest(&self, name: &str) -> Result<(DataFrame, Manifest)> {
        table::read_with_manifest(&output_path(self.results, name))
    }

    /// The manifest of input `name`, read without decoding its table (`None`: not a woodpile
    /// table).
    pub fn input_manifest(&self, name: &str) -> Result<Option<Manifest>> {
        table::read_manifest(&output_path(self.results, name))
    }

    /// Where upstream stage `name` (an optimiser or a design) wrote its best scene.
    pub fn best_scene(&self, name: &str) -> Result<PathBuf> {
        self.upstream(name)?;
        Ok(woodpile_files::layout::best_path(self.results, name))
    }

    /// This stage's own output manifest from its previous run, if a readable one is there:
    /// what a kind checks before it replaces a file of its own.
    pub fn previous_manifest(&self) -> Option<Manifest> {
        table::read_manifest(&output_path(self.results, self.name()))
            .ok()
            .flatten()
    }

    /// The first `limit` bytes of `path`, one of the files this stage declares, as they are
    /// on disk now (`None`: absent, not a regular file, or unreadable): read without following
    /// a link, as every read of the tree is.
    pub fn existing_head(&self, path: &Path, limit: usize) -> Option<Vec<u8>> {
        let declared = self
            .stage
            .spec
            .files(self.name(), self.results, self.figures);
        if !declared.iter().any(|p| p == path) {
            return None;
        }
        let mut bytes = woodpile_files::regular::read(path, 1 << 26).ok()?;
        bytes.truncate(limit);
        Some(bytes)
    }

    /// Writes `bytes` to `path`, one of the files this stage declares besides its table
    /// ([`Kind::files`]), atomically. The one door through which a kind writes: a file it did
    /// not declare is refused (its checksum would not be recorded, so `status` could not see
    /// it change), and so is a path through a symbolic link below the tree it lies in (a
    /// `docs -> /elsewhere` folder would take the write outside the project).
    pub fn write_file(&self, path: &Path, bytes: &[u8]) -> Result<()> {
        let declared = self
            .stage
            .spec
            .files(self.name(), self.results, self.figures);
        if !declared.iter().any(|p| p == path) {
            return Err(PipelineError::stage(
                self.name(),
                format!("writes {}, which its kind does not declare", path.display()),
            ));
        }
        if let Some(link) = self.link_on_the_way(path) {
            return Err(PipelineError::stage(
                self.name(),
                format!(
                    "{}: {} is a symbolic link; a stage writes only inside the project",
                    path.display(),
                    link.display()
                ),
            ));
        }
        Ok(woodpile_files::atomic::write(path, bytes)?)
    }

    /// The first folder between the tree `path` lies in (the results, the figures, or the
    /// project around them) and `path` that is a symbolic link.
    fn link_on_the_way(&self, path: &Path) -> Option<PathBuf> {
        let project = self.results.parent().unwrap_or_else(|| Path::new(""));
        let root = [self.results, self.figures, project]
            .into_iter()
            .find(|root| path.starts_with(root))?;
        let inside = path.strip_prefix(root).ok()?.parent()?;
        let mut folder = root.to_path_buf();
        for part in inside.components() {
            folder.push(part);
            if std::fs::symlink_metadata(&folder).is_ok_and(|m| m.file_type().is_symlink()) {
                return Some(folder);
            }
        }
        None
    }
}

/// What a stage computed, before it is written with its manifest.
pub struct Output {
    /// The table.
    pub frame: polars::prelude::DataFrame,
    /// Kind-specific facts for the manifest.
    pub summary: serde_json::Value,
    /// What failed inside the stage without stopping it (a fit that did not converge, a
    /// quote that could not be read): recorded in the table, and the run ends non-zero
    /// naming them.
    pub failures: Vec<String>,
    /// For a grid of scenes: its points' statistics (how many, how many failed), which the
    /// run's `done` line reports.
    pub points: Option<PointStats>,
    /// Scenes the stage simulated (not read from the point cache): what a run reports.
    pub simulated: usize,
}

impl Output {
    /// A table and its manifest summary, with nothing failed inside the stage.
    pub fn table(frame: polars::prelude::DataFrame, summary: serde_json::Value) -> Output {
        Output {
            frame,
            summary,
            failures: Vec::new(),
            points: None,
            simulated: 0,
        }
    }

    /// The output of a grid of scenes, whose points' statistics are `stats`.
    pub fn with_points(self, stats: PointStats) -> Output {
        Output {
            points: Some(stats),
            simulated: stats.simulated,
            ..self
        }
    }

    /// The output, with what failed inside the stage without stopping it.
    pub fn with_failures(self, failures: Vec<String>) -> Output {
        Output { failures, ..self }
    }

    /// The output of a stage that simulated `count` scenes outside a grid (a map, a survey,
    /// an optimiser's evaluations).
    pub fn with_simulated(self, count: usize) -> Output {
        Output {
            simulated: count,
            ..self
        }
    }
}
