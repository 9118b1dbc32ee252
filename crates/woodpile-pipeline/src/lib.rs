//! The figure pipeline's engine: stages declared in TOML (`pipeline/*.toml`), forming a DAG,
//! each writing one parquet table under `results/` whose metadata records its cache key and
//! everything the key was computed from. The engine names no stage kind: it is handed a
//! [`kind::Registry`] (`woodpile_stages::KINDS` is the paper's).
//!
//! - [`kind`]: the [`kind::Kind`] trait every stage kind implements, and the [`kind::Context`]
//!   a running stage is given.
//! - [`stage`], [`pipeline`], [`variant`]: parse stage files (and `--set` variants), check the
//!   DAG, compute the keys.
//! - [`status`], [`run`]: decide what is stale and why; run it upstream first.
//! - The point directory ([`woodpile_files::PointsDir`]) is handed to the kinds; turning a
//!   scene into a cached point is theirs (`woodpile_points`), so this crate links no simulator.
//! - [`shard`], [`slurm`]: sweeps split across a cluster and merged.
//! - [`lock`]: one writer of a results tree at a time.
//! - [`diff`]: compare two result trees with tolerances (CI's regression check).
//! - [`table`], [`manifest`], [`sealed_files`]: parquet IO and row tables, self-description,
//!   the checksums of a stage's other files.
//!
//! Nothing here prints: progress goes to an [`events::Events`] implementation.
#![warn(missing_docs)]

pub mod diff;
pub mod error;
pub mod events;
pub mod fields;
pub mod kind;
pub mod lock;
pub mod manifest;
pub mod params;
pub mod pipeline;
pub mod run;
pub mod sealed_files;
pub mod shard;
pub mod slurm;
pub mod stage;
pub mod status;
pub mod table;
pub mod variant;

pub use error::{PipelineError, Result};
pub use kind::Output;
pub use pipeline::Pipeline;
