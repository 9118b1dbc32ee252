//! Classical RK4 written for the chain's second-order form q' = v, v' = a(q): the same
//! arithmetic as [`super::ExplicitRk`]`<`[`super::Rk4`]`>`, operation for operation (so the
//! result is the same bits, which a test checks), with each stage's state, derivative and
//! contribution to the new state computed in one pass over memory instead of four.
//!
//! With k_i = (v_i, a_i): q_{i+1} = q + (c h) v_i, v_{i+1} = v + (c h) a_i, a_{i+1} = a(q_{i+1});
//! the new state accumulates y + (h b_1) k_1 + (h b_2) k_2 + ... in that order.
//!
//! The same stepper is `rk4-contact` when made by [`Rk4Fused::with_contact_events`]: it records
//! each stage's bond forces and, after the step, replaces RK4's quadrature of every bond whose
//! contact opened or closed by the integral along the bond's path ([`super::contact_event`]).

use super::contact_event::{changes_contact, path_integrals, rk4_quadrature, BondPath};
use super::{StepOutcome, Stepper};
use crate::model::{Boundary, Model, Window};

const B: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
/// a_{i+1, i} of the tableau: the weight of stage i in stage i + 1.
const A_NEXT: [f64; 3] = [0.5, 0.5, 1.0];
const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];

/// Fused RK4 stepper with its scratch (allocated once).
#[derive(Debug, Clone)]
pub struct Rk4Fused {
    /// Stage positions.
    q_stage: Vec<f64>,
    /// Stage velocities (the position derivatives k_q).
    v_stage: Vec<f64>,
    /// Stage accelerations (the velocity derivatives k_v).
    a_stage: Vec<f64>,
    /// The new state being accumulated.
    y_new: Vec<f64>,
    evals: u64,
    /// For `rk4-contact`: the bond forces of each stage (see [`ContactEvents`]).
    contact: Option<ContactEvents>,
}

/// What `rk4-contact` keeps per step to correct the bonds whose contact opened or closed:
/// every bond force of the four stages (indexing of [`Model::accelerations_recording`]) and
/// the corrections found, applied after the scan so that each uses the uncorrected step.
#[derive(Debug, Clone)]
struct ContactEvents {
    stage_force: [Vec<f64>; 4],
    /// (left site or None for a wall, right site or None, impulse, position) corrections.
    pending: Vec<(Option<usize>, Option<usize>, f64, f64)>,
    /// Bonds corrected so far.
    events: u64,
    /// Scratch: window offsets of the bonds that changed contact in this step.
    changed: Vec<usize>,
}

impl Rk4Fused {
    /// A stepper for states of `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.n_dof();
        Self {
            q_stage: vec![0.0; n],
            v_stage: vec![0.0; n],
            a_stage: vec![0.0; n],
            y_new: vec![0.0; 2 * n],
            evals: 0,
            contact: None,
        }
    }

    /// `rk4-contact`: the same RK4, plus the exact integral of every contact force across the
    /// step in which that contact opens or closes ([`super::contact_event`]).
    pub fn with_contact_events(model: &Model) -> Self {
        let bonds = model.n_sites() + 1;
        Self {
            contact: Some(ContactEvents {
                stage_force: std::array::from_fn(|_| vec![0.0; bonds]),
                pending: Vec::new(),
                events: 0,
                changed: Vec::new(),
            }),
            ..Self::new(model)
        }
    }

    /// Bonds whose contact changed state inside a step and were corrected (0 for plain RK4).
    pub fn contact_events(&self) -> u64 {
        self.contact.as_ref().map_or(0, |c| c.events)
    }
}

/// Largest contact force for which an opening or closing is left to RK4: the correction of
/// such a bond is below |force| h, under 1e-15 in a dimensionless chain struck at unit
/// velocity. Four in five contact changes on the paper's scenes are grazing touches of the
/// quiet chain behind the wave, with forces below 1e-16; skipping them changes no fraction by
/// more than 1e-16 and saves most of the correction's cost.
const NEGLIGIBLE_FORCE: f64 = 1e-14;

