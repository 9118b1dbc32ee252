//! The right-hand side: accelerations from positions (paper Eqs. 3 and 7 with per-site masses).
//!
//! This is the hot loop of every integrator. It allocates nothing, calls nothing dynamic, and
//! evaluates a power 3/2 only for compressed contacts: at any moment only a handful of the
//! chain's contacts are closed.

use crate::contact::ContactLaw;
use crate::model::{Model, Window};

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

/// `x^p` for the odd coupling exponents (p = 1 is the common case and skips `powi`).
#[inline(always)]
pub fn odd_power(x: f64, p: u32) -> f64 {
    match p {
        1 => x,
        3 => x * x * x,
        _ => x.powi(p as i32),
    }
}

impl Model {
    /// Accelerations `q'' = M^{-1} F(t, q)` for positions `q` (length `n_dof`), written into
    /// `acc` (same length).
    pub fn accelerations(&self, t: f64, q: &[f64], acc: &mut [f64]) {
        self.accelerations_in(t, q, acc, Window::full(self));
    }

    /// [`Model::accelerations`] for the sites of `window` (and every resonator). Entries of
    /// `acc` outside the window are left untouched: the caller keeps them at zero, which is
    /// their exact value while those sites are at rest.
    pub fn accelerations_in(&self, t: f64, q: &[f64], acc: &mut [f64], window: Window) {
        self.accelerations_dispatched(t, q, acc, window, None);
    }

    /// [`Model::accelerations_in`] that also writes every contact force of the window into
    /// `bond_force` (length `n_sites + 1`): entry `b + 1` is the bond between sites `b` and
    /// `b + 1`, entry 0 the left wall, entry `n_sites` the right wall (0 for free ends). The
    /// contact-event correction of `rk4-contact` reads them.
    pub(crate) fn accelerations_recording(
        &self,
        t: f64,
        q: &[f64],
        acc: &mut [f64],
        window: Window,
        bond_force: &mut [f64],
    ) {
        self.accelerations_dispatched(t, q, acc, window, Some(bond_force));
    }

    crate::simd::dispatched! {
        /// The force loop, in its AVX2 or AVX-512 copy where the CPU has one (`crate::simd`).
        fn accelerations_dispatched[&self](
            t: f64,
            q: &[f64],
            acc: &mut [f64],
            window: Window,
            bond_force: Option<&mut [f64]>,
        ) => accelerations_impl, accelerations_avx2, accelerations_avx512
    }

    #[inline(always)]
    fn accelerations_impl(
        &self,
        t: f64,
        q: &[f64],
        acc: &mut [f64],
        window: Window,
        bond_force: Option<&mut [f64]>,
    ) {
        let n_sites = self.n_sites();
        debug_assert_eq!(q.len(), self.n_dof());
        debug_assert_eq!(acc.len(), self.n_dof());
        debug_assert!(window.lo <= window.hi && window.hi < n_sites);
        let (u, v) = q.split_at(n_sites);
        let (acc_u, acc_v) = acc.split_at_mut(n_sites);
        let (lo, hi) = (window.lo, window.hi);

        match self.contacts() {
            None => Self::hertz_chain(self.walls(), u, acc_u, window, bond_force),
            Some(law) => Self::law_chain(law, self.walls(), u, acc_u, window, bond_force),
        }
        if self.has_soft_end() {
            self.spring_ends(u, acc_u, window);
        }
        for (j, r) in self.resonators().iter().enumerate() {
            if r.site < lo || r.site > hi {
                continue;
            }
            let f = r.coupling.at(t) * odd_power(u[r.site] - v[j], r.p);
            acc_u[r.site] -= f;
            acc_v[j] = f / r.eps;
        }
        if let Some(masses) = self.site_masses() {
            for (a, m) in acc_u[lo..=hi].iter_mut().zip(&masses[lo..=hi]) {
                *a /= m;
            }
        }
    }

