//! The forces of a dissipative chain ([`crate::damping`]): accelerations from positions *and*
//! velocities, with the dissipated power the ledger integrates. They are the chain's force
//! kernel ([`crate::chain_force`]) with the chain's losses ([`Dissipating`]); only a scene
//! that declares dissipation runs them, and the conservative chain keeps its bits.

use crate::chain_force::{chain_accelerations, Losses};
use crate::contact::{with_law, Law};
use crate::damping::Damping;
pub use crate::error::Dissipator;
use crate::model::{Model, Window};

/// Where a dissipative force loop records each bond's force and dashpot power (indexing of
/// [`Model::accelerations_recording`]'s recorded bonds: entry b is bond b, walls at 0 and
/// `n_sites`).
pub(crate) struct BondRecord<'a> {
    /// The bond's total force, clipped at zero (what the contact-event scan reads).
    pub force: &'a mut [f64],
    /// The bond's dashpot power (F − elastic) ċ.
    pub power: &'a mut [f64],
}

impl Model {
    /// Accelerations `q'' = M^{-1} F(t, q, q')` of a dissipative model on the sites of `window`
    /// (and every resonator), written into `acc`, for positions `q` and velocities `v` (each
    /// of length `n_dof`); returns the dissipated power of the window. With `record`, every
    /// bond's force and dashpot power are kept for the contact-event correction.
    pub fn damped_accelerations_in(
        &self,
        t: f64,
        (q, v): (&[f64], &[f64]),
        acc: &mut [f64],
        window: Window,
    ) -> f64 {
        self.damped_recording(t, (q, v), acc, window, None)
    }

    /// [`Model::damped_accelerations_in`], recording every bond's force and dashpot power
    /// into `record` when a contact-event method keeps them: the chain's force kernel
    /// ([`chain_accelerations`]) with the chain's losses ([`Dissipating`]).
    pub(crate) fn damped_recording(
        &self,
        t: f64,
        (q, v): (&[f64], &[f64]),
        acc: &mut [f64],
        window: Window,
        record: Option<BondRecord<'_>>,
    ) -> f64 {
        let n_dof = self.n_dof();
        let (force_record, power_record) = match record {
            Some(BondRecord { force, power }) => (Some(force), Some(power)),
            None => (None, None),
        };
        let (u_dot, w_dot) = v[..n_dof].split_at(self.n_sites());
        let mut losses = Dissipating {
            damping: self.damping(),
            velocities: (u_dot, w_dot),
            inv_mass: self.inv_mass(),
            power: 0.0,
            end_power: 0.0,
            power_record,
        };
        let frame = self.frame();
        with_law!(self.law(), |law| chain_accelerations(
            (law, &frame),
            self.coupled(t),
            &mut losses,
            (&q[..n_dof], &mut acc[..n_dof]),
            window,
            force_record
        ));
        losses.power
    }

    /// The fastest rate, 1/time, at which the chain's dashpots and soft ends act in a
    /// motion of total energy `energy`: a dashpot c between masses m1 and m2 relaxes at
    /// c (1/m1 + 1/m2), a soft end's spring vibrates at sqrt(k / m). An explicit step must
    /// stay well below its inverse, as below a resonator's period ([`crate::integrate::Plan::resolving_dt`]);
    /// 0 when the chain has none of them.
    pub fn max_dissipation_rate(&self, energy: f64) -> f64 {
        self.dissipation_rates(energy)
            .into_iter()
            .fold(0.0, |rate, (_, r)| rate.max(r))
    }

    /// The fastest rate, 1/time, at which the losses that act on velocities alone damp a
    /// motion ([`Model::linear_loss_rates`]); 0 without any. What decides whether `auto` may
    /// split them from the conservative step ([`crate::integrate::Plan::choose`]).
    pub fn linear_loss_rate(&self) -> f64 {
        self.linear_loss_rates()
            .into_iter()
            .fold(0.0, |rate, (_, r)| rate.max(r))
    }

