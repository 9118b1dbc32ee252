//! The batched `rkn6-contact` step: DPRKN6 on four chains in structure-of-arrays form (entry k
//! of a vector is degree of freedom k, its lanes the four scenes), then each lane's contact
//! corrections. Every lane does the scalar [`crate::integrate::Rkn`]'s operations in its order
//! (`raw_step_body`, `Model::accelerations_impl`), which is what keeps it bit-identical.

use super::events::LaneEvents;
use super::{lanewise, Lane, LaneChain, LaneMut, Lanes, LANES, S, ZERO};
use crate::force::{hertz_force, odd_power};
use crate::integrate::erkn_weights::NystromWeights;
use crate::integrate::exact_resonator::ExactResonators;
use crate::integrate::rkn::DPRKN6;
use crate::model::{Model, Window};

/// `rkn6-contact` for four lanes, with its scratch (allocated once).
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
        let n = chain.n_dof();
        let bonds = chain.n_sites + 1;
        Self {
            q_stage: vec![ZERO; n],
            a: std::array::from_fn(|_| vec![ZERO; n]),
            new_q: vec![ZERO; n],
            new_v: vec![ZERO; n],
            stage_force: std::array::from_fn(|_| vec![ZERO; bonds]),
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
        let corrected = self.events.correct(
            models,
            (&*q, &*v),
            (&mut self.new_q, &mut self.new_v),
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

    fn dof_ranges(&self, window: Window) -> [std::ops::Range<usize>; 2] {
        [
            window.lo..window.hi + 1,
            self.chain.n_sites..self.chain.n_dof(),
        ]
    }

    crate::simd::dispatched! {
        /// The uncorrected step into `new_q`, `new_v`, recording every stage's bond forces, in
        /// its AVX2 copy where the CPU has one (`crate::simd`).
        fn raw_step[&mut self](
            q: &[Lanes],
            v: &[Lanes],
            h: f64,
            window: Window,
            live: [bool; LANES],
        ) => raw_step_body, raw_step_avx2
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
        let reuse = (0..LANES)
            .all(|l| !live[l] || self.last_stage_current[l] || !self.events.touched[l].is_empty());
        for i in 0..S {
            if i > 0 {
                for r in ranges.clone() {
                    let cv = tab.c[i] * h;
                    let qs = &mut self.q_stage[r.clone()];
                    for ((qs, q), v) in qs.iter_mut().zip(&q[r.clone()]).zip(&v[r.clone()]) {
                        *qs = lanewise(*q, *v, |q, v| q + cv * v);
                    }
                    for j in 0..i {
                        let w = h * h * tab.a[i][j];
                        if w != 0.0 {
                            add_scaled(qs, &self.a[j][r.clone()], w);
                        }
                    }
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
            self.new_v[r.clone()].copy_from_slice(&v[r.clone()]);
            for i in 0..S {
                let wv = h * tab.b_prime[i];
                if wv != 0.0 {
                    add_scaled(&mut self.new_v[r.clone()], &self.a[i][r.clone()], wv);
                }
            }
        }
        for (l, exact) in self.exact.iter().enumerate() {
            if let Some(exact) = exact {
                exact.shift_velocity(&mut LaneMut(&mut self.new_v, l));
            }
        }
    }
}

/// Lane `l`'s forces of the state `q` near `site`, whose position a contact correction moved
/// after the forces `acc` and `record` (a whole evaluation's) were taken: the bonds beside it
/// and the accelerations of it and its neighbours, each by the operations [`accelerations`]
/// makes of it on `window`, so that the patched forces are a whole evaluation's bit for bit.
/// Returns the sites whose accelerations it wrote.
fn patch(
    chain: &LaneChain,
    q: &[Lanes],
    (acc, record): (&mut [Lanes], &mut [Lanes]),
    (window, l): (Window, usize),
    site: usize,
) -> std::ops::RangeInclusive<usize> {
    let n = chain.n_sites;
    let (lo, hi) = (window.lo, window.hi);
    let (u, rv) = q.split_at(n);
    let (acc_u, acc_v) = acc.split_at_mut(n);
    let [left_wall, right_wall] = chain.walls;
    // The force of bond b, between sites b - 1 and b, as the loop computes it.
    let bond = |b: usize| {
        let d = (u[b - 1][l] - u[b][l]).max(0.0);
        d * d.sqrt()
    };
    for b in [site, site + 1] {
        if b > lo && b <= hi {
            record[b][l] = bond(b);
        }
    }
    if site == 0 && lo == 0 && left_wall {
        record[0][l] = hertz_force(-u[0][l]);
    }
    if site == n - 1 && hi == n - 1 && right_wall {
        record[n][l] = hertz_force(u[n - 1][l]);
    }
    let patched = site.saturating_sub(1).max(lo)..=(site + 1).min(hi);
    for k in patched.clone() {
        let left = if k > lo { bond(k) } else { 0.0 };
        let mut a = if k < hi { left - bond(k + 1) } else { left };
        if k == 0 && left_wall {
            a += hertz_force(-u[0][l]);
        }
        if k == n - 1 && right_wall {
            a -= hertz_force(u[n - 1][l]);
        }
        for (j, r) in chain.resonators.iter().enumerate() {
            if r.site == k {
                let f = r.kappa[l] * odd_power(u[k][l] - rv[j][l], r.p);
                a -= f;
                acc_v[j][l] = f / r.eps[l];
            }
        }
        acc_u[k][l] = a;
    }
    patched
}

/// `dst += w x`, lane by lane.
#[inline(always)]
fn add_scaled(dst: &mut [Lanes], x: &[Lanes], w: f64) {
    for (d, x) in dst.iter_mut().zip(x) {
        *d = lanewise(*d, *x, |d, x| d + w * x);
    }
}

/// The paper's force loop (`Model::accelerations_impl` with `hertz_chain`, recording), lane by
/// lane: accelerations `acc` at positions `q` on `window`, and every bond force into `record`.
#[inline(always)]
fn accelerations(
    chain: &LaneChain,
    q: &[Lanes],
    (acc, record): (&mut [Lanes], &mut [Lanes]),
    window: Window,
) {
    let n = chain.n_sites;
    let (lo, hi) = (window.lo, window.hi);
    let (u, rv) = q.split_at(n);
    let (acc_u, acc_v) = acc.split_at_mut(n);
    let u_w = &u[lo..=hi];
    let acc_w = &mut acc_u[lo..=hi][..u_w.len()];
    let record_w = &mut record[lo + 1..=hi][..u_w.len() - 1];
    let mut previous = ZERO;
    for bond in 1..u_w.len() {
        let f = lanewise(u_w[bond - 1], u_w[bond], |a, b| {
            let d = (a - b).max(0.0);
            d * d.sqrt()
        });
        acc_w[bond - 1] = lanewise(previous, f, |p, f| p - f);
        record_w[bond - 1] = f;
        previous = f;
    }
    acc_w[u_w.len() - 1] = previous;
    let [left_wall, right_wall] = chain.walls;
    if lo == 0 && left_wall {
        for l in 0..LANES {
            let f = hertz_force(-u[0][l]);
            record[0][l] = f;
            acc_u[0][l] += f;
        }
    }
    if hi == n - 1 && right_wall {
        for l in 0..LANES {
            let f = hertz_force(u[n - 1][l]);
            record[n][l] = f;
            acc_u[n - 1][l] -= f;
        }
    }
    for (j, r) in chain.resonators.iter().enumerate() {
        if r.site < lo || r.site > hi {
            continue;
        }
        for l in 0..LANES {
            let f = r.kappa[l] * odd_power(u[r.site][l] - rv[j][l], r.p);
            acc_u[r.site][l] -= f;
            acc_v[j][l] = f / r.eps[l];
        }
    }
}
