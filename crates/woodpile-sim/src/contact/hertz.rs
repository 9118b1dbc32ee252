//! The paper's contact law (paper Eq. 3): force `[d]_+^{3/2}`, potential `(2/5) [d]_+^{5/2}`,
//! unit coefficients, no precompression. [`PaperHertz`] carries no data: the loops generic
//! over [`Law`] compile, for it, to the paper's own loop, with its bits.

use super::{Law, LawOf, NEGLIGIBLE_FORCE};
use crate::integrate::contact_event::{oscillating_path_integrals, path_integrals, BondPath};

/// Hertz contact force for an overlap `d`: `[d]_+^{3/2}`.
#[inline(always)]
pub fn hertz_force(d: f64) -> f64 {
    if d > 0.0 {
        d * d.sqrt()
    } else {
        0.0
    }
}

/// Hertz contact potential for an overlap `d`: `(2/5) [d]_+^{5/2}`, whose derivative is
/// [`hertz_force`].
#[inline(always)]
pub fn hertz_potential(d: f64) -> f64 {
    if d > 0.0 {
        0.4 * d * d * d.sqrt()
    } else {
        0.0
    }
}

/// End overlaps whose force d√d is surely below [`NEGLIGIBLE_FORCE`] (4e-10: 8.0e-15), and
/// surely not (5e-10: 1.12e-14). The rounded d·√d never decreases as d grows, so comparing d
/// with these decides as the force itself would, without its square root: the grazing
/// touches, most changed bonds, end far below the first.
const SURELY_NEGLIGIBLE_OVERLAP: f64 = 4e-10;
const SURELY_FELT_OVERLAP: f64 = 5e-10;

/// The paper's law: see the module documentation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PaperHertz;

impl Law for PaperHertz {
    fn n_bonds(&self) -> Option<usize> {
        None
    }

    fn describe(&self) -> LawOf<'_> {
        LawOf::Paper
    }

    fn exponent(&self) -> f64 {
        1.5
    }

    fn gravity(&self) -> f64 {
        0.0
    }

    #[inline(always)]
    fn static_overlap(&self, _bond: usize) -> f64 {
        0.0
    }

    #[inline(always)]
    fn overlap(&self, _bond: usize, r: f64) -> f64 {
        r
    }

    /// `max(r, 0)^{3/2}`, as the paper's loop computes it: the same bits as [`hertz_force`]
    /// for every r, NaN included, and no branch to mispredict on the many barely-touching
    /// contacts behind the wave.
    #[inline(always)]
    fn elastic(&self, _bond: usize, r: f64) -> f64 {
        let d = r.max(0.0);
        d * d.sqrt()
    }

    #[inline(always)]
    fn static_force(&self, _bond: usize) -> f64 {
        0.0
    }

    #[inline(always)]
    fn net(&self, _bond: usize, elastic: f64) -> f64 {
        elastic
    }

    fn potential(&self, _bond: usize, r: f64) -> f64 {
        hertz_potential(r)
    }

    fn static_overlaps(&self) -> Option<&[f64]> {
        None
    }

    fn path_integrals(&self, _bond: usize, path: &BondPath, h: f64) -> (f64, f64) {
        path_integrals(path, h)
    }

    fn oscillating_integrals(
        &self,
        _bond: usize,
        path: &BondPath,
        h: f64,
        theta: f64,
    ) -> (f64, f64) {
        oscillating_path_integrals(path, h, theta, |d| d * d.sqrt())
    }

    #[inline(always)]
    fn force_negligible(&self, _bond: usize, c: f64) -> bool {
        let end = c.max(0.0);
        if end < SURELY_NEGLIGIBLE_OVERLAP {
            return true;
        }
        if end > SURELY_FELT_OVERLAP {
            return false;
        }
        end * end.sqrt() < NEGLIGIBLE_FORCE
    }

    /// (3/2) √c.
    fn stiffness(&self, _bond: usize, c: f64) -> f64 {
        1.5 * c.sqrt()
    }

    /// (2/5) c^{5/2} ≤ energy.
    fn overlap_within(&self, _bond: usize, energy: f64) -> f64 {
        (2.5 * energy.max(0.0)).powf(0.4)
    }

    fn stiffness_within(&self, _bond: usize, _energy: f64) -> Option<f64> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_loops_power_is_hertz_force_for_every_overlap() {
        for d in [
            -1.0,
            -0.0,
            0.0,
            1e-300,
            0.013,
            0.5,
            1.7,
            f64::NAN,
            f64::INFINITY,
        ] {
            let (a, b) = (PaperHertz.elastic(3, d), hertz_force(d));
            assert_eq!(a.to_bits(), b.to_bits(), "overlap {d}");
        }
    }

    #[test]
    fn the_overlap_shortcut_decides_as_the_force_does() {
        let by_force = |d: f64| {
            let end = d.max(0.0);
            end * end.sqrt() < NEGLIGIBLE_FORCE
        };
        // Both bounds and the force's own threshold, neighbours a few ulps apart, and a sweep
        // over the decades around them (negative overlaps, a NaN and zeros too).
        let threshold = NEGLIGIBLE_FORCE.powf(2.0 / 3.0);
        let mut overlaps = vec![-1.0, -0.0, 0.0, f64::NAN, 1.0, 1e300];
        for centre in [SURELY_NEGLIGIBLE_OVERLAP, SURELY_FELT_OVERLAP, threshold] {
            let bits = centre.to_bits();
            overlaps.extend((bits - 64..bits + 64).map(f64::from_bits));
        }
        overlaps.extend((0..20_000).map(|k| 1e-12 * 1.001f64.powi(k)));
        for d in overlaps {
            assert_eq!(
                PaperHertz.force_negligible(0, d),
                by_force(d),
                "overlap {d:e}"
            );
        }
        assert!(by_force(SURELY_NEGLIGIBLE_OVERLAP) && !by_force(SURELY_FELT_OVERLAP));
    }
}
