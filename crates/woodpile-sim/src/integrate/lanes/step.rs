//! The batched `rkn6-contact` step (and `erkn6-contact`'s, with each lane's harmonic resonators
//! integrated exactly): DPRKN6 on four chains in structure-of-arrays form (entry k of a vector
//! is degree of freedom k, its lanes the four scenes), then each lane's contact corrections.
//! Every lane does the scalar [`crate::integrate::Rkn`]'s operations in its order (`raw_step_body`, and the one force
//! kernel, [`crate::chain_force`]), which is what keeps it bit-identical.

use super::events::LaneEvents;
use super::force::{accelerations, patch};
use super::{Lane, LaneChain, LaneMut, Lanes, LANES, S, ZERO};
use crate::contact::{with_law, Law};
use crate::dofs::{Phase, PhaseMut};
use crate::integrate::erkn_weights::NystromWeights;
use crate::integrate::exact_resonator::ExactResonators;
use crate::integrate::rkn::DPRKN6;
use crate::integrate::stage_sum::{sum_into, Base, Terms};
use crate::model::{Model, Window};

/// `rkn6-contact` or `erkn6-contact` for four lanes, with its scratch (allocated once).
#[derive(Debug, Clone)]
pub(super) struct LaneRkn6 {
    pub chain: LaneChain,
    q_stage: Vec<Lanes>,
    a: [Vec<Lanes>; S],
    new_q: Vec<Lanes>,
    new_v: Vec<Lanes>,
    /// Each stage's bond forces (entry b: the bond left of site b; 0 and n_sites the walls).
    stage_force: [Vec<Lanes>; S],
    /// Force evaluations per lane, as the scalar run counts them.
    pub evals: [u64; LANES],
    /// Per lane: whether the last stage's forces are those of the current state (the scalar
    /// stepper's first-same-as-last flag).
    last_stage_current: [bool; LANES],
    events: LaneEvents,
    /// Per lane, its harmonic resonators integrated exactly (`erkn6-contact`), if any.
    exact: [Option<ExactResonators<S>>; LANES],
}

impl LaneRkn6 {
    /// The lanes of `chain`, their models `models`, with their harmonic resonators integrated
    /// exactly when `exact` (`erkn6-contact`; `rkn6-contact` otherwise).
    pub fn new(chain: LaneChain, models: &[&Model; LANES], exact: bool) -> Self {
        let weights = NystromWeights {
            c: DPRKN6.c,
            b: DPRKN6.b,
            b_prime: DPRKN6.b_prime,
        };
        let exact = models.map(|m| exact.then(|| ExactResonators::of(m, weights)).flatten());
        let bonds = chain.n_sites + 1;
        // A bond outside the window is at rest and carries its static force (0 but under
        // precompression): what its record must read when the window grows over it and a
        // reused stage was recorded before it did (as the scalar `ContactEvents::new`).
        let at_rest: Vec<Lanes> = with_law!(chain.law(), |law| law.forces_at_rest(bonds))
            .into_iter()
            .map(|f| [f; LANES])
            .collect();
        let n = chain.n_dof();
        Self {
            q_stage: vec![ZERO; n],
            a: std::array::from_fn(|_| vec![ZERO; n]),
            new_q: vec![ZERO; n],
            new_v: vec![ZERO; n],
            stage_force: std::array::from_fn(|_| at_rest.clone()),
            evals: [0; LANES],
            last_stage_current: [false; LANES],
            events: LaneEvents::default(),
            exact,
            chain,
        }
    }

    /// One step of size `h` of the `live` lanes of `(q, v)` on the union `window` of their
    /// windows, corrected per lane and copied back. `models` are the lanes' own models, which
    /// the corrections read.
    pub fn step(
        &mut self,
        models: &[&Model; LANES],
        (q, v): (&mut [Lanes], &mut [Lanes]),
        h: f64,
        (window, live): (Window, [bool; LANES]),
    ) {
        self.raw_step(q, v, h, window, live);
        let begun = Phase { q: &*q, v: &*v };
        let ended = PhaseMut {
            q: &mut self.new_q[..],
            v: &mut self.new_v[..],
        };
        let corrected = self.events.correct(
            models,
            begun,
            ended,
            (&self.stage_force, h),
            (window, live),
            &self.exact,
        );
        self.last_stage_current = corrected.map(|c| !c);
        for r in self.dof_ranges(window) {
            q[r.clone()].copy_from_slice(&self.new_q[r.clone()]);
            v[r.clone()].copy_from_slice(&self.new_v[r]);
        }
    }

    /// Puts lane `l`, whose run has stopped, at rest: its stage forces zero, its bond records
    /// at their rest values, its last stage current.
    pub fn retire(&mut self, l: usize) {
        for x in self.a.iter_mut().flatten() {
            x[l] = 0.0;
        }
        let bonds = self.chain.n_sites + 1;
        let rest = with_law!(self.chain.law(), |law| law.forces_at_rest(bonds));
        for record in &mut self.stage_force {
            for (x, &f) in record.iter_mut().zip(&rest) {
                x[l] = f;
            }
        }
        self.last_stage_current[l] = true;
    }