fn negligible(stage_forces: [f64; 4], d_end: f64) -> bool {
    let end = d_end.max(0.0);
    stage_forces.iter().all(|&f| f < NEGLIGIBLE_FORCE) && end * end.sqrt() < NEGLIGIBLE_FORCE
}

/// Stage accelerations, recording the bond forces when `contact` events are corrected.
fn stage_accelerations(
    model: &Model,
    contact: &mut Option<ContactEvents>,
    (q_stage, a_stage): (&[f64], &mut [f64]),
    (t, stage): (f64, usize),
    window: Window,
) {
    match contact {
        None => model.accelerations_in(t, q_stage, a_stage, window),
        Some(c) => {
            model.accelerations_recording(t, q_stage, a_stage, window, &mut c.stage_force[stage])
        }
    }
}

impl Stepper for Rk4Fused {
    fn name(&self) -> &'static str {
        if self.contact.is_some() {
            "rk4-contact"
        } else {
            "rk4"
        }
    }

    fn step(
        &mut self,
        model: &Model,
        t: f64,
        y: &mut [f64],
        h: f64,
        window: Window,
    ) -> StepOutcome {
        let n = model.n_dof();
        let ranges = window.dof_ranges(model);
        let (q, v) = y.split_at(n);
        let (new_q, new_v) = self.y_new.split_at_mut(n);
        // Stage 1: (q, v), a(q).
        for r in ranges.clone() {
            new_q[r.clone()].copy_from_slice(&q[r.clone()]);
            new_v[r.clone()].copy_from_slice(&v[r.clone()]);
            self.v_stage[r.clone()].copy_from_slice(&v[r]);
        }
        for r in ranges.clone() {
            self.q_stage[r.clone()].copy_from_slice(&q[r]);
        }
        stage_accelerations(
            model,
            &mut self.contact,
            (&self.q_stage, &mut self.a_stage),
            (t, 0),
            window,
        );
        for stage in 0..4 {
            let hb = h * B[stage];
            let next = A_NEXT.get(stage).map(|&a| h * a);
            for r in ranges.clone() {
                let len = r.len();
                let vs = &mut self.v_stage[r.clone()];
                let as_ = &self.a_stage[r.clone()][..len];
                let qs = &mut self.q_stage[r.clone()][..len];
                let nq = &mut new_q[r.clone()][..len];
                let nv = &mut new_v[r.clone()][..len];
                let q0 = &q[r.clone()][..len];
                let v0 = &v[r][..len];
                // Two loops rather than a branch inside one, so that both vectorise.
                match next {
                    Some(w) => {
                        for i in 0..len {
                            nq[i] += hb * vs[i];
                            nv[i] += hb * as_[i];
                            qs[i] = q0[i] + w * vs[i];
                            vs[i] = v0[i] + w * as_[i];
                        }
                    }
                    None => {
                        for i in 0..len {
                            nq[i] += hb * vs[i];
                            nv[i] += hb * as_[i];
                        }
                    }
                }
            }
            if stage < 3 {
                stage_accelerations(
                    model,
                    &mut self.contact,
                    (&self.q_stage, &mut self.a_stage),
                    (t + C[stage + 1] * h, stage + 1),
                    window,
                );
            }
        }
        self.evals += 4;
        if self.contact.is_some() {
            self.correct_contact_events(model, y, h, window);
        }
        let (new_q, new_v) = self.y_new.split_at(n);
        let (q, v) = y.split_at_mut(n);
        for r in ranges {
            q[r.clone()].copy_from_slice(&new_q[r.clone()]);
            v[r.clone()].copy_from_slice(&new_v[r]);
        }
        StepOutcome::Accepted { h_next: h }
    }

    fn reach(&self) -> usize {
        4
    }

    fn rhs_evals(&self) -> u64 {
        self.evals
    }
}

