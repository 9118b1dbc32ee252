//! Which bonds changed contact during a step: the scalar test, and the vectorised one over a
//! block of bonds that the scan runs (the two agree on every pattern, tested); and which of
//! those changes are too weak to correct.

use super::contact_event::BondPath;
use crate::contact::{with_law, Law, NEGLIGIBLE_FORCE};
use crate::model::Model;

/// Whether a changed bond's forces, at every stage and at the end of its `path`, all stay
/// below [`NEGLIGIBLE_FORCE`]: then its correction is skipped. The end is looked at only when
/// every stage force is below it. A contact dashpot's clip records a zero force on a bond
/// that still dissipates, so on a chain with one the elastic force at the start of the path
/// must be negligible too.
pub(super) fn negligible<const S: usize>(
    model: &Model,
    bond: usize,
    stage_forces: [f64; S],
    path: &BondPath,
) -> bool {
    stage_forces.iter().all(|&f| f < NEGLIGIBLE_FORCE)
        && end_force_negligible(model, bond, path)
        && (!model.damping().is_some_and(|d| d.has_contact_dashpot())
            || with_law!(model.law(), |law| law.force_negligible(bond, path.d0)))
}

/// Whether the bond's elastic force at the end of its path is below [`NEGLIGIBLE_FORCE`], by
/// the chain's law (the path is of the total overlap: `bond_path` adds the static overlap).
fn end_force_negligible(model: &Model, bond: usize, path: &BondPath) -> bool {
    with_law!(model.law(), |law| law.force_negligible(bond, path.d1))
}

/// Whether a bond's contact changed state during a step: its stage forces and end overlap do
/// not all agree on "touching". Bonds that stay open (the whole quiet chain) or stay closed
/// (smooth force) need no correction. Written as [`block_changes`] is, the largest of the
/// S + 1 values positive and the smallest not (compare-and-select from the end overlap), so
/// that the two agree on every input, a NaN end overlap included (neither flags it), and the
/// SIMD lanes' scan can match either.
#[inline(always)]
pub(crate) fn changes_contact<const S: usize>(stage_forces: [f64; S], d_end: f64) -> bool {
    let (mut low, mut high) = (d_end, d_end);
    for f in stage_forces {
        low = if f < low { f } else { low };
        high = if f > high { f } else { high };
    }
    (high > 0.0) & (low <= 0.0)
}

/// `slice` (of length `N`) as an array reference, so that loops over it need no bounds checks.
#[inline(always)]
pub(super) fn block_of<const N: usize>(slice: &[f64]) -> &[f64; N] {
    slice.try_into().expect("a block of the requested length")
}

/// Which bonds of a block changed contact during the step, as a bit mask (bit i: bond i). A
/// bond's end overlap is `left - right`, its stage forces are `forces[s]`; "touching" is a
/// positive value, and a change is some but not all of them touching. Lane-wise minima and
/// maxima by compare-and-select (not `f64::min`, whose NaN handling blocks packed
/// instructions; a NaN state is caught by the driver), then one packed compare per bound.
#[inline(always)]
pub(super) fn block_changes<const S: usize, const N: usize>(
    left: &[f64; N],
    right: &[f64; N],
    forces: [&[f64; N]; S],
) -> u32 {
    let mut low = [0.0; N];
    for i in 0..N {
        low[i] = left[i] - right[i];
    }
    let mut high = low;
    for f in &forces {
        for i in 0..N {
            low[i] = if f[i] < low[i] { f[i] } else { low[i] };
            high[i] = if f[i] > high[i] { f[i] } else { high[i] };
        }
    }
    let changed: [bool; N] = std::array::from_fn(|i| (high[i] > 0.0) & (low[i] <= 0.0));
    // Nearly every block has no change: one test of the whole block (an OR reduction, which
    // compiles to a single mask test) before the bits are gathered one by one.
    if !changed.iter().fold(false, |any, &c| any | c) {
        return 0;
    }
    let mut mask = 0;
    for (i, &c) in changed.iter().enumerate() {
        mask |= u32::from(c) << i;
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_changes_are_detected_only_at_sign_changes() {
        assert!(!changes_contact([0.0; 4], 0.0));
        assert!(!changes_contact([1.0, 2.0, 2.0, 1.0], 0.5));
        assert!(changes_contact([0.0, 0.1, 0.1, 0.2], 0.3));
        assert!(changes_contact([0.1, 0.1, 0.1, 0.2], -0.3));
        assert!(changes_contact([0.0, 0.0, 0.1], 0.0));
        assert!(!changes_contact([0.1, 0.2, 0.1], 0.1));
    }

    #[test]
    fn a_nan_end_overlap_is_no_change_for_either_test() {
        assert!(!changes_contact([0.5, 0.0, 0.2], f64::NAN));
        let nan = [f64::NAN, 0.0, 0.0, 0.0];
        let forces = [0.5, 0.0, 0.0, 0.0];
        assert_eq!(
            block_changes(&nan, &[0.0; 4], [&forces, &forces, &forces]),
            0
        );
    }

    #[test]
    fn the_block_test_agrees_with_the_scalar_one() {
        // Every pattern of touching (positive), just-open (zero) and open (negative) values
        // over three stage forces and the end overlap, four bonds to a block.
        let values: [f64; 3] = [-0.5, 0.0, 0.7];
        let mut bonds: Vec<([f64; 3], f64)> = Vec::new();
        // All 81 patterns, the first three again to fill the last block.
        for code in (0..84).map(|c| c % 81) {
            let pick = |k: u32| values[(code / 3usize.pow(k)) % 3];
            bonds.push((
                [pick(0).max(0.0), pick(1).max(0.0), pick(2).max(0.0)],
                pick(3),
            ));
        }
        for block in bonds.chunks_exact(4) {
            let right = [0.0f64; 4];
            let left: [f64; 4] = std::array::from_fn(|i| block[i].1);
            let stage: [[f64; 4]; 3] =
                std::array::from_fn(|s| std::array::from_fn(|i| block[i].0[s]));
            let mask = block_changes(&left, &right, [&stage[0], &stage[1], &stage[2]]);
            for (i, (forces, d_end)) in block.iter().enumerate() {
                assert_eq!(
                    mask >> i & 1 == 1,
                    changes_contact(*forces, *d_end),
                    "{forces:?} {d_end}"
                );
            }
        }
    }
}