    fn dof_ranges(&self, window: Window) -> [std::ops::Range<usize>; 2] {
        [
            window.lo..window.hi + 1,
            self.chain.n_sites..self.chain.n_dof(),
        ]
    }

    crate::simd::dispatched! {
        /// The uncorrected step into `new_q`, `new_v`, recording every stage's bond forces, in
        /// its AVX2 or AVX-512 copy where the CPU has one (`crate::simd`).
        fn raw_step[&mut self](
            q: &[Lanes],
            v: &[Lanes],
            h: f64,
            window: Window,
            live: [bool; LANES],
        ) => raw_step_body, raw_step_avx2, raw_step_avx512
    }

    #[inline(always)]
    fn raw_step_body(
        &mut self,
        q: &[Lanes],
        v: &[Lanes],
        h: f64,
        window: Window,
        live: [bool; LANES],
    ) {
        let tab = DPRKN6;
        let ranges = self.dof_ranges(window);
        // The last stage is reused when it is current in every live lane, or was moved by a
        // correction at a few sites whose forces are then evaluated again; otherwise (the
        // first step) the first stage is evaluated whole.
        for (l, exact) in self.exact.iter_mut().enumerate() {
            if let Some(exact) = exact {
                exact.begin_step(h, (&Lane(q, l), &Lane(v, l)), (window.lo, window.hi));
            }
        }
        // A lane that is not current was corrected in the last step, at the sites in
        // `touched`; only the first step evaluates its first stage whole.
        let reuse = (0..LANES)
            .all(|l| !live[l] || self.last_stage_current[l] || !self.events.touched[l].is_empty());
        debug_assert!(
            self.evals.iter().all(|&e| e == 0) || reuse,
            "after the first step, every live lane is current or was corrected"
        );
        for i in 0..S {
            if i > 0 {
                for r in ranges.clone() {
                    // Lane by lane, the scalar path's sums: the lanes are flat f64 slices.
                    let mut terms = Terms::new();
                    for j in 0..i {
                        terms.push(h * h * tab.a[i][j], self.a[j][r.clone()].as_flattened());
                    }
                    let (q, v) = (q[r.clone()].as_flattened(), v[r.clone()].as_flattened());
                    let qs = self.q_stage[r].as_flattened_mut();
                    sum_into(qs, Base::Plus(q, tab.c[i] * h, v), &terms);
                }
                for (l, exact) in self.exact.iter().enumerate() {
                    if let Some(exact) = exact {
                        exact.shift_stage(i, &mut LaneMut(&mut self.q_stage, l));
                    }
                }
            }
            if i == 0 && reuse {
                self.a.swap(0, S - 1);
                self.stage_force.swap(S - 1, 0);
                for exact in self.exact.iter_mut().flatten() {
                    exact.reuse_stage(S - 1, 0);
                }
                for l in (0..LANES).filter(|&l| live[l] && !self.last_stage_current[l]) {
                    self.evals[l] += 1;
                    for &site in &self.events.touched[l] {
                        let forces = (&mut self.a[0][..], &mut self.stage_force[0][..]);
                        let patched = patch(&self.chain, q, forces, (window, l), site);
                        if let Some(exact) = self.exact[l].as_mut() {
                            for k in patched {
                                let acc = &mut LaneMut(&mut self.a[0], l);
                                exact.remove_spring_at((0, k), &Lane(q, l), acc);
                            }
                        }
                    }
                }
                continue;
            }
            for l in (0..LANES).filter(|&l| live[l]) {
                if i > 0 || !self.last_stage_current[l] {
                    self.evals[l] += 1;
                }
            }
            let qs: &[Lanes] = if i == 0 { q } else { &self.q_stage };
            accelerations(
                &self.chain,
                qs,
                (&mut self.a[i], &mut self.stage_force[i]),
                window,
            );
            for (l, exact) in self.exact.iter_mut().enumerate() {
                if let Some(exact) = exact {
                    exact.remove_springs(i, &Lane(qs, l), &mut LaneMut(&mut self.a[i], l));
                }
            }
        }
        for r in ranges {
            // DPRKN6's last stage position is the new position, computed the same way.
            self.new_q[r.clone()].copy_from_slice(&self.q_stage[r.clone()]);
            let mut terms = Terms::new();
            for i in 0..S {
                terms.push(h * tab.b_prime[i], self.a[i][r.clone()].as_flattened());
            }
            let new_v = self.new_v[r.clone()].as_flattened_mut();
            sum_into(new_v, Base::Of(v[r].as_flattened()), &terms);
        }
        for (l, exact) in self.exact.iter().enumerate() {
            if let Some(exact) = exact {
                exact.shift_velocity(&mut LaneMut(&mut self.new_v, l));
            }
        }
    }
}
