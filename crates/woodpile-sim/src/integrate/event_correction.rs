//! The per-step bookkeeping of the exact contact events, shared by `rk4-contact` and
//! `rkn4-contact`: keep every bond force of each of the method's `S` stages, find after the
//! step the bonds whose contact opened or closed, and replace the method's quadrature of those
//! bonds' forces by the integral along the bond's path ([`super::contact_event`]).
//!
//! A method supplies only its quadrature: what its stage weights make of a bond's `S` stage
//! forces, as an impulse `h Σ b_i F_i` and a position change `h² Σ b̄_i F_i`.

pub(crate) use super::bond_correction::Quadrature;
use super::bond_correction::{
    apply, apply_fast, bond_correction, bond_integrals, bond_path, damped_force, Bond, Changed,
    Correction, Rule,
};
use super::contact_event::{first_crossing, first_switch, BondPath};
use super::contact_scan::{block_changes, block_of, changes_contact, negligible};
use super::exact_resonator::{ExactResonators, FastModeCorrection};
use crate::contact::{with_law, Law};
use crate::dofs::{Phase, PhaseMut, StepStates, StepStatesMut};
use crate::model::{Model, Window};

/// Extra passes of a dissipative chain's corrections ([`ContactEvents::refine`]).
const REFINE_PASSES: usize = 2;

/// Steps after a located force switch, each the size of the step it was located in, during
/// which its bond is corrected along its path whatever the scan finds
/// ([`ContactEvents::correct_next`]). A Hertzian dashpot's force rises like √s from the onset,
/// and RK4's quadrature of it is off by O(h^{3/2}) not only in the step that begins there but
/// in each of the next ones (by about k^{-7/2} in the k-th). With the contacts that open in
/// their clip corrected ([`ContactEvents::add_crossings`]) and one step carried, the standard
/// scene with a Hertzian dashpot was off by 7.3e-9, 1.5e-9 and 1.5e-10 at dt = 0.0086, 0.0022
/// and 0.001; with four, by 2.0e-9, 1.4e-10 and 3.6e-11 (docs/methods.md, "The onset of a
/// dashpot"). A linear dashpot's chain moves by under 10%; sixteen steps gain nothing more.
const CARRIED_STEPS: f64 = 4.0;

/// What a contact-event method keeps per step: every bond force of its `S` stages (indexing
/// of [`Model::accelerations_recording`]) and the corrections found, applied after the scan so
/// that each uses the uncorrected step.
#[derive(Debug, Clone)]
pub(crate) struct ContactEvents<const S: usize> {
    /// The bond forces of each stage, written by [`Model::accelerations_recording`].
    pub(super) stage_force: [Vec<f64>; S],
    /// The bonds' dashpot power of each stage (empty for a conservative chain).
    pub(super) stage_power: [Vec<f64>; S],
    quadrature: Quadrature<S>,
    /// The corrections of the last step.
    pending: Vec<Correction>,
    /// Their parts along the fast modes of exactly integrated resonators.
    pending_fast: Vec<FastModeCorrection>,
    /// A dissipative chain's corrected bonds and the energy each dissipated along its path.
    corrected: Vec<(usize, f64)>,
    /// Bonds corrected so far.
    events: u64,
    /// Scratch: the bonds this step corrects: those that changed contact, and on a chain with
    /// a contact dashpot those carried from a switch and those whose overlap changed sign.
    changed: Vec<Bond>,
    /// Bonds the next steps correct whatever their scan finds, and for how much longer
    /// ([`ContactEvents::correct_next`]): time, not a count of calls, since a located step
    /// corrects each of its parts.
    carried: Vec<(Bond, f64)>,
}

impl<const S: usize> ContactEvents<S> {
    /// Scratch for `model`'s bonds, corrected with the method's `quadrature`.
    pub fn new(model: &Model, quadrature: Quadrature<S>) -> Self {
        // A bond outside the window is at rest and carries its static force (0 but under
        // precompression): what its record must read when the window grows over it and a
        // reused stage (FSAL) was recorded before it did.
        let at_rest = with_law!(model.law(), |law| law.forces_at_rest(model.n_sites() + 1));
        let powers = match model.is_dissipative() {
            true => model.n_sites() + 1,
            false => 0,
        };
        Self {
            stage_force: std::array::from_fn(|_| at_rest.clone()),
            stage_power: std::array::from_fn(|_| vec![0.0; powers]),
            quadrature,
            pending: Vec::new(),
            pending_fast: Vec::new(),
            events: 0,
            changed: Vec::new(),
            carried: Vec::new(),
            corrected: Vec::new(),
        }
    }

