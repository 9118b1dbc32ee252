//! Four scenes in the lanes of one register: `rkn6-contact` (or `erkn6-contact`) advancing four
//! chains together,
//! each lane doing exactly the operations of the scalar [`super::Rkn`] in its order, so that
//! every lane's run equals its scene's scalar run bit for bit (tested, and `make check` at
//! `--abs 0`).
//!
//! Why: a sweep's neighbouring points are the same chain with other resonator masses or
//! couplings. The scalar step is already four sites wide, but its window edges, its
//! loop-carried force and its bookkeeping are paid once per scene; here they are paid once
//! per four (docs/performance.md, "Scenes in SIMD lanes").
//!
//! What lanes share, and what each keeps ([`LaneChain`]): the chain (sites, walls, resonator
//! sites and exponents, contacts, boundary) is one; each lane has its own masses of the
//! resonators and couplings, its own site masses, its own initial impulse, its own active window, contact corrections, first-same-as-last
//! reuse, failures and observer. The lanes step on the union of their windows: outside its
//! own window a lane is exactly at rest, and working on resting sites changes none of its bits.
//!
//! The lanes step by `rkn6-contact` or by `erkn6-contact`, whose harmonic resonators each lane
//! integrates exactly with its own scalar [`super::exact_resonator::ExactResonators`] (the
//! pair steps read and write one lane through [`Lane`] and [`LaneMut`]).
//!
//! Only conservative chains with constant couplings take lanes (the paper's, or the
//! experiment's: a striker, precompression, per-contact coefficients, any exponent, site
//! masses, soft ends without dashpots); a dissipative or ramped scene steps alone.
//! - [`step`]: the batched DPRKN6 step, its first-same-as-last reuse and exact resonators.
//! - [`force`]: the force loop of four lanes, and its patch at a few sites of one.
//! - [`events`]: each lane's contact-event scan and corrections.
//! - [`drive`]: the fixed-step time loop of four runs, [`drive_lanes`].

mod drive;
mod events;
mod force;
mod step;

pub use drive::drive_lanes;

use super::exact_resonator::{Dofs, DofsMut};
use crate::contact::ChainLaw;
use crate::model::{Coupling, Model};

/// Scenes per batch: the f64 lanes of an AVX2 register.
pub const LANES: usize = 4;

/// One value per lane.
pub(crate) type Lanes = [f64; LANES];

/// Stages of DPRKN6, the tableau the lanes step by.
pub(crate) const S: usize = 6;

/// Every lane at zero.
pub(crate) const ZERO: Lanes = [0.0; LANES];

/// Lane `l` of a batch's vector, read as one state's vector is ([`Dofs`]).
pub(crate) struct Lane<'a>(pub &'a [Lanes], pub usize);

/// Lane `l` of a batch's vector, read and written as one state's vector is ([`DofsMut`]).
pub(crate) struct LaneMut<'a>(pub &'a mut [Lanes], pub usize);

impl Dofs for Lane<'_> {
    #[inline(always)]
    fn at(&self, k: usize) -> f64 {
        self.0[k][self.1]
    }
}

impl Dofs for LaneMut<'_> {
    #[inline(always)]
    fn at(&self, k: usize) -> f64 {
        self.0[k][self.1]
    }
}

impl DofsMut for LaneMut<'_> {
    #[inline(always)]
    fn set(&mut self, k: usize, x: f64) {
        self.0[k][self.1] = x;
    }
}

/// A resonator of the shared chain: its host site and exponent, and each lane's coupling and
/// mass ratio.
#[derive(Debug, Clone)]
pub(crate) struct LaneResonator {
    pub site: usize,
    pub p: u32,
    pub kappa: Lanes,
    pub eps: Lanes,
}

/// The chain the lanes share, with each lane's resonator parameters and site masses.
#[derive(Debug, Clone)]
pub(crate) struct LaneChain {
    pub n_sites: usize,
    pub walls: [bool; 2],
    pub resonators: Vec<LaneResonator>,
    /// The contact law, the same in every lane.
    pub law: ChainLaw,
    /// The springs of soft ends (left, right), the same in every lane.
    pub springs: [Option<f64>; 2],
    /// Each lane's site masses (1 in a lane whose model has none: dividing by 1 changes no
    /// bit); `None` when no lane has any.
    pub masses: Option<Vec<Lanes>>,
}

impl LaneChain {
    /// The shared chain of `models` (one per lane), or `None` when they differ in anything
    /// but their resonators' masses and couplings and their site masses, or when one is not a
    /// conservative chain with constant couplings ([`takes_lanes`]).
    pub fn of(models: &[&Model; LANES]) -> Option<LaneChain> {
        let first = models[0];
        let same_shape = |m: &Model| {
            takes_lanes(m)
                && m.n_sites() == first.n_sites()
                && m.boundary() == first.boundary()
                && m.law() == first.law()
                && m.resonators().len() == first.resonators().len()
                && m.resonators()
                    .iter()
                    .zip(first.resonators())
                    .all(|(r, r0)| r.site == r0.site && r.p == r0.p)
        };
        if !models.iter().all(|m| same_shape(m)) {
            return None;
        }
        let constant = |m: &Model, j: usize| match m.resonators()[j].coupling {
            Coupling::Constant(kappa) => kappa,
            Coupling::Ramp { .. } => unreachable!("a ramped coupling does not take lanes"),
        };
        let resonators = (0..first.resonators().len())
            .map(|j| LaneResonator {
                site: first.resonators()[j].site,
                p: first.resonators()[j].p,
                kappa: std::array::from_fn(|l| constant(models[l], j)),
                eps: std::array::from_fn(|l| models[l].resonators()[j].eps),
            })
            .collect();
        let soft = |end: crate::model::End| end.soft().map(|(spring, _)| spring);
        let boundary = first.boundary();
        let masses = models.iter().any(|m| m.site_masses().is_some()).then(|| {
            (0..first.n_sites())
                .map(|i| std::array::from_fn(|l| models[l].site_mass(i)))
                .collect()
        });
        Some(LaneChain {
            n_sites: first.n_sites(),
            walls: first.walls(),
            resonators,
            law: first.law().clone(),
            springs: [soft(boundary.left()), soft(boundary.right())],
            masses,
        })
    }

    /// Positions (or velocities) per lane: sites, then resonators.
    pub fn n_dof(&self) -> usize {
        self.n_sites + self.resonators.len()
    }
}

/// Set by [`turn_off`].
static OFF: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Runs every scene of this process alone (same results), as an edge asks
/// (`WOODPILE_LANES=off`), so that both paths can be timed on one machine.
pub fn turn_off() {
    OFF.store(true, std::sync::atomic::Ordering::Relaxed);
}

/// Whether scenes may take lanes at all: unless [`turn_off`] was called.
pub fn enabled() -> bool {
    !OFF.load(std::sync::atomic::Ordering::Relaxed)
}

/// Whether `models` (one per lane) can step together: they share a chain that takes lanes.
pub fn shares_a_chain(models: &[&Model; LANES]) -> bool {
    LaneChain::of(models).is_some()
}

/// Whether `model` can run in a lane: a conservative chain (the paper's, or the experiment's
/// with a striker, precompression, per-contact coefficients, any exponent, site masses and
/// soft ends without dashpots) with constant couplings, whose force loop the lanes copy.
pub fn takes_lanes(model: &Model) -> bool {
    !model.is_dissipative()
        && model
            .resonators()
            .iter()
            .all(|r| matches!(r.coupling, Coupling::Constant(_)))
}
