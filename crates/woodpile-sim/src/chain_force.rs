//! The conservative chain's force kernel, written once: generic over the contact law
//! ([`Law`]) and over the width of a value ([`Width`]: one scene's `f64`, or the lanes' group
//! of four scenes), and the patch after a corrected step, generic over the law and over how
//! one scene's values are read ([`Dofs`]).
//!
//! Every force is computed by the same operations in the same order in every copy, so that
//! a scene in a lane, a patched stage and a whole evaluation give the same bits as the scalar
//! loop (tested in [`crate::force`] and by the lanes' tests). Every force of the chain acts
//! between neighbours or within a site and its resonators: that is what lets the patch
//! re-evaluate one site more on each side of what moved, and no more.

use crate::contact::Law;
use crate::force::odd_power;
use crate::integrate::exact_resonator::{Dofs, DofsMut};
use crate::model::Window;
use std::ops::RangeInclusive;

/// A value of the force loops: one scene's (`f64`), or one per scene of a group of lanes
/// (`[f64; N]`), on which every operation acts lane by lane.
pub(crate) trait Width: Copy {
    /// Zero in every lane.
    const ZERO: Self;

    /// `op` on each lane.
    fn map(self, op: impl Fn(f64) -> f64) -> Self;

    /// `op` on each lane of `self` and `other`.
    fn zip(self, other: Self, op: impl Fn(f64, f64) -> f64) -> Self;
}

impl Width for f64 {
    const ZERO: f64 = 0.0;

    #[inline(always)]
    fn map(self, op: impl Fn(f64) -> f64) -> f64 {
        op(self)
    }

    #[inline(always)]
    fn zip(self, other: f64, op: impl Fn(f64, f64) -> f64) -> f64 {
        op(self, other)
    }
}

/// Whole-lane operations on arrays are what the compiler turns into packed instructions;
/// element by element it reloads every pointer (docs/performance.md).
impl<const N: usize> Width for [f64; N] {
    const ZERO: [f64; N] = [0.0; N];

    #[inline(always)]
    fn map(self, op: impl Fn(f64) -> f64) -> [f64; N] {
        std::array::from_fn(|l| op(self[l]))
    }

    #[inline(always)]
    fn zip(self, other: [f64; N], op: impl Fn(f64, f64) -> f64) -> [f64; N] {
        std::array::from_fn(|l| op(self[l], other[l]))
    }
}

/// A resonator as the force loops read it: its host, its exponent, its mass ratio, and its
/// coupling at the time of the evaluation (one per lane), computed only for a resonator whose
/// host the loop reaches (a ramp's costs a `tanh`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Coupled<V, K: Fn() -> V> {
    pub site: usize,
    pub p: u32,
    pub eps: V,
    pub kappa: K,
}

/// What the force loops read of a chain besides its law, its resonators and its masses.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    pub n_sites: usize,
    /// Whether a wall lies beyond the first and the last site.
    pub walls: [bool; 2],
    /// The springs of soft ends (left, right). A soft end's dashpot makes the chain
    /// dissipative, and its forces then come from [`crate::damped_force`].
    pub springs: [Option<f64>; 2],
}

/// Accelerations of positions `q` (sites, then resonators) on the sites of `window` and of
/// every resonator, written into `acc`; with `record`, every bond's elastic force of the window
/// too (entry b: the bond left of site b; 0 and `n_sites` the walls). Entries outside the
/// window are left untouched: the callers keep them at their exact value while those sites
/// are at rest. `masses` are the sites' (none: unit masses, and no division).
#[inline(always)]
pub(crate) fn chain_accelerations<L: Law, V: Width, K: Fn() -> V>(
    (law, frame): (&L, &Frame),
    resonators: impl Iterator<Item = Coupled<V, K>>,
    masses: Option<&[V]>,
    (q, acc): (&[V], &mut [V]),
    window: Window,
    record: Option<&mut [V]>,
) {
    let n = frame.n_sites;
    let (lo, hi) = (window.lo, window.hi);
    debug_assert!(lo <= hi && hi < n);
    let (u, rv) = q.split_at(n);
    let (acc_u, acc_v) = acc.split_at_mut(n);
    contact_chain(law, frame.walls, u, acc_u, window, record);
    if frame.springs.iter().any(Option::is_some) {
        spring_ends(frame.springs, u, acc_u, window);
    }
    for (j, r) in resonators.enumerate() {
        if r.site < lo || r.site > hi {
            continue;
        }
        let stretch = u[r.site].zip(rv[j], |host, own| host - own);
        let f = (r.kappa)().zip(stretch, |kappa, x| kappa * odd_power(x, r.p));
        acc_u[r.site] = acc_u[r.site].zip(f, |a, f| a - f);
        acc_v[j] = f.zip(r.eps, |f, eps| f / eps);
    }
    if let Some(masses) = masses {
        for (a, m) in acc_u[lo..=hi].iter_mut().zip(&masses[lo..=hi]) {
            *a = a.zip(*m, |a, m| a / m);
        }
    }
}

