//! The sites a step works on.

use super::Model;

/// The sites a step works on: a contiguous range of site indices, inclusive. Everything outside
/// it is exactly at rest (zero displacement and velocity, zero force) for the whole step, so
/// skipping it changes no bit of the result; see [`crate::integrate::drive`], which grows the
/// window ahead of the wave. Resonator coordinates are always inside (there are few).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// First site index.
    pub lo: usize,
    /// Last site index (inclusive).
    pub hi: usize,
}

impl Window {
    /// Every site of `model`.
    pub fn full(model: &Model) -> Self {
        Self {
            lo: 0,
            hi: model.n_sites() - 1,
        }
    }

    /// Number of sites covered.
    pub fn len(&self) -> usize {
        self.hi - self.lo + 1
    }

    /// Never empty: a window holds at least one site.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The parts of a state `[q, q']` of `model` that the window covers, in state order:
    /// site positions, resonator positions, site velocities, resonator velocities, and D
    /// (empty for a conservative chain).
    pub fn state_ranges(&self, model: &Model) -> [std::ops::Range<usize>; 5] {
        let (n_sites, n_dof) = (model.n_sites(), model.n_dof());
        [
            self.lo..self.hi + 1,
            n_sites..n_dof,
            n_dof + self.lo..n_dof + self.hi + 1,
            n_dof + n_sites..2 * n_dof,
            2 * n_dof..model.state_len(),
        ]
    }

    /// The parts of a position (or acceleration) vector of length `n_dof` it covers.
    pub fn dof_ranges(&self, model: &Model) -> [std::ops::Range<usize>; 2] {
        [self.lo..self.hi + 1, model.n_sites()..model.n_dof()]
    }
}
