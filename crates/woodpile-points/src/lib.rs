//! Scene to cached point, in one place and with no polars, so that the pipeline engine, the
//! stage kinds and the Python module turn a scene into the same point, under the same key, in
//! the same file, with the same table columns.
//!
//! - [`canonical`]: a scene's canonical JSON and the blake3 [`canonical::Key`] of it.
//! - [`point`]: one scene simulated into a [`point::PointData`] (or why it failed), its key,
//!   and the [`point::PointStats`] a set of points reports.
//! - [`store`]: the [`store::PointStore`], one checksummed file per point.
//! - [`rows`]: a sweep's table as columns, the one row schema of the sweep stage and of
//!   Python's `sweep`.
//! - [`atomic`], [`regular`], [`layout`]: writes that land whole or not at all, reads of
//!   regular files only, and where everything of a results tree lives.
#![warn(missing_docs)]

pub mod atomic;
pub mod canonical;
pub mod error;
pub mod layout;
pub mod point;
pub mod regular;
pub mod rows;
pub mod store;

pub use canonical::Key;
pub use error::{FileError, Result};
pub use point::{
    point_key, simulate_point, simulate_points_until, PointData, PointResult, PointStats, Shares,
};
pub use store::{Fetched, PointStore};