/// The contact forces on the sites of `window`, written into `acc_u`; with `record`, every
/// bond's elastic force. Each site's force is (left bond) − (right bond), computed in one
/// pass with the previous bond's force in a register: every acceleration is written once
/// (no store-to-load chain). The recording loop is a separate copy so that the plain one
/// carries no extra store.
#[inline(always)]
fn contact_chain<L: Law, V: Width>(
    law: &L,
    [left_wall, right_wall]: [bool; 2],
    u: &[V],
    acc_u: &mut [V],
    window: Window,
    mut record: Option<&mut [V]>,
) {
    let (lo, hi) = (window.lo, window.hi);
    let n = u.len();
    let u_w = &u[lo..=hi];
    let acc_w = &mut acc_u[lo..=hi][..u_w.len()];
    let elastic = |bond: usize, left: V, right: V| left.zip(right, |l, r| law.elastic(bond, l - r));
    let net = |bond: usize, elastic: V| elastic.map(|e| law.net(bond, e));
    let mut previous = V::ZERO;
    match record.as_deref_mut() {
        None => {
            for i in 1..u_w.len() {
                let f = net(lo + i, elastic(lo + i, u_w[i - 1], u_w[i]));
                acc_w[i - 1] = previous.zip(f, |p, f| p - f);
                previous = f;
            }
        }
        Some(record) => {
            let record_w = &mut record[lo + 1..=hi][..u_w.len() - 1];
            for i in 1..u_w.len() {
                let e = elastic(lo + i, u_w[i - 1], u_w[i]);
                let f = net(lo + i, e);
                acc_w[i - 1] = previous.zip(f, |p, f| p - f);
                record_w[i - 1] = e;
                previous = f;
            }
        }
    }
    acc_w[u_w.len() - 1] = previous;
    if lo == 0 && left_wall {
        let e = u[0].map(|u| law.elastic(0, -u));
        if let Some(record) = record.as_deref_mut() {
            record[0] = e;
        }
        acc_u[0] = acc_u[0].zip(net(0, e), |a, f| a + f);
    }
    if hi == n - 1 && right_wall {
        let e = u[n - 1].map(|u| law.elastic(n, u));
        if let Some(record) = record {
            record[n] = e;
        }
        acc_u[n - 1] = acc_u[n - 1].zip(net(n, e), |a, f| a - f);
    }
}

/// The springs of soft ends, added to the window's end sites. Out of line: the force loop of
/// chains without them should not carry it.
#[inline(never)]
#[cold]
fn spring_ends<V: Width>(springs: [Option<f64>; 2], u: &[V], acc_u: &mut [V], window: Window) {
    let last = u.len() - 1;
    if let (0, Some(spring)) = (window.lo, springs[0]) {
        acc_u[0] = acc_u[0].zip(u[0], |a, u| a - spring * u);
    }
    if let (true, Some(spring)) = (window.hi == last, springs[1]) {
        acc_u[last] = acc_u[last].zip(u[last], |a, u| a - spring * u);
    }
}

/// One scene's forces of positions `q` near `sites`, whose positions a contact correction
/// moved after `acc` and `record` (a whole evaluation's on `window`, as
/// [`chain_accelerations`] writes them) were taken: the bonds beside them and the
/// accelerations of them and their neighbours, each by the operations the whole evaluation
/// makes of it, so that the patched forces are a whole evaluation's bit for bit. Each bond is
/// evaluated once, in the chain loop's order. Returns the sites whose accelerations it wrote.
#[allow(clippy::too_many_arguments)]
pub(crate) fn patch<L: Law, K: Fn() -> f64, Q: Dofs + ?Sized, A: DofsMut + ?Sized>(
    (law, frame): (&L, &Frame),
    resonators: impl Iterator<Item = Coupled<f64, K>> + Clone,
    masses: Option<&Q>,
    q: &Q,
    (acc, record): (&mut A, &mut A),
    window: Window,
    sites: RangeInclusive<usize>,
) -> RangeInclusive<usize> {
    let n = frame.n_sites;
    let (lo, hi) = (window.lo, window.hi);
    let [left_wall, right_wall] = frame.walls;
    let forces = |b: usize, r: f64| {
        let e = law.elastic(b, r);
        (e, law.net(b, e))
    };
    let bond = |b: usize| forces(b, q.at(b - 1) - q.at(b));
    let left_wall_force = || forces(0, -q.at(0));
    let right_wall_force = || forces(n, q.at(n - 1));
    if *sites.start() == 0 && lo == 0 && left_wall {
        record.set(0, left_wall_force().0);
    }
    if *sites.end() == n - 1 && hi == n - 1 && right_wall {
        record.set(n, right_wall_force().0);
    }
    let patched = sites.start().saturating_sub(1).max(lo)..=(sites.end() + 1).min(hi);
    let mut left = (0.0, 0.0);
    if *patched.start() > lo {
        left = bond(*patched.start());
        record.set(*patched.start(), left.0);
    }
    for k in patched.clone() {
        let mut a = left.1;
        if k < hi {
            let right = bond(k + 1);
            record.set(k + 1, right.0);
            a = left.1 - right.1;
            left = right;
        }
        if k == 0 && left_wall {
            a += left_wall_force().1;
        }
        if k == n - 1 && right_wall {
            a -= right_wall_force().1;
        }
        if let (0, Some(spring)) = (k, frame.springs[0]) {
            a -= spring * q.at(0);
        }
        if let (true, Some(spring)) = (k == n - 1, frame.springs[1]) {
            a -= spring * q.at(n - 1);
        }
        for (j, r) in resonators.clone().enumerate() {
            if r.site == k {
                let f = (r.kappa)() * odd_power(q.at(k) - q.at(n + j), r.p);
                a -= f;
                acc.set(n + j, f / r.eps);
            }
        }
        if let Some(masses) = masses {
            a /= masses.at(k);
        }
        acc.set(k, a);
    }
    patched
}
