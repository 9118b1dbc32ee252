//! The physics engine of woodpile: a Hertzian chain carrying internal resonators ("mass-with-mass"
//! defects), its energy, and the integrators that advance it.
//!
//! This crate knows nothing about TOML, parquet, files, terminals or threads: it takes validated
//! values and returns numbers or a [`SimError`]. Paper references are to *Lattices With Internal
//! Resonator Defects* (Hauver et al.).
//!
//! The pieces, in the order a simulation uses them:
//! - [`model`]: the chain, its boundary, its resonators and their coupling law (Eqs. 3, 7, 14).
//! - [`force`]: the right-hand side, accelerations from positions.
//! - [`damping`]: dashpots, ground damping and soft ends; [`damped_force`]: their forces, which
//!   depend on velocities, and the dissipated power.
//! - [`energy`]: energy density, total energy, R/T/E_tr fractions (Eq. 5 generalised).
//! - [`integrate`]: the steppers (RK4, Störmer–Verlet, symplectic compositions, DOP853) and the
//!   single driver that owns the time loop, sampling and failure detection.
//! - [`observe`]: sampled time series of the fractions and the space-time velocity field.
//! - [`share`]: the shares (R, T, E_tr, S, D) named once, and which a scene reports.
//! - [`simulation`]: "simulate a scene, return its fractions" as one function.
//! - [`simulation::budget`]: what a run will cost, so an endless one is refused before it starts.
//! - [`units`]: the dimensional form (SI in, dimensionless eps and kappa out).
#![warn(missing_docs)]

mod chain_force;
pub mod contact;
pub mod damped_force;
pub mod damping;
mod dofs;
pub mod energy;
mod error;
pub mod force;
pub mod integrate;
pub mod model;
pub mod observe;
pub mod restitution;
pub mod rods;
pub mod share;
pub mod simd;
pub mod simulation;
#[cfg(any(test, feature = "testing"))]
pub mod testing;
pub mod units;

pub use contact::ContactLaw;
pub use damping::{Damping, DashpotLaw};
pub use error::{ModelError, OverBudget, Refusal, SimError, StepSetBy, Unverified};
pub use model::{Boundary, Coupling, End, Model, Resonator};
pub use share::{Share, ShareSet};