impl Rk4Fused {
    /// Replaces RK4's quadrature by the path integral for every bond of `window` whose contact
    /// opened or closed during the step from `y` to `self.y_new` (not yet copied back).
    fn correct_contact_events(&mut self, model: &Model, y: &[f64], h: f64, window: Window) {
        let Some(contact) = self.contact.as_mut() else {
            return;
        };
        let n = model.n_dof();
        let n_sites = model.n_sites();
        let (q, v) = y.split_at(n);
        let (new_q, new_v) = self.y_new.split_at_mut(n);
        let forces = &contact.stage_force;
        let stage_forces = |bond: usize| {
            [
                forces[0][bond],
                forces[1][bond],
                forces[2][bond],
                forces[3][bond],
            ]
        };
        // Overlap and rate of a bond from (positions, velocities): left minus right member.
        let member = |x: &[f64], site: Option<usize>| site.map_or(0.0, |i| x[i]);
        let mut pending = std::mem::take(&mut contact.pending);
        pending.clear();
        let mut correct = |bond: usize, left: Option<usize>, right: Option<usize>| {
            let stage = stage_forces(bond);
            let d_end = member(new_q, left) - member(new_q, right);
            if !changes_contact(stage, d_end) || negligible(stage, d_end) {
                return;
            }
            let path = BondPath {
                d0: member(q, left) - member(q, right),
                rate0: member(v, left) - member(v, right),
                d1: d_end,
                rate1: member(new_v, left) - member(new_v, right),
            };
            let (impulse, moment) = path_integrals(&path, h);
            let (q0, q1) = rk4_quadrature(stage, h);
            pending.push((left, right, impulse - q0, moment - q1));
        };
        // The scan over the window's bonds is the only per-bond cost; it touches the stage
        // forces and end positions in order and calls out only for the rare bond that changed.
        let (lo, hi) = (window.lo, window.hi);
        let bonds = lo + 1..hi + 1;
        let (f0, f1, f2, f3) = (
            &forces[0][bonds.clone()],
            &forces[1][bonds.clone()],
            &forces[2][bonds.clone()],
            &forces[3][bonds],
        );
        let (left_q, right_q) = (&new_q[lo..hi], &new_q[lo + 1..hi + 1]);
        // A bond changed contact when between one and four of its five values say "touching"
        // (`changes_contact`, written out here so that it vectorises).
        // The test runs branch-free over blocks of eight bonds (it vectorises); only a block
        // holding a changed bond, which is rare, is looked at bond by bond.
        let changed_at = |i: usize| {
            let touching = u8::from(f0[i] > 0.0)
                + u8::from(f1[i] > 0.0)
                + u8::from(f2[i] > 0.0)
                + u8::from(f3[i] > 0.0)
                + u8::from(left_q[i] - right_q[i] > 0.0);
            touching.wrapping_sub(1) < 4
        };
        let changed = &mut contact.changed;
        changed.clear();
        let n_bonds = hi - lo;
        const BLOCK: usize = 8;
        let mut start = 0;
        while start < n_bonds {
            let end = (start + BLOCK).min(n_bonds);
            let mut any = false;
            for i in start..end {
                any |= changed_at(i);
            }
            if any {
                changed.extend((start..end).filter(|&i| changed_at(i)));
            }
            start = end;
        }
        for &i in changed.iter() {
            correct(lo + i + 1, Some(lo + i), Some(lo + i + 1));
        }
        if model.boundary() == Boundary::Fixed {
            if lo == 0 {
                correct(0, None, Some(0));
            }
            if hi == n_sites - 1 {
                correct(n_sites, Some(n_sites - 1), None);
            }
        }
        // The bond pushes its left member back and its right member on.
        let inv_mass = model.inv_mass();
        for &(left, right, impulse, moment) in &pending {
            if let Some(i) = left {
                new_v[i] -= impulse * inv_mass[i];
                new_q[i] -= moment * inv_mass[i];
            }
            if let Some(i) = right {
                new_v[i] += impulse * inv_mass[i];
                new_q[i] += moment * inv_mass[i];
            }
        }
        contact.events += pending.len() as u64;
        contact.pending = pending;
    }
}