    /// The paper's contact forces on the sites of `window` (unit coefficients, exponent 3/2,
    /// no precompression), written into `acc_u`; with `bond_force`, every bond force too.
    #[inline(always)]
    fn hertz_chain(
        [left_wall, right_wall]: [bool; 2],
        u: &[f64],
        acc_u: &mut [f64],
        window: Window,
        bond_force: Option<&mut [f64]>,
    ) {
        let (lo, hi) = (window.lo, window.hi);
        let n_sites = u.len();
        // Each site's force is (left bond) - (right bond). Computing it in one pass with the
        // previous bond's force in a register writes every acceleration once (no store to load
        // chain), and max(d, 0)^{3/2} has no branch to mispredict on the many barely-touching
        // contacts behind the wave. Same bits as accumulating bond by bond. The recording loop
        // is a separate copy so that the plain one carries no extra store.
        let u_w = &u[lo..=hi];
        let acc_w = &mut acc_u[lo..=hi][..u_w.len()];
        let mut previous = 0.0;
        match bond_force {
            None => {
                for bond in 1..u_w.len() {
                    let d = (u_w[bond - 1] - u_w[bond]).max(0.0);
                    let f = d * d.sqrt();
                    acc_w[bond - 1] = previous - f;
                    previous = f;
                }
            }
            Some(record) => {
                let record_w = &mut record[lo + 1..=hi][..u_w.len() - 1];
                for bond in 1..u_w.len() {
                    let d = (u_w[bond - 1] - u_w[bond]).max(0.0);
                    let f = d * d.sqrt();
                    acc_w[bond - 1] = previous - f;
                    record_w[bond - 1] = f;
                    previous = f;
                }
                if lo == 0 && left_wall {
                    record[0] = hertz_force(-u[0]);
                }
                if hi == n_sites - 1 && right_wall {
                    record[n_sites] = hertz_force(u[n_sites - 1]);
                }
            }
        }
        acc_w[u_w.len() - 1] = previous;
        if lo == 0 && left_wall {
            acc_u[0] += hertz_force(-u[0]);
        }
        if hi == n_sites - 1 && right_wall {
            acc_u[n_sites - 1] -= hertz_force(u[n_sites - 1]);
        }
    }

    /// [`Model::hertz_chain`] under a [`ContactLaw`]: each bond's force beyond its static one,
    /// a_b [δ_b + u_left − u_right]_+^α − F_b. A recorded bond force is the elastic part
    /// a_b \[c_b\]_+^α, positive exactly while the contact is closed, as the contact-event scan
    /// needs; the static part is constant over a step, so every quadrature integrates it exactly
    /// and the event correction may leave it out.
    #[inline(always)]
    fn law_chain(
        law: &ContactLaw,
        [left_wall, right_wall]: [bool; 2],
        u: &[f64],
        acc_u: &mut [f64],
        window: Window,
        mut bond_force: Option<&mut [f64]>,
    ) {
        let (lo, hi) = (window.lo, window.hi);
        let n_sites = u.len();
        let mut previous = 0.0;
        for bond in lo + 1..=hi {
            let elastic = law.elastic(bond, u[bond - 1] - u[bond]);
            if let Some(record) = bond_force.as_deref_mut() {
                record[bond] = elastic;
            }
            let f = elastic - law.static_force(bond);
            acc_u[bond - 1] = previous - f;
            previous = f;
        }
        acc_u[hi] = previous;
        if lo == 0 && left_wall {
            let elastic = law.elastic(0, -u[0]);
            if let Some(record) = bond_force.as_deref_mut() {
                record[0] = elastic;
            }
            acc_u[0] += elastic - law.static_force(0);
        }
        if hi == n_sites - 1 && right_wall {
            let elastic = law.elastic(n_sites, u[n_sites - 1]);
            if let Some(record) = bond_force {
                record[n_sites] = elastic;
            }
            acc_u[n_sites - 1] -= elastic - law.static_force(n_sites);
        }
    }

    /// The forces of positions `q` near `sites`, whose positions a contact correction moved
    /// after `acc` and `record` (a whole evaluation's on `window`, as
    /// [`Model::accelerations_recording`] writes them) were taken: the bonds beside them and
    /// the accelerations of them and their neighbours, each by the operations the whole
    /// evaluation makes of it, so that the patched forces are a whole evaluation's bit for bit
    /// (tested). Each bond is evaluated once, in the chain loop's order. Returns the sites
    /// whose accelerations it wrote. Every force of the chain acts between neighbours or
    /// within a site and its resonators, which is why one site more on each side suffices.
    pub(crate) fn patch_accelerations(
        &self,
        t: f64,
        q: &[f64],
        (acc, record): (&mut [f64], &mut [f64]),
        window: Window,
        sites: std::ops::RangeInclusive<usize>,
    ) -> std::ops::RangeInclusive<usize> {
        let n = self.n_sites();
        let (lo, hi) = (window.lo, window.hi);
        let (u, v) = q.split_at(n);
        let (acc_u, acc_v) = acc.split_at_mut(n);
        let [left_wall, right_wall] = self.walls();
        let bond = |b: usize| self.contact_forces(b, u[b - 1] - u[b]);
        if *sites.start() == 0 && lo == 0 && left_wall {
            record[0] = self.contact_forces(0, -u[0]).0;
        }
        if *sites.end() == n - 1 && hi == n - 1 && right_wall {
            record[n] = self.contact_forces(n, u[n - 1]).0;
        }
        let patched = sites.start().saturating_sub(1).max(lo)..=(sites.end() + 1).min(hi);
        let mut left = (0.0, 0.0);
        if *patched.start() > lo {
            left = bond(*patched.start());
            record[*patched.start()] = left.0;
        }
        for k in patched.clone() {
            let mut a = left.1;
            if k < hi {
                let right = bond(k + 1);
                record[k + 1] = right.0;
                a = left.1 - right.1;
                left = right;
            }
            a = self.patched_ends(k, u, a);
            for (j, r) in self.resonators().iter().enumerate() {
                if r.site == k {
                    let f = r.coupling.at(t) * odd_power(u[k] - v[j], r.p);
                    a -= f;
                    acc_v[j] = f / r.eps;
                }
            }
            if let Some(masses) = self.site_masses() {
                a /= masses[k];
            }
            acc_u[k] = a;
        }
        patched
    }