    /// What acts fastest among the chain's dashpots and soft ends in a motion of total
    /// energy `energy`, and its rate ([`Model::max_dissipation_rate`]): what a scene whose
    /// step they set is told to change. `None` when the chain has none of them.
    pub fn fastest_dissipation(&self, energy: f64) -> Option<(Dissipator, f64)> {
        self.dissipation_rates(energy)
            .into_iter()
            .filter(|(_, r)| *r > 0.0 || r.is_nan())
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Each dashpot's and soft end's rate ([`Model::max_dissipation_rate`]), by what it is: a
    /// soft end's spring, then the losses on velocities alone, then the contacts' dashpots.
    fn dissipation_rates(&self, energy: f64) -> Vec<(Dissipator, f64)> {
        let n = self.n_sites();
        let inv = |site: Option<usize>| site.map_or(0.0, |i| self.inv_mass()[i]);
        let mut rates: Vec<(Dissipator, f64)> = self
            .each_soft_end()
            .map(|(end, site, (spring, _))| (end, (spring * self.inv_mass()[site]).sqrt()))
            .collect();
        rates.extend(self.linear_loss_rates());
        let Some(d) = self.damping() else {
            return rates;
        };
        if d.has_contact_dashpot() {
            for bond in 0..=n {
                let pair = inv(bond.checked_sub(1)) + inv((bond < n).then_some(bond));
                let overlap = with_law!(self.law(), |law| law.overlap_within(bond, energy));
                rates.push((
                    Dissipator::Contact { bond },
                    d.law.force(d.contact_at(bond), overlap, 1.0) * pair,
                ));
            }
        }
        rates
    }

    /// The rates of the losses that act on velocities alone, by what they are: each soft
    /// end's dashpot d/m, ground damping g/m (on the lightest site), each resonator's dashpot
    /// c (1/m + 1/ε).
    fn linear_loss_rates(&self) -> Vec<(Dissipator, f64)> {
        let n = self.n_sites();
        let mut rates: Vec<(Dissipator, f64)> = self
            .each_soft_end()
            .map(|(end, site, (_, damping))| (end, damping * self.inv_mass()[site]))
            .collect();
        let Some(d) = self.damping() else {
            return rates;
        };
        let lightest = self.inv_mass()[..n].iter().fold(0.0, |a: f64, &b| a.max(b));
        rates.push((Dissipator::Ground, d.ground * lightest));
        for (j, r) in self.resonators().iter().enumerate() {
            let inv_pair = self.inv_mass()[r.site] + 1.0 / r.eps;
            rates.push((Dissipator::Resonator(j), d.resonator(j) * inv_pair));
        }
        rates
    }

    /// Each soft end: what it is, its site, and its spring and dashpot.
    fn each_soft_end(&self) -> impl Iterator<Item = (Dissipator, usize, (f64, f64))> + '_ {
        let last = self.n_sites() - 1;
        [(0, self.boundary().left()), (last, self.boundary().right())]
            .into_iter()
            .filter_map(|(site, end)| {
                let soft = end.soft()?;
                Some((Dissipator::SoftEnd { last: site > 0 }, site, soft))
            })
    }
}

/// The losses of a dissipative chain, as the force kernel adds them: each contact's dashpot
/// (clipped so that a contact never pulls), each soft end's dashpot, ground damping and each
/// resonator's dashpot, with the power they dissipate summed in the kernel's order.
struct Dissipating<'a> {
    damping: Option<&'a Damping>,
    /// The sites' and the resonators' velocities.
    velocities: (&'a [f64], &'a [f64]),
    inv_mass: &'a [f64],
    /// The dissipated power summed so far.
    power: f64,
    /// The soft ends' dashpots' power, summed apart and added to `power` once, before the
    /// ground's: the order of the sum, and so its bits, as the dissipated power always had.
    end_power: f64,
    /// Where each bond's dashpot power is kept, for the contact-event correction.
    power_record: Option<&'a mut [f64]>,
}

