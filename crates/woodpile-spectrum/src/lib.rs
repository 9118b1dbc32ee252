//! woodpile-spectrum (in progress).
#![warn(missing_docs)]

pub mod bands;
pub mod chain;
pub mod condense;
mod error;

pub use error::SpectrumError;
mod matrices;
pub mod modes;
pub mod shape;
pub mod damped;
pub mod localised;
mod tridiagonal;
pub mod transmission;
pub mod linearise;
