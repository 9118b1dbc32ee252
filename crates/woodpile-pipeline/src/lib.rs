//! The figure pipeline: stages declared in TOML (`pipeline/*.toml`), forming a DAG, each
//! writing one parquet table under `results/` whose metadata records its cache key and
//! everything the key was computed from.
//!
//! - [`kind`]: the `Kind` trait every stage kind implements, and `KINDS`, the one list of them.
//! - [`stage`], [`pipeline`]: parse stage files, check the DAG, compute the keys.
//! - [`sweep`] (with [`grid`], [`template`], [`points`]): simulate parameter grids, cached
//!   per scene so that overlapping and interrupted sweeps never repeat a simulation.
//! - [`spacetime`]: site velocities over time for space-time maps (paper Figs. 3, 8).
//! - [`reduce`]: read fractions at a time, maximise over axes.
//! - [`optimize`]: Nelder–Mead refinement of a grid maximum, simulating between grid points.
//! - [`fit`]: Levenberg–Marquardt fits of the paper's power and tanh forms (the numerics are
//!   `woodpile-analysis`'s, as are Nelder–Mead and the product approximation).
//! - [`approximate`]: the product approximation of two-defect trapping (paper Fig. 9).
//! - [`design`]: inverse design, the best resonator layout by differential evolution.
//! - [`render`]: draw a table as PNG and SVG (through `woodpile-plot`).
//! - [`status`], [`run`]: decide what is stale and why; run it upstream first.
//! - [`lock`]: one writer of a results tree at a time.
//! - [`diff`]: compare two result trees with tolerances (CI's regression check).
//! - [`table`], [`manifest`], [`atomic`], [`canonical`]: parquet IO, self-description, atomic
//!   writes, blake3 keys of canonical JSON.
//!
//! Nothing here prints: progress goes to an [`events::Events`] implementation.
#![warn(missing_docs)]

pub mod approximate;
pub mod atomic;
pub mod canonical;
pub mod design;
pub mod diff;
pub mod error;
pub mod events;
mod fields;
pub mod fit;
pub mod grid;
pub mod kind;
pub mod lock;
pub mod manifest;
pub mod optimize;
pub mod pipeline;
pub mod points;
pub mod reduce;
pub mod render;
pub mod report;
pub mod run;
#[cfg(feature = "testing")]
pub mod sampling;
pub mod shard;
pub mod slurm;
pub mod spacetime;
pub mod stability;
pub mod stage;
pub mod status;
pub mod sweep;
pub mod table;
pub mod template;
pub mod workprecision;

pub use error::{PipelineError, Result};
pub use pipeline::Pipeline;

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
}