impl Losses<f64> for Dissipating<'_> {
    const DISSIPATES: bool = true;

    #[inline(always)]
    fn bond<L: Law>(
        &mut self,
        law: &L,
        bond: usize,
        r: f64,
        (left, right): (Option<usize>, Option<usize>),
    ) -> (f64, f64, f64) {
        let at = |site: Option<usize>| site.map_or(0.0, |i| self.velocities.0[i]);
        let rate = at(left) - at(right);
        let (force, dashpot_power) = law.damped(self.damping, bond, r, rate);
        if let Some(record) = self.power_record.as_deref_mut() {
            record[bond] = dashpot_power;
        }
        (force.total, force.total - force.rest, dashpot_power)
    }

    #[inline(always)]
    fn contacts_dissipated(&mut self, power: f64) {
        self.power += power;
    }

    fn soft_end(&mut self, (spring, damping): (f64, f64), site: usize, u: f64) -> f64 {
        let u_dot = self.velocities.0[site];
        self.end_power += damping * u_dot * u_dot;
        spring * u + damping * u_dot
    }

    fn ground(&mut self, acc_u: &mut [f64], window: Window) {
        // The kernel asks for the ground after the soft ends, always.
        self.power += self.end_power;
        self.end_power = 0.0;
        let ground = self.damping.map_or(0.0, |d| d.ground);
        if ground > 0.0 {
            let sites = window.lo..=window.hi;
            for (a, &u_dot) in acc_u[sites.clone()]
                .iter_mut()
                .zip(&self.velocities.0[sites])
            {
                *a -= ground * u_dot;
                self.power += ground * u_dot * u_dot;
            }
        }
    }

    fn resonator(&mut self, j: usize, site: usize, elastic: f64) -> f64 {
        let c = self.damping.map_or(0.0, |d| d.resonator(j));
        let slip = self.velocities.0[site] - self.velocities.1[j];
        self.power += c * slip * slip;
        elastic + c * slip
    }

    fn inertia(&self, acc_u: &mut [f64], window: Window) {
        let (lo, hi) = (window.lo, window.hi);
        for (a, inv_m) in acc_u[lo..=hi].iter_mut().zip(&self.inv_mass[lo..=hi]) {
            *a *= inv_m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{audit_scene, chain_audit_scene, Lcg};

    /// The damped chain's forces are the one kernel's: with its losses at zero they are the
    /// conservative evaluation's, bit for bit (but the sign of a zero), on chains of every
    /// law and end the audits draw (unit masses: the damped chain multiplies by 1/m, the
    /// conservative one divides by m).
    #[test]
    fn without_losses_the_damped_kernel_is_the_conservative_one() {
        let mut rng = Lcg(2027);
        let mut compared = 0;
        for k in 0..60 {
            let scenario = match k % 2 {
                0 => chain_audit_scene(&mut rng),
                _ => audit_scene(&mut rng),
            };
            let model = scenario.model;
            if model.site_masses().is_some() || model.is_dissipative() {
                continue;
            }
            compared += 1;
            let (n, n_dof, t) = (model.n_sites(), model.n_dof(), 3.25);
            let q: Vec<f64> = (0..n_dof).map(|_| 0.02 * (rng.uniform() - 0.5)).collect();
            let v: Vec<f64> = (0..n_dof).map(|_| rng.uniform() - 0.5).collect();
            let window = Window {
                lo: n / 5,
                hi: n - 1,
            };
            let (mut plain, mut plain_record) = (vec![0.0; n_dof], vec![0.0; n + 1]);
            model.accelerations_recording(t, &q, &mut plain, window, &mut plain_record);
            let (mut damped, mut damped_record) = (vec![0.0; n_dof], vec![0.0; n + 1]);
            let mut losses = Dissipating {
                damping: None,
                velocities: v.split_at(n),
                inv_mass: model.inv_mass(),
                power: 0.0,
                end_power: 0.0,
                power_record: None,
            };
            let frame = model.frame();
            with_law!(model.law(), |law| chain_accelerations(
                (law, &frame),
                model.coupled(t),
                &mut losses,
                (&q[..], &mut damped[..]),
                window,
                Some(&mut damped_record[..])
            ));
            // x + 0.0 is x, but for a negative zero, which it makes positive.
            let bits = |x: &[f64]| x.iter().map(|x| (x + 0.0).to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&damped), bits(&plain), "chain {k}");
            assert_eq!(bits(&damped_record), bits(&plain_record), "chain {k}");
            assert_eq!(losses.power, 0.0, "chain {k}");
        }
        assert!(compared >= 20, "only {compared} chains compared");
    }
}
