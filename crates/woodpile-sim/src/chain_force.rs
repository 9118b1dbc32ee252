//! The chain's force kernel, written once: generic over the contact law ([`Law`]), over the
//! width of a value ([`Width`]: one scene's `f64`, or the lanes' group of four scenes) and
//! over what the chain loses ([`Losses`]: nothing, or the dashpots of a dissipative chain,
//! [`crate::damped_force`]); and the patch after a corrected step, generic over the law and
//! over how one scene's values are read ([`Dofs`]).
//!
//! Every force is computed by the same operations in the same order in every copy, so that
//! a scene in a lane, a patched stage and a whole evaluation give the same bits as the scalar
//! loop (tested in [`crate::force`] and by the lanes' tests). Every force of the chain acts
//! between neighbours or within a site and its resonators: that is what lets the patch
//! re-evaluate one site more on each side of what moved, and no more.

use crate::contact::Law;
use crate::dofs::{Dofs, DofsMut};
use crate::model::{odd_power, Window};
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
    /// The spring and dashpot of each soft end (left, right). A dashpot acts only through
    /// [`Losses::soft_end`]: a chain with one is dissipative.
    pub soft_ends: [Option<(f64, f64)>; 2],
}

/// What a chain loses, where the kernel asks: each hook of a conservative chain
/// ([`Lossless`]) returns the conservative force by the conservative loop's operations, so
/// that it compiles to that loop; a dissipative chain's adds its dashpots and sums their power.
pub(crate) trait Losses<V: Width> {
    /// Whether the chain dissipates: only then does the kernel sum the bonds' powers.
    const DISSIPATES: bool;

    /// Bond `bond`'s recorded force, the force it adds to the rest state's, and the power its
    /// dashpot dissipates, at relative displacement `r`, its members being `sites` (left,
    /// right; `None` for a wall).
    fn bond<L: Law>(
        &mut self,
        law: &L,
        bond: usize,
        r: V,
        sites: (Option<usize>, Option<usize>),
    ) -> (V, V, V);

    /// The power the chain's contacts dissipate, summed over its bonds left to right (asked
    /// once, before the soft ends, and only when [`Losses::DISSIPATES`]). The kernel keeps the
    /// sum in a register: summed into `self` bond by bond, it was a store and a load per bond
    /// on the loop's critical path.
    fn contacts_dissipated(&mut self, power: V);

    /// The force of a soft end (`spring`, `damping`) on its site `site`, at position `u`.
    fn soft_end(&mut self, end: (f64, f64), site: usize, u: V) -> V;

    /// What acts on the window's sites from outside the chain (ground damping), taken from
    /// their forces `acc_u`. Asked after the soft ends, always.
    fn ground(&mut self, acc_u: &mut [V], window: Window);

    /// Resonator `j`'s force on its host `site`, whose elastic part is `elastic`.
    fn resonator(&mut self, j: usize, site: usize, elastic: V) -> V;

    /// The window's accelerations from its forces `acc_u`.
    fn inertia(&self, acc_u: &mut [V], window: Window);
}

/// A conservative chain: no losses, and its sites' masses (`None` for unit masses: no
/// division).
pub(crate) struct Lossless<'a, V> {
    pub masses: Option<&'a [V]>,
}

impl<V: Width> Losses<V> for Lossless<'_, V> {
    const DISSIPATES: bool = false;

    #[inline(always)]
    fn bond<L: Law>(
        &mut self,
        law: &L,
        bond: usize,
        r: V,
        _: (Option<usize>, Option<usize>),
    ) -> (V, V, V) {
        let elastic = r.map(|r| law.elastic(bond, r));
        (elastic, elastic.map(|e| law.net(bond, e)), V::ZERO)
    }

    #[inline(always)]
    fn contacts_dissipated(&mut self, _: V) {}

    #[inline(always)]
    fn soft_end(&mut self, (spring, _): (f64, f64), _: usize, u: V) -> V {
        u.map(|u| spring * u)
    }

    #[inline(always)]
    fn ground(&mut self, _: &mut [V], _: Window) {}

    #[inline(always)]
    fn resonator(&mut self, _: usize, _: usize, elastic: V) -> V {
        elastic
    }

    #[inline(always)]
    fn inertia(&self, acc_u: &mut [V], window: Window) {
        let (lo, hi) = (window.lo, window.hi);
        if let Some(masses) = self.masses {
            for (a, m) in acc_u[lo..=hi].iter_mut().zip(&masses[lo..=hi]) {
                *a = a.zip(*m, |a, m| a / m);
            }
        }
    }
}