    /// Contact `b`'s (recorded, acting) force at overlap `d`: the paper's \[d\]_+^{3/2} for
    /// both, or the law's elastic part and that less its static part, with the operations of
    /// the chain loops and the walls ([`hertz_force`] gives the loop's max(d, 0)^{3/2} bits for
    /// every d, NaN included).
    fn contact_forces(&self, b: usize, d: f64) -> (f64, f64) {
        match self.contacts() {
            None => (hertz_force(d), hertz_force(d)),
            Some(law) => {
                let elastic = law.elastic(b, d);
                (elastic, elastic - law.static_force(b))
            }
        }
    }

    /// Site `k`'s acceleration `a` (its bonds' part) with what a wall or a soft end adds there,
    /// in the whole evaluation's order: the wall's contact, then the spring.
    fn patched_ends(&self, k: usize, u: &[f64], mut a: f64) -> f64 {
        let last = self.n_sites() - 1;
        let [left_wall, right_wall] = self.walls();
        if k == 0 && left_wall {
            a += self.contact_forces(0, -u[0]).1;
        }
        if k == last && right_wall {
            a -= self.contact_forces(last + 1, u[last]).1;
        }
        if let (0, Some((spring, _))) = (k, self.boundary().left().soft()) {
            a -= spring * u[0];
        }
        if let (true, Some((spring, _))) = (k == last, self.boundary().right().soft()) {
            a -= spring * u[last];
        }
        a
    }

    /// The springs of soft ends (without dashpots: a model with one is dissipative and runs
    /// [`Model::damped_accelerations_in`]), added to the window's end sites. Out of line: the
    /// force loop of chains without them should not carry it.
    #[inline(never)]
    #[cold]
    fn spring_ends(&self, u: &[f64], acc_u: &mut [f64], window: Window) {
        let last = self.n_sites() - 1;
        if let (0, Some((spring, _))) = (window.lo, self.boundary().left().soft()) {
            acc_u[0] -= spring * u[0];
        }
        if let (true, Some((spring, _))) = (window.hi == last, self.boundary().right().soft()) {
            acc_u[last] -= spring * u[last];
        }
    }

