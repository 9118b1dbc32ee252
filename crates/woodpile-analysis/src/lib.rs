//! The numerics the pipeline's analysis stages run, apart from any table or file: they take
//! numbers and return numbers, so they are tested on their own and reusable outside the
//! pipeline.
//!
//! - [`lm`]: Levenberg–Marquardt fits of the paper's three-parameter forms (power law, tanh).
//! - [`least_squares`]: bounded least squares of any model the caller evaluates, with the
//!   parameters' standard errors (the calibration to a measured trace).
//! - [`nelder_mead`]: derivative-free maximisation, for refining optima between grid points.
//! - [`search`]: differential evolution and random search in the unit cube, seeded.
//! - [`product`]: the paper's product approximation of two-defect trapping and its error
//!   measures.
#![warn(missing_docs)]

pub mod least_squares;
pub mod lm;
pub mod nelder_mead;
pub mod product;
pub mod search;
