//! The files of a results tree, with no simulator, so that the pipeline engine can cache,
//! lock, seal and diff a tree without linking what computes it.
//!
//! - [`atomic`], [`regular`], [`layout`]: writes that land whole or not at all, reads of
//!   regular files only, and where everything of a results tree lives.
//! - [`key`]: the blake3 [`key::Key`] of a canonical JSON text, and the code version every key
//!   includes.
//! - [`points`]: the point directory ([`points::PointsDir`]) and the [`points::PointStats`] a
//!   set of points reports; what a point holds is `woodpile_points`'.
//! - [`rows`]: tables as rows of typed cells.
//! - [`input`]: an input file read as text, and its errors told without echoing it.
#![warn(missing_docs)]

pub mod atomic;
pub mod error;
pub mod input;
pub mod key;
pub mod layout;
pub mod points;
pub mod regular;
pub mod rows;

pub use error::{FileError, Result};
pub use key::Key;
pub use points::{PointStats, PointsDir};