    /// Bonds corrected so far.
    pub fn events(&self) -> u64 {
        self.events
    }

    /// Whether the last [`finish_step`](super::stage_step::finish_step) corrected any bond (then the end state is not the one
    /// the method's last stage saw).
    pub fn corrected_last_step(&self) -> bool {
        !self.pending.is_empty()
    }

    /// Makes a reused first stage (`acc`, and the recorded forces of stage 0) the forces of
    /// the positions `q` the last step's corrections moved: each corrected bond's members
    /// evaluated again by [`Model::patch_accelerations`], and an exact resonator's spring taken
    /// out at the sites patched. The same bits as evaluating the stage whole, at a few sites'
    /// cost: a step after a corrected one would otherwise evaluate its first stage again.
    pub(super) fn patch_reused_stage(
        &mut self,
        model: &Model,
        (t, q, window): (f64, &[f64], Window),
        acc: &mut [f64],
        mut exact: Option<&mut ExactResonators<S>>,
    ) {
        for &Correction {
            bond: Bond { left, right, .. },
            ..
        } in &self.pending
        {
            let Some(first) = left.or(right) else {
                continue;
            };
            let sites = first..=right.unwrap_or(first);
            let forces = (&mut *acc, &mut self.stage_force[0][..]);
            let patched = model.patch_accelerations(t, q, forces, window, sites);
            if let Some(exact) = exact.as_deref_mut() {
                for k in patched {
                    exact.remove_spring_at((0, k), q, acc);
                }
            }
        }
    }

    /// Makes stage `to`'s recorded bond forces those of stage `from` (the stage vectors are
    /// swapped; `from`'s are overwritten before they are read again): for a method whose first
    /// stage reuses its previous step's last.
    pub fn reuse_stage(&mut self, from: usize, to: usize) {
        self.stage_force.swap(from, to);
    }

    /// Replaces the method's quadrature by the path integral for every bond of `window` whose
    /// contact opened or closed during the step of size `h` between `states` (the end not yet
    /// corrected, and corrected here), and on a chain with a contact dashpot every bond carried
    /// from a switch ([`ContactEvents::correct_next`]) or whose overlap changed sign
    /// ([`ContactEvents::add_crossings`]). Bonds at the host of an `exact` resonator are
    /// corrected along its fast mode too ([`bond_correction`]).
    pub(super) fn correct(
        &mut self,
        model: &Model,
        states: StepStatesMut<'_>,
        h: f64,
        (window, exact): (Window, Option<&ExactResonators<S>>),
    ) {
        let n = model.n_dof();
        let StepStatesMut { start, end } = states;
        self.scan(model, &end[..n], window);
        let begun = Phase::of(start, n);
        if model.damping().is_some_and(|d| d.has_contact_dashpot()) {
            self.take_carried(h);
            let states = StepStates {
                start,
                end: &end[..],
            };
            self.add_crossings(model, states, window);
        }
        let (new_q, new_v) = end.split_at_mut(n);
        let quadrature = self.quadrature;
        let rule = Rule {
            h,
            quadrature,
            exact,
        };
        let mut pending = std::mem::take(&mut self.pending);
        pending.clear();
        let mut dissipated = 0.0;
        let mut corrected = std::mem::take(&mut self.corrected);
        corrected.clear();
        let ended = Phase {
            q: &*new_q,
            v: &new_v[..n],
        };
        for &bond in &self.changed {
            let stage = self.stage_forces(bond.index);
            let changed = Changed { bond, stage };
            let found =
                bond_correction(model, changed, (begun, ended), rule, &mut self.pending_fast);
            let Some((correction, lost)) = found else {
                continue;
            };
            pending.push(correction);
            if model.is_dissipative() {
                let powers = std::array::from_fn(|s| self.stage_power[s][bond.index]);
                dissipated += lost - quadrature(powers, h).0;
                corrected.push((bond.index, lost));
            }
        }
        if model.is_dissipative() {
            // D follows the velocities, at index n_dof of them.
            new_v[n] += dissipated;
        }
        let mut ended = PhaseMut {
            q: new_q,
            v: &mut new_v[..],
        };
        apply(model.inv_mass(), &pending, ended.reborrow());
        apply_fast(self.pending_fast.drain(..), ended);
        if model.is_dissipative() {
            let states = StepStatesMut { start, end };
            self.refine(model, states, h, (&mut pending, &mut corrected));
        }
        self.corrected = corrected;
        self.events += pending.len() as u64;
        self.pending = pending;
    }

