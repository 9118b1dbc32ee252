//! Scene to cached point, with no polars, so that the stage kinds and the Python module turn
//! a scene into the same point, under the same key, in the same file, with the same table
//! columns. The files themselves (atomic writes, the tree's layout, the point directory, key
//! hashing) are `woodpile_files`', which the engine links without the simulator.
//!
//! - [`canonical`]: a scene's canonical JSON, which its key hashes.
//! - [`point`]: one scene simulated into a [`point::PointData`] (or why it failed), its key,
//!   and the statistics a set of points reports.
//! - [`store`]: the [`store::PointStore`], one checksummed file per point.
//! - [`rows`]: a sweep's table rows, the one row schema of the sweep stage and of Python's
//!   `sweep`.
#![warn(missing_docs)]

pub mod canonical;
pub mod point;
pub mod rows;
pub mod store;

pub use point::{
    point_key, simulate_point, simulate_points_until, stats_of, PointData, PointResult, Shares,
};
pub use store::{Fetched, PointStore};