/// Accelerations of positions `q` (sites, then resonators) on the sites of `window` and of
/// every resonator, written into `acc`; with `record`, every bond's recorded force of the
/// window too (entry b: the bond left of site b; 0 and `n_sites` the walls). Entries outside
/// the window are left untouched: the callers keep them at their exact value while those sites
/// are at rest.
#[inline(always)]
pub(crate) fn chain_accelerations<L: Law, V: Width, K: Fn() -> V>(
    (law, frame): (&L, &Frame),
    resonators: impl Iterator<Item = Coupled<V, K>>,
    losses: &mut impl Losses<V>,
    (q, acc): (&[V], &mut [V]),
    window: Window,
    record: Option<&mut [V]>,
) {
    let n = frame.n_sites;
    let (lo, hi) = (window.lo, window.hi);
    debug_assert!(lo <= hi && hi < n);
    let (u, rv) = q.split_at(n);
    let (acc_u, acc_v) = acc.split_at_mut(n);
    contact_chain((law, frame.walls), losses, u, acc_u, window, record);
    if frame.soft_ends.iter().any(Option::is_some) {
        soft_ends(frame.soft_ends, losses, u, acc_u, window);
    }
    losses.ground(acc_u, window);
    for (j, r) in resonators.enumerate() {
        if r.site < lo || r.site > hi {
            continue;
        }
        let stretch = u[r.site].zip(rv[j], |host, own| host - own);
        let elastic = (r.kappa)().zip(stretch, |kappa, x| kappa * odd_power(x, r.p));
        let f = losses.resonator(j, r.site, elastic);
        acc_u[r.site] = acc_u[r.site].zip(f, |a, f| a - f);
        acc_v[j] = f.zip(r.eps, |f, eps| f / eps);
    }
    losses.inertia(acc_u, window);
}

/// The contact forces on the sites of `window`, written into `acc_u`; with `record`, every
/// bond's recorded force. Each site's force is (left bond) − (right bond), computed in one
/// pass with the previous bond's force in a register: every acceleration is written once
/// (no store-to-load chain). The recording loop is a separate copy so that the plain one
/// carries no extra store. The bonds are evaluated left to right, walls included, which is
/// the order a dissipative chain sums its dashpots' power in.
#[inline(always)]
fn contact_chain<L: Law, V: Width, Lo: Losses<V>>(
    (law, [left_wall, right_wall]): (&L, [bool; 2]),
    losses: &mut Lo,
    u: &[V],
    acc_u: &mut [V],
    window: Window,
    mut record: Option<&mut [V]>,
) {
    let (lo, hi) = (window.lo, window.hi);
    let n = u.len();
    // The dissipated power, summed in the bonds' order (left wall, inner bonds, right wall).
    let mut power = V::ZERO;
    let mut dissipated = |p: V| {
        if Lo::DISSIPATES {
            power = power.zip(p, |sum, p| sum + p);
        }
    };
    let left = (lo == 0 && left_wall).then(|| {
        let r = u[0].map(|u| -u);
        let (recorded, f, p) = losses.bond(law, 0, r, (None, Some(0)));
        dissipated(p);
        (recorded, f)
    });
    let u_w = &u[lo..=hi];
    let acc_w = &mut acc_u[lo..=hi][..u_w.len()];
    let mut previous = V::ZERO;
    match record.as_deref_mut() {
        None => {
            for i in 1..u_w.len() {
                let (_, f, p) = inner_bond(law, losses, u_w, (lo, i));
                dissipated(p);
                acc_w[i - 1] = previous.zip(f, |p, f| p - f);
                previous = f;
            }
        }
        Some(record) => {
            let record_w = &mut record[lo + 1..=hi][..u_w.len() - 1];
            for i in 1..u_w.len() {
                let (recorded, f, p) = inner_bond(law, losses, u_w, (lo, i));
                dissipated(p);
                acc_w[i - 1] = previous.zip(f, |p, f| p - f);
                record_w[i - 1] = recorded;
                previous = f;
            }
        }
    }
    acc_w[u_w.len() - 1] = previous;
    if let Some((recorded, f)) = left {
        if let Some(record) = record.as_deref_mut() {
            record[0] = recorded;
        }
        acc_u[0] = acc_u[0].zip(f, |a, f| a + f);
    }
    if hi == n - 1 && right_wall {
        let (recorded, f, p) = losses.bond(law, n, u[n - 1], (Some(n - 1), None));
        dissipated(p);
        if let Some(record) = record {
            record[n] = recorded;
        }
        acc_u[n - 1] = acc_u[n - 1].zip(f, |a, f| a - f);
    }
    if Lo::DISSIPATES {
        losses.contacts_dissipated(power);
    }
}

/// The forces of the bond between the window's sites `i − 1` and `i` (`u_w`: the window's
/// positions, starting at site `lo`): its recorded and its net force, and its dashpot's power.
#[inline(always)]
fn inner_bond<L: Law, V: Width>(
    law: &L,
    losses: &mut impl Losses<V>,
    u_w: &[V],
    (lo, i): (usize, usize),
) -> (V, V, V) {
    let r = u_w[i - 1].zip(u_w[i], |l, r| l - r);
    losses.bond(law, lo + i, r, (Some(lo + i - 1), Some(lo + i)))
}

/// The soft ends' forces, taken from the window's end sites. Out of line: the force loop of
/// chains without them should not carry it.
#[inline(never)]
#[cold]
fn soft_ends<V: Width>(
    ends: [Option<(f64, f64)>; 2],
    losses: &mut impl Losses<V>,
    u: &[V],
    acc_u: &mut [V],
    window: Window,
) {
    let last = u.len() - 1;
    if let (0, Some(end)) = (window.lo, ends[0]) {
        let f = losses.soft_end(end, 0, u[0]);
        acc_u[0] = acc_u[0].zip(f, |a, f| a - f);
    }
    if let (true, Some(end)) = (window.hi == last, ends[1]) {
        let f = losses.soft_end(end, last, u[last]);
        acc_u[last] = acc_u[last].zip(f, |a, f| a - f);
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
        if let (0, Some((spring, _))) = (k, frame.soft_ends[0]) {
            a -= spring * q.at(0);
        }
        if let (true, Some((spring, _))) = (k == n - 1, frame.soft_ends[1]) {
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