    /// A dissipative chain's corrections again, [`REFINE_PASSES`] times, each from the end
    /// state the last one corrected. A bond's path is drawn through the step's end, and the
    /// uncorrected end is off by what the stages made of the bond's force. For a force that
    /// only kinks, that is small; a dashpot's force rises like √s (Hertzian) or carries
    /// c^{3/2} beside a jump, and the end is then too far off for the path to be right to the
    /// method's order. Each pass brings the path closer by about a power of the step.
    fn refine(
        &mut self,
        model: &Model,
        states: StepStatesMut<'_>,
        h: f64,
        (pending, corrected): (&mut [Correction], &mut [(usize, f64)]),
    ) {
        let n = model.n_dof();
        let StepStatesMut { start, end } = states;
        let begun = Phase::of(start, n);
        for _ in 0..REFINE_PASSES {
            let (new_q, new_v) = end.split_at_mut(n);
            let mut deltas = Vec::with_capacity(pending.len());
            let mut dissipated = 0.0;
            for (applied, (bond, lost_before)) in pending.iter_mut().zip(corrected.iter_mut()) {
                let before = *applied;
                let ended = Phase {
                    q: &*new_q,
                    v: &new_v[..n],
                };
                let path = bond_path(model, before.bond, begun, ended);
                let (impulse, moment, lost) = bond_integrals(model, *bond, &path, h);
                let (q0, q1) = (self.quadrature)(self.stage_forces(*bond), h);
                *applied = Correction {
                    impulse: impulse - q0,
                    moment: moment - q1,
                    ..before
                };
                deltas.push(Correction {
                    impulse: impulse - q0 - before.impulse,
                    moment: moment - q1 - before.moment,
                    ..before
                });
                dissipated += lost - *lost_before;
                *lost_before = lost;
            }
            new_v[n] += dissipated;
            apply(model.inv_mass(), &deltas, PhaseMut { q: new_q, v: new_v });
        }
    }

    /// The earliest moment, as a fraction of the step in (`after`, 1), at which a contact of
    /// `window` that is not [`negligible`] opens or closes along its path over the step of size
    /// `h` between `states`: where an event-located method ends its step.
    pub(crate) fn first_event(
        &mut self,
        model: &Model,
        states: StepStates<'_>,
        h: f64,
        window: Window,
        after: f64,
    ) -> Option<f64> {
        let crossing = |_: usize, path: &BondPath| first_crossing(path, h, after);
        self.earliest(model, states, window, crossing)
            .map(|(x, _)| x)
    }

    /// The earliest moment, as a fraction of the step in (0, 1), at which the force of a
    /// damped contact of `window` switches along its path ([`first_switch`]: it closes, or its
    /// clip starts), not counting [`negligible`] ones, and its bond: where `rk4-contact` ends a
    /// step on a dissipative chain, so that no step carries a jump or a kink of a force in its
    /// stages.
    pub(crate) fn first_switch(
        &mut self,
        model: &Model,
        states: StepStates<'_>,
        h: f64,
        window: Window,
    ) -> Option<(f64, Bond)> {
        let switch = |bond: usize, path: &BondPath| {
            let damping = model.damping();
            with_law!(model.law(), |law| {
                first_switch(path, h, damped_force(law, damping, bond))
            })
        };
        self.earliest(model, states, window, switch)
    }

