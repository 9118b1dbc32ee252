//! The force loop of four lanes: `Model::accelerations_impl` (with `hertz_chain` or
//! `law_chain`, the soft ends' springs, the resonators and the site masses), recording every
//! bond force, lane by lane in its operations and their order; and `patch`, the same forces
//! evaluated again at a few sites of one lane.

use super::{lanewise, LaneChain, Lanes, LANES, ZERO};
use crate::contact::ContactLaw;
use crate::force::{hertz_force, odd_power};
use crate::model::Window;

/// A bond's elastic force (what is recorded) and its force beyond the rest state's (what
/// pushes), at relative displacement `r` = left − right, as the scalar loop computes them.
#[inline(always)]
fn bond_force(contacts: Option<&ContactLaw>, bond: usize, r: f64) -> (f64, f64) {
    match contacts {
        None => {
            let d = r.max(0.0);
            let f = d * d.sqrt();
            (f, f)
        }
        Some(law) => {
            let elastic = law.elastic(bond, r);
            (elastic, elastic - law.static_force(bond))
        }
    }
}

/// A wall's elastic and net force at relative displacement `r` (−u₀ on the left, u_last on
/// the right), as the scalar loop computes them.
#[inline(always)]
fn wall_force(contacts: Option<&ContactLaw>, bond: usize, r: f64) -> (f64, f64) {
    match contacts {
        None => {
            let f = hertz_force(r);
            (f, f)
        }
        Some(law) => {
            let elastic = law.elastic(bond, r);
            (elastic, elastic - law.static_force(bond))
        }
    }
}

/// Accelerations `acc` at positions `q` on `window` for every lane, and every bond's elastic
/// force into `record` (entry b: the bond left of site b; 0 and n_sites the walls).
#[inline(always)]
pub(super) fn accelerations(
    chain: &LaneChain,
    q: &[Lanes],
    (acc, record): (&mut [Lanes], &mut [Lanes]),
    window: Window,
) {
    let n = chain.n_sites;
    let (lo, hi) = (window.lo, window.hi);
    let (u, rv) = q.split_at(n);
    let (acc_u, acc_v) = acc.split_at_mut(n);
    match &chain.contacts {
        None => hertz_chain(&u[lo..=hi], (&mut acc_u[lo..=hi], &mut record[lo + 1..=hi])),
        Some(law) => law_chain(law, (u, lo, hi), (acc_u, record)),
    }
    let contacts = chain.contacts.as_ref();
    let [left_wall, right_wall] = chain.walls;
    for l in 0..LANES {
        if lo == 0 && left_wall {
            let (elastic, net) = wall_force(contacts, 0, -u[0][l]);
            record[0][l] = elastic;
            acc_u[0][l] += net;
        }
        if hi == n - 1 && right_wall {
            let (elastic, net) = wall_force(contacts, n, u[n - 1][l]);
            record[n][l] = elastic;
            acc_u[n - 1][l] -= net;
        }
    }
    if let (0, Some(spring)) = (lo, chain.springs[0]) {
        acc_u[0] = lanewise(acc_u[0], u[0], |a, u| a - spring * u);
    }
    if let (true, Some(spring)) = (hi == n - 1, chain.springs[1]) {
        acc_u[n - 1] = lanewise(acc_u[n - 1], u[n - 1], |a, u| a - spring * u);
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
    if let Some(masses) = &chain.masses {
        for (a, m) in acc_u[lo..=hi].iter_mut().zip(&masses[lo..=hi]) {
            *a = lanewise(*a, *m, |a, m| a / m);
        }
    }
}

/// The paper's contacts on the window's sites `u_w`, `acc_w` and `record_w` being the
/// window's accelerations and inner bonds: each site's force is (left bond) − (right bond),
/// the previous bond's force carried in a register, as `hertz_chain` does.
#[inline(always)]
fn hertz_chain(u_w: &[Lanes], (acc_w, record_w): (&mut [Lanes], &mut [Lanes])) {
    let acc_w = &mut acc_w[..u_w.len()];
    let record_w = &mut record_w[..u_w.len() - 1];
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
}

/// The experiment's contacts ([`ContactLaw`]) on the sites `lo..=hi`, as `law_chain` does.
#[inline(always)]
fn law_chain(
    law: &ContactLaw,
    (u, lo, hi): (&[Lanes], usize, usize),
    (acc_u, record): (&mut [Lanes], &mut [Lanes]),
) {
    let mut previous = ZERO;
    for bond in lo + 1..=hi {
        let elastic = lanewise(u[bond - 1], u[bond], |a, b| law.elastic(bond, a - b));
        record[bond] = elastic;
        let rest = law.static_force(bond);
        let f = elastic.map(|e| e - rest);
        acc_u[bond - 1] = lanewise(previous, f, |p, f| p - f);
        previous = f;
    }
    acc_u[hi] = previous;
}

/// Lane `l`'s forces of the state `q` near `site`, whose position a contact correction moved
/// after the forces `acc` and `record` (a whole evaluation's) were taken: the bonds beside it
/// and the accelerations of it and its neighbours, each by the operations [`accelerations`]
/// makes of it on `window`, so that the patched forces are a whole evaluation's bit for bit.
/// Returns the sites whose accelerations it wrote. This relies on every force of the chain
/// acting between neighbours or within a site and its resonators: a longer-range force would
/// need a wider patch.
pub(super) fn patch(
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
    let contacts = chain.contacts.as_ref();
    let [left_wall, right_wall] = chain.walls;
    let bond = |b: usize| bond_force(contacts, b, u[b - 1][l] - u[b][l]);
    for b in [site, site + 1] {
        if b > lo && b <= hi {
            record[b][l] = bond(b).0;
        }
    }
    if site == 0 && lo == 0 && left_wall {
        record[0][l] = wall_force(contacts, 0, -u[0][l]).0;
    }
    if site == n - 1 && hi == n - 1 && right_wall {
        record[n][l] = wall_force(contacts, n, u[n - 1][l]).0;
    }
    let patched = site.saturating_sub(1).max(lo)..=(site + 1).min(hi);
    for k in patched.clone() {
        let left = if k > lo { bond(k).1 } else { 0.0 };
        let mut a = if k < hi { left - bond(k + 1).1 } else { left };
        if k == 0 && left_wall {
            a += wall_force(contacts, 0, -u[0][l]).1;
        }
        if k == n - 1 && right_wall {
            a -= wall_force(contacts, n, u[n - 1][l]).1;
        }
        if let (0, Some(spring)) = (k, chain.springs[0]) {
            a -= spring * u[0][l];
        }
        if let (true, Some(spring)) = (k == n - 1, chain.springs[1]) {
            a -= spring * u[n - 1][l];
        }
        for (j, r) in chain.resonators.iter().enumerate() {
            if r.site == k {
                let f = r.kappa[l] * odd_power(u[k][l] - rv[j][l], r.p);
                a -= f;
                acc_v[j][l] = f / r.eps[l];
            }
        }
        if let Some(masses) = &chain.masses {
            a /= masses[k][l];
        }
        acc_u[k][l] = a;
    }
    patched
}
