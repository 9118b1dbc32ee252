//! Each lane's contact events: the scan for bonds whose contact opened or closed, run on all
//! lanes at once (a lane mask per bond), and the corrections, lane by lane in the scalar
//! [`crate::integrate::event_correction`]'s order and with its functions, so that a lane's end
//! state is corrected exactly as its scalar run's is.

use super::{Lane, LaneMut, Lanes, LANES, S};
use crate::chain_force::Width;
use crate::contact::{with_law, Law};
use crate::dofs::{Phase, PhaseMut};
use crate::integrate::bond_correction::{
    apply, apply_fast, bond_correction, Bond, Changed, Correction, Rule,
};
use crate::integrate::contact_scan::changes_contact;
use crate::integrate::exact_resonator::{ExactResonators, FastModeCorrection};
use crate::integrate::rkn::DPRKN6;
use crate::model::{Model, Window};

/// The scan's and corrections' scratch, and the bonds corrected per lane.
#[derive(Debug, Clone, Default)]
pub(super) struct LaneEvents {
    /// The bonds some live lane saw change in this step, with the mask of those lanes, in the
    /// scalar scan's order (inner bonds rising, then the left wall, then the right).
    changed: Vec<(Bond, u32)>,
    pending: Vec<Correction>,
    pending_fast: Vec<FastModeCorrection>,
    /// Per lane, the sites the last step's corrections moved.
    pub touched: [Vec<usize>; LANES],
}

impl LaneEvents {
    /// Corrects the state the step of size `h` from `begun` has `ended` at, in every live lane
    /// whose bonds of `window` changed contact, from the stages' bond forces `stage_force`.
    /// Returns which lanes were corrected.
    pub fn correct(
        &mut self,
        models: &[&Model; LANES],
        begun: Phase<'_, [Lanes]>,
        ended: PhaseMut<'_, [Lanes]>,
        (stage_force, h): (&[Vec<Lanes>; S], f64),
        (window, live): (Window, [bool; LANES]),
        exact: &[Option<ExactResonators<S>>; LANES],
    ) -> [bool; LANES] {
        let Phase { q, v } = begun;
        let PhaseMut { q: new_q, v: new_v } = ended;
        let live_mask = (0..LANES).fold(0, |m, l| m | (u32::from(live[l]) << l));
        self.scan(models[0], new_q, stage_force, window, live_mask);
        let mut corrected = [false; LANES];
        for touched in &mut self.touched {
            touched.clear();
        }
        if self.changed.is_empty() {
            return corrected;
        }
        for (l, model) in models.iter().enumerate() {
            let mut pending = std::mem::take(&mut self.pending);
            pending.clear();
            for &(bond, mask) in &self.changed {
                if mask >> l & 1 == 0 {
                    continue;
                }
                let stage: [f64; S] = std::array::from_fn(|s| stage_force[s][bond.index][l]);
                let begun = Phase {
                    q: &Lane(q, l),
                    v: &Lane(v, l),
                };
                let ended = Phase {
                    q: &Lane(new_q, l),
                    v: &Lane(new_v, l),
                };
                let rule = Rule {
                    h,
                    quadrature: DPRKN6.quadrature,
                    exact: exact[l].as_ref(),
                };
                let fast = &mut self.pending_fast;
                let changed = Changed { bond, stage };
                if let Some((correction, _)) =
                    bond_correction(model, changed, (begun, ended), rule, fast)
                {
                    pending.push(correction);
                }
            }
            let (mut lane_q, mut lane_v) = (LaneMut(new_q, l), LaneMut(new_v, l));
            let mut ended = PhaseMut {
                q: &mut lane_q,
                v: &mut lane_v,
            };
            apply(model.inv_mass(), &pending, ended.reborrow());
            apply_fast(self.pending_fast.drain(..), ended);
            let touched = &mut self.touched[l];
            for correction in &pending {
                touched.extend(correction.bond.sites());
            }
            corrected[l] = !pending.is_empty();
            self.pending = pending;
        }
        corrected
    }

    crate::simd::dispatched! {
        /// Lists in `self.changed` every bond of `window` whose contact opened or closed during
        /// the step in some lane of `live_mask`, as the scalar scan does per lane (a bond outside a
        /// lane's own window is at rest there, and never changes). In its AVX2 or AVX-512 copy
        /// where the CPU has one (`crate::simd`).
        fn scan[&mut self](
            model: &Model,
            new_q: &[Lanes],
            stage_force: &[Vec<Lanes>; S],
            window: Window,
            live_mask: u32,
        ) => scan_body, scan_avx2, scan_avx512
    }

    #[inline(always)]
    fn scan_body(
        &mut self,
        model: &Model,
        new_q: &[Lanes],
        stage_force: &[Vec<Lanes>; S],
        window: Window,
        live_mask: u32,
    ) {
        self.changed.clear();
        let (lo, hi) = (window.lo, window.hi);
        // Under precompression a bond's overlap is its static overlap plus left − right.
        let offsets = with_law!(model.law(), |law| law.static_overlaps());
        let offset = |bond: usize| offsets.map_or(0.0, |delta| delta[bond]);
        for bond in lo + 1..=hi {
            // Some but not all of the S + 1 values say "touching": the largest is positive and
            // the smallest is not (compare-and-select, as the scalar block test).
            let mut low = match offsets {
                None => new_q[bond - 1].zip(new_q[bond], |l, r| l - r),
                Some(delta) => new_q[bond - 1].zip(new_q[bond], |l, r| delta[bond] + (l - r)),
            };
            let mut high = low;
            for forces in stage_force {
                let f = forces[bond];
                low = low.zip(f, |low, f| if f < low { f } else { low });
                high = high.zip(f, |high, f| if f > high { f } else { high });
            }
            let changed: [bool; LANES] = std::array::from_fn(|l| (high[l] > 0.0) & (low[l] <= 0.0));
            // Nearly every bond changed in no lane: one test of all four (an OR reduction, a
            // single mask test) before the bits are gathered one by one.
            if !changed.iter().fold(false, |any, &c| any | c) {
                continue;
            }
            let mask = (0..LANES).fold(0, |m, l| m | (u32::from(changed[l]) << l)) & live_mask;
            if mask != 0 {
                self.changed.push((Bond::inner(bond), mask));
            }
        }
        let n_sites = model.n_sites();
        let last = n_sites - 1;
        let [left_wall, right_wall] = model.walls();
        let wall = |bond: usize, d_end: Lanes| {
            (0..LANES).fold(0, |m, l| {
                let forces = std::array::from_fn(|s| stage_force[s][bond][l]);
                m | (u32::from(changes_contact::<S>(forces, d_end[l])) << l)
            }) & live_mask
        };
        if lo == 0 && left_wall {
            let mask = wall(0, new_q[0].map(|x| offset(0) - x));
            if mask != 0 {
                self.changed.push((Bond::left_wall(), mask));
            }
        }
        if hi == last && right_wall {
            let mask = wall(n_sites, new_q[last].map(|x| offset(n_sites) + x));
            if mask != 0 {
                self.changed.push((Bond::right_wall(n_sites), mask));
            }
        }
    }
}