    /// The earliest `moment` (a fraction of the step, or none) over the bonds of `window` that
    /// changed during the step between `states` and are not [`negligible`], with its bond.
    fn earliest(
        &mut self,
        model: &Model,
        states: StepStates<'_>,
        window: Window,
        moment: impl Fn(usize, &BondPath) -> Option<f64>,
    ) -> Option<(f64, Bond)> {
        let n = model.n_dof();
        let StepStates { start, end } = states;
        self.scan(model, &end[..n], window);
        let (begun, ended) = (Phase::of(start, n), Phase::of(end, n));
        let mut first: Option<(f64, Bond)> = None;
        for &bond in &self.changed {
            let path = bond_path(model, bond, begun, ended);
            if negligible(model, bond.index, self.stage_forces(bond.index), &path) {
                continue;
            }
            let earlier = |&x: &f64| first.is_none_or(|(f, _)| x < f);
            if let Some(x) = moment(bond.index, &path).filter(earlier) {
                first = Some((x, bond));
            }
        }
        first
    }

    /// Makes the steps of the next [`CARRIED_STEPS`] × `h` correct `bond` (as
    /// [`ContactEvents::first_switch`] gives it, located in a step of size `h`) whether or not
    /// their scan finds it changed: steps that begin just after the bond's force switched,
    /// whose force is not smooth near their start.
    pub(crate) fn correct_next(&mut self, bond: Bond, h: f64) {
        self.carried.retain(|&(b, _)| b != bond);
        // Half a step short, so that rounding in the countdown neither adds a fifth step nor
        // drops the fourth.
        self.carried.push((bond, (CARRIED_STEPS - 0.5) * h));
    }

    /// Adds the carried bonds to the changed ones of this step (or part of a step) of size `h`,
    /// each with `h` less to go.
    fn take_carried(&mut self, h: f64) {
        for (bond, left) in &mut self.carried {
            *left -= h;
            if !self.changed.contains(bond) {
                self.changed.push(*bond);
            }
        }
        self.carried.retain(|&(_, left)| left > 0.0);
    }

    /// Adds to this step's changed bonds every bond of `window` whose overlap changed sign
    /// between `states` (c = 0 counting as open) that the scan missed, as a contact that opens
    /// while its dashpot's clip holds its force at zero. Its recorded forces are all zero, so
    /// the scan sees nothing, but it still dissipates (−c^{3/2} ċ until it opens, a power with a kink there): left to RK4's
    /// quadrature, that kink put an error of O(h^{5/2}) into D at every opening, ten to a
    /// thousand times the error of the motion (docs/methods.md, "The onset of a dashpot").
    fn add_crossings(&mut self, model: &Model, states: StepStates<'_>, window: Window) {
        let n = model.n_dof();
        let (q0, q1) = (&states.start[..n], &states.end[..n]);
        // One pass over the window's positions, as the scan reads them (a bond's overlap is
        // its static overlap plus left − right); the walls, rare, through their paths.
        let (lo, hi) = (window.lo, window.hi);
        let (left0, right0) = (&q0[lo..hi], &q0[lo + 1..=hi]);
        let (left1, right1) = (&q1[lo..hi], &q1[lo + 1..=hi]);
        let static_overlaps = with_law!(model.law(), |law| law.static_overlaps());
        let mut add = |bond: Bond| {
            if !self.changed.contains(&bond) {
                self.changed.push(bond);
            }
        };
        for i in 0..hi - lo {
            let offset = static_overlaps.map_or(0.0, |delta| delta[lo + 1 + i]);
            let d0 = offset + (left0[i] - right0[i]);
            let d1 = offset + (left1[i] - right1[i]);
            if (d0 > 0.0) != (d1 > 0.0) {
                add(Bond::inner(lo + 1 + i));
            }
        }
        let n_sites = model.n_sites();
        let [left_wall, right_wall] = model.walls();
        let walls = [
            (window.lo == 0 && left_wall).then(Bond::left_wall),
            (window.hi == n_sites - 1 && right_wall).then(|| Bond::right_wall(n_sites)),
        ];
        let (begun, ended) = (Phase::of(states.start, n), Phase::of(states.end, n));
        for wall in walls.into_iter().flatten() {
            let path = bond_path(model, wall, begun, ended);
            if (path.d0 > 0.0) != (path.d1 > 0.0) {
                add(wall);
            }
        }
    }