    /// First-order form `y' = (q', q'')` of the equations of motion, for Runge–Kutta methods.
    pub fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.rhs_in(t, y, dy, Window::full(self));
    }

    /// [`Model::rhs`] for the sites of `window`; entries outside it are left untouched.
    /// A dissipative model's state ends with D, whose rate is the dissipated power.
    pub fn rhs_in(&self, t: f64, y: &[f64], dy: &mut [f64], window: Window) {
        let n_dof = self.n_dof();
        let (q, qdot) = y.split_at(n_dof);
        let (dq, dqdot) = dy.split_at_mut(n_dof);
        for range in window.dof_ranges(self) {
            dq[range.clone()].copy_from_slice(&qdot[range]);
        }
        if self.is_dissipative() {
            let power = self.damped_accelerations_in(t, (q, qdot), dqdot, window);
            dqdot[n_dof] = power;
        } else {
            self.accelerations_in(t, q, dqdot, window);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Boundary, Resonator};

    /// The force is minus the gradient of the potential energy: check by central differences.
    #[test]
    fn force_is_minus_gradient_of_potential() {
        let res = vec![
            Resonator::constant(1, 0.7, 1.3, 1),
            Resonator::constant(2, 2.0, 0.4, 3),
        ];
        let masses = Some(vec![1.0, 2.0, 0.5, 1.5]);
        let model = Model::with_masses(4, Boundary::Fixed, res, masses).unwrap();
        let q = vec![0.3, 0.1, -0.2, 0.25, 0.05, 0.4];
        let mut acc = vec![0.0; 6];
        model.accelerations(0.0, &q, &mut acc);
        let mut y = vec![0.0; 12];
        let h = 1e-6;
        for i in 0..6 {
            y[..6].copy_from_slice(&q);
            y[i] += h;
            let up = crate::energy::total_energy(&model, 0.0, &y);
            y[i] -= 2.0 * h;
            let down = crate::energy::total_energy(&model, 0.0, &y);
            let force = -(up - down) / (2.0 * h);
            let mass = 1.0 / model.inv_mass()[i];
            assert!(
                (force - mass * acc[i]).abs() < 1e-8,
                "dof {i}: {force} vs {}",
                mass * acc[i]
            );
        }
    }

    /// A chain of the audit's kinds (walls or free ends, resonators of every exponent, the
    /// experiment's contact laws, masses, precompression), given soft ends without dashpots on
    /// every third.
    fn patch_test_model(rng: &mut crate::testing::Lcg, k: usize) -> Model {
        use crate::testing::{audit_scene, chain_audit_scene};
        let model = match k % 2 {
            0 => chain_audit_scene(rng).model,
            _ => audit_scene(rng).model,
        };
        if !k.is_multiple_of(3) {
            return model;
        }
        let soft = |spring| crate::End::Soft {
            spring,
            damping: 0.0,
        };
        let n = model.n_sites();
        let masses = (0..n).map(|i| model.site_mass(i)).collect();
        let ends = Boundary::ends(soft(0.07), soft(0.03));
        let soft_model = Model::with_masses(n, ends, model.resonators().to_vec(), Some(masses));
        match (soft_model, model.contacts()) {
            (Ok(m), None) => m,
            (Ok(m), Some(law)) => m.with_contacts(law.clone()).unwrap_or(model),
            (Err(_), _) => model,
        }
    }

    #[test]
    fn a_patched_evaluation_is_the_whole_evaluation_bit_for_bit() {
        let mut rng = crate::testing::Lcg(2026);
        for k in 0..90 {
            let model = patch_test_model(&mut rng, k);
            let (n, t) = (model.n_sites(), 7.5);
            let q: Vec<f64> = (0..model.n_dof())
                .map(|_| 0.02 * (rng.uniform() - 0.5))
                .collect();
            let (lo, hi) = match k % 3 {
                0 => (0, n - 1),
                1 => (n / 4, n - 1),
                _ => (0, 3 * n / 4),
            };
            let window = Window { lo, hi };
            let (mut acc, mut record) = (vec![0.0; model.n_dof()], vec![0.0; n + 1]);
            model.accelerations_recording(t, &q, &mut acc, window, &mut record);
            // Corrected bonds: each moves its two members (one alone at a wall or an end), two
            // beside each other overlap, and an exactly integrated resonator's host moves it too.
            let mid = (lo + hi) / 2;
            let corrections = [
                vec![lo..=lo],
                vec![lo..=lo + 1],
                vec![mid..=mid + 1, mid + 1..=mid + 2],
                vec![hi - 1..=hi],
                vec![hi..=hi],
            ];
            for ranges in corrections {
                let mut moved = q.clone();
                for site in ranges.iter().flat_map(|r| r.clone()) {
                    moved[site] += 3e-3 * (rng.uniform() - 0.3);
                    for (j, r) in model.resonators().iter().enumerate() {
                        if r.site == site {
                            moved[n + j] -= 2e-3 * rng.uniform();
                        }
                    }
                }
                let (mut whole_acc, mut whole_record) = (acc.clone(), record.clone());
                model.accelerations_recording(t, &moved, &mut whole_acc, window, &mut whole_record);
                let (mut patched_acc, mut patched_record) = (acc.clone(), record.clone());
                for sites in ranges.iter().cloned() {
                    let forces = (&mut patched_acc[..], &mut patched_record[..]);
                    model.patch_accelerations(t, &moved, forces, window, sites);
                }
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                let what = format!("chain {k}, corrections {ranges:?}");
                assert_eq!(bits(&patched_acc), bits(&whole_acc), "{what}");
                assert_eq!(bits(&patched_record), bits(&whole_record), "{what}");
            }
        }
    }

    #[test]
    fn separated_sites_feel_no_force() {
        let model = Model::new(3, Boundary::Free, vec![]).unwrap();
        let mut acc = vec![1.0; 3];
        model.accelerations(0.0, &[0.0, 1.0, 2.0], &mut acc);
        assert_eq!(acc, vec![0.0; 3]);
    }
}
