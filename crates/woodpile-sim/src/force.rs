//! The right-hand side: accelerations from positions (paper Eqs. 3 and 7 with per-site masses),
//! the chain's force kernel ([`crate::chain_force`]) run for a [`Model`] without losses, in
//! each CPU tier's copy (`crate::simd`). Every integrator's hot loop: it allocates nothing and
//! calls nothing dynamic. `Model::accelerations` gives the conservative forces of any model:
//! a dissipative one's dashpots and ground damping act only through
//! [`Model::damped_accelerations_in`].

use crate::chain_force::{chain_accelerations, patch, Coupled, Frame, Lossless};
use crate::contact::{with_law, Law};
use crate::model::{Model, Window};

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
        debug_assert_eq!(q.len(), self.n_dof());
        debug_assert_eq!(acc.len(), self.n_dof());
        let frame = self.frame();
        let mut lossless = Lossless {
            masses: self.site_masses(),
        };
        with_law!(self.law(), |law| chain_accelerations(
            (law, &frame),
            self.coupled(t),
            &mut lossless,
            (q, acc),
            window,
            bond_force
        ));
    }

    /// The forces of positions `q` near `sites`, whose positions a contact correction moved
    /// after `acc` and `record` (a whole evaluation's on `window`, as
    /// [`Model::accelerations_recording`] writes them) were taken, bit for bit as a whole
    /// evaluation gives them ([`crate::chain_force::patch`]). Returns the sites whose
    /// accelerations it wrote.
    pub(crate) fn patch_accelerations(
        &self,
        t: f64,
        q: &[f64],
        forces: (&mut [f64], &mut [f64]),
        window: Window,
        sites: std::ops::RangeInclusive<usize>,
    ) -> std::ops::RangeInclusive<usize> {
        let frame = self.frame();
        let (resonators, masses) = (self.coupled(t), self.site_masses());
        with_law!(self.law(), |law| patch(
            (law, &frame),
            resonators,
            masses,
            q,
            forces,
            window,
            sites
        ))
    }

    /// What the force loops read of the chain besides its law, resonators and masses.
    #[inline(always)]
    pub(crate) fn frame(&self) -> Frame {
        let boundary = self.boundary();
        Frame {
            n_sites: self.n_sites(),
            walls: self.walls(),
            soft_ends: [boundary.left().soft(), boundary.right().soft()],
        }
    }

    /// The resonators as the force loops read them at time `t` (a coupling is computed only
    /// where a loop reaches its host).
    #[inline(always)]
    pub(crate) fn coupled(
        &self,
        t: f64,
    ) -> impl Iterator<Item = Coupled<f64, impl Fn() -> f64 + '_>> + Clone + '_ {
        self.resonators().iter().map(move |r| Coupled {
            site: r.site,
            p: r.p,
            eps: r.eps,
            kappa: move || r.coupling.at(t),
        })
    }

    /// The fastest a contact of a chain under a [`crate::ContactLaw`] vibrates in a motion of total
    /// energy `energy`: sqrt(k (1/m_left + 1/m_right)) at the stiffness k the bond has at the
    /// largest overlap the energy allows ([`Law::stiffness_within`]); a wall counts as
    /// infinitely heavy. 0 for the paper's chain, whose steps are calibrated on it.
    pub fn max_contact_omega(&self, energy: f64) -> f64 {
        with_law!(self.law(), |law| self.max_contact_omega_of(law, energy))
    }

    fn max_contact_omega_of(&self, law: &impl Law, energy: f64) -> f64 {
        let n = self.n_sites();
        let walls = self.walls();
        (0..=n)
            .filter(|&bond| (bond > 0 || walls[0]) && (bond < n || walls[1]))
            .filter_map(|bond| {
                let inverse_masses = [bond.checked_sub(1), (bond < n).then_some(bond)]
                    .into_iter()
                    .flatten()
                    .map(|site| 1.0 / self.site_mass(site))
                    .sum::<f64>();
                let stiffness = law.stiffness_within(bond, energy)?;
                Some((stiffness * inverse_masses).sqrt())
            })
            .fold(0.0, f64::max)
    }

    /// The static overlap of bond `bond` (numbering of [`crate::contact`]): 0 but under a
    /// precompression or gravity (positive) or across a gap (negative).
    pub fn static_overlap(&self, bond: usize) -> f64 {
        with_law!(self.law(), |law| law.static_overlap(bond))
    }

    /// The stiffness dF/dc of bond `bond` at total overlap `c` > 0, by the chain's law: the
    /// linear picture's spring about a static state.
    pub fn contact_stiffness(&self, bond: usize, c: f64) -> f64 {
        with_law!(self.law(), |law| law.stiffness(bond, c))
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
    /// experiment's contact laws, masses, precompression, gapped linear contacts), given soft
    /// ends without dashpots on every third.
    fn patch_test_model(rng: &mut crate::testing::Lcg, k: usize) -> Model {
        use crate::testing::{audit_scene, chain_audit_scene, gap_audit_scene};
        let model = match k % 4 {
            0 | 2 => chain_audit_scene(rng).model,
            1 => audit_scene(rng).model,
            _ => gap_audit_scene(rng).model,
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
        soft_model
            .and_then(|m| m.with_law(model.law().clone()))
            .unwrap_or(model)
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