    fn stage_forces(&self, bond: usize) -> [f64; S] {
        std::array::from_fn(|s| self.stage_force[s][bond])
    }

    crate::simd::dispatched! {
        /// Lists in `self.changed` every bond of `window` whose contact opened or closed during
        /// the step, as (bond, left site, right site) with `None` for a wall; `new_q` are the
        /// end positions.
        fn scan[&mut self](model: &Model, new_q: &[f64], window: Window) => scan_body, scan_avx2, scan_avx512
    }

    #[inline(always)]
    fn scan_body(&mut self, model: &Model, new_q: &[f64], window: Window) {
        let n_sites = model.n_sites();
        let forces = &self.stage_force;
        // The scan over the window's bonds is the only per-bond cost; it touches the stage
        // forces and end positions in order and calls out only for the rare bond that changed.
        let (lo, hi) = (window.lo, window.hi);
        let stage_slices: [&[f64]; S] = std::array::from_fn(|s| &forces[s][lo + 1..hi + 1]);
        let (left_q, right_q) = (&new_q[lo..hi], &new_q[lo + 1..hi + 1]);
        // A bond changed contact when between one and S of its S + 1 values say "touching"
        // (`changes_contact`): when the largest of them is positive and the smallest is not.
        // Written as compare-and-select minima and maxima over fixed blocks of four bonds (one
        // AVX2 register), the test has no bounds checks and no branch per bond; each block
        // yields a bit mask of its changed bonds, and only set bits are visited. This scan
        // took a third of a step as a per-bond count of "touching" values; now it is a tenth
        // (standard scene, `rkn4-contact` at dt = 0.1: 2.10 -> 1.65 ms, best of 400).
        let changed = &mut self.changed;
        changed.clear();
        let inner = |i: usize| Bond::inner(lo + i + 1);
        let n_bonds = hi - lo;
        // Under precompression a bond's overlap is its static overlap plus left − right.
        let offsets = with_law!(model.law(), |law| law.static_overlaps());
        let mut start = 0;
        if offsets.is_none() {
            const BLOCK: usize = 4;
            // Every slice cut to `n_bonds` here, once, so that the blocks below need no
            // bounds checks: `start + BLOCK <= n_bonds` proves each in range.
            let stage: [&[f64]; S] = std::array::from_fn(|s| &stage_slices[s][..n_bonds]);
            let (left, right) = (&left_q[..n_bonds], &right_q[..n_bonds]);
            while start + BLOCK <= n_bonds {
                let block = start..start + BLOCK;
                let forces: [&[f64; BLOCK]; S] =
                    std::array::from_fn(|s| block_of(&stage[s][block.clone()]));
                let mut mask = block_changes(
                    block_of(&left[block.clone()]),
                    block_of(&right[block]),
                    forces,
                );
                while mask != 0 {
                    changed.push(inner(start + mask.trailing_zeros() as usize));
                    mask &= mask - 1;
                }
                start += BLOCK;
            }
        }
        // The last bonds, fewer than a block, or every bond of a precompressed chain: the
        // scalar test.
        let offset = |bond: usize| offsets.map_or(0.0, |delta| delta[bond]);
        changed.extend(
            (start..n_bonds)
                .filter(|&i| {
                    let d_end = match offsets {
                        None => left_q[i] - right_q[i],
                        Some(delta) => delta[lo + i + 1] + (left_q[i] - right_q[i]),
                    };
                    changes_contact::<S>(std::array::from_fn(|s| stage_slices[s][i]), d_end)
                })
                .map(inner),
        );
        let wall_changed = |bond: usize, d_end: f64| {
            changes_contact::<S>(std::array::from_fn(|s| forces[s][bond]), d_end)
        };
        let [left_wall, right_wall] = model.walls();
        if lo == 0 && left_wall && wall_changed(0, offset(0) - new_q[0]) {
            changed.push(Bond::left_wall());
        }
        let last = n_sites - 1;
        if hi == last && right_wall && wall_changed(n_sites, offset(n_sites) + new_q[last]) {
            changed.push(Bond::right_wall(n_sites));
        }
    }
}
