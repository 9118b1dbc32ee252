//! One bond's contact-event correction, shared by the scalar steppers
//! ([`super::event_correction`]) and the lanes (`super::lanes`): which bond ([`Bond`]), its
//! path over the step, the integrals of its force along it less the method's quadrature
//! ([`bond_correction`]), and the correction applied to the end state ([`apply`]).

use super::contact_event::{damped_path_integrals, BondPath};
use super::contact_scan::negligible;
use super::exact_resonator::{
    fast_mode_correction, Dofs, DofsMut, ExactResonators, FastModeCorrection,
};
use crate::contact::{with_law, Law};
use crate::damping::Damping;
use crate::dofs::{Phase, PhaseMut};
use crate::model::Model;

/// A method's quadrature of one bond force from its stage values: (impulse, position change).
pub(crate) type Quadrature<const S: usize> = fn([f64; S], f64) -> (f64, f64);

/// A bond and its members (`None` for a wall), in the numbering of [`crate::contact`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Bond {
    pub index: usize,
    pub left: Option<usize>,
    pub right: Option<usize>,
}

impl Bond {
    /// The bond between sites `index − 1` and `index`.
    pub fn inner(index: usize) -> Bond {
        Bond {
            index,
            left: Some(index - 1),
            right: Some(index),
        }
    }

    /// The wall left of the first site.
    pub fn left_wall() -> Bond {
        Bond {
            index: 0,
            left: None,
            right: Some(0),
        }
    }

    /// The wall right of the last of `n_sites` sites.
    pub fn right_wall(n_sites: usize) -> Bond {
        Bond {
            index: n_sites,
            left: Some(n_sites - 1),
            right: None,
        }
    }

    /// Its members' sites (one or two).
    pub fn sites(self) -> impl Iterator<Item = usize> {
        self.left.into_iter().chain(self.right)
    }
}

/// A bond that changed contact during a step, with the forces the method's stages gave it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Changed<const S: usize> {
    pub bond: Bond,
    pub stage: [f64; S],
}

/// A step as a correction reads it: its size, the method's quadrature of a bond force, and
/// the exactly integrated resonators, if any.
#[derive(Clone, Copy)]
pub(crate) struct Rule<'a, const S: usize> {
    pub h: f64,
    pub quadrature: Quadrature<S>,
    pub exact: Option<&'a ExactResonators<S>>,
}

/// A bond's correction: the impulse and the position moment its members receive (the left
/// one pushed back, the right one on).
#[derive(Debug, Clone, Copy)]
pub(super) struct Correction {
    pub bond: Bond,
    pub impulse: f64,
    pub moment: f64,
}

/// Adds each correction to the end state: the bond pushes its left member back and its right
/// member on.
/// The end state may be a lane of four (`super::lanes`): it is written through [`DofsMut`].
pub(super) fn apply<D: DofsMut + ?Sized>(
    inv_mass: &[f64],
    corrections: &[Correction],
    end: PhaseMut<'_, D>,
) {
    let PhaseMut { q: new_q, v: new_v } = end;
    for &Correction {
        bond: Bond { left, right, .. },
        impulse,
        moment,
    } in corrections
    {
        if let Some(i) = left {
            new_v.sub(i, impulse * inv_mass[i]);
            new_q.sub(i, moment * inv_mass[i]);
        }
        if let Some(i) = right {
            new_v.add(i, impulse * inv_mass[i]);
            new_q.add(i, moment * inv_mass[i]);
        }
    }
}

/// Adds the fast-mode parts of the corrections to the end state (host and resonator).
pub(super) fn apply_fast<D: DofsMut + ?Sized>(
    fast: impl IntoIterator<Item = FastModeCorrection>,
    end: PhaseMut<'_, D>,
) {
    let PhaseMut { q: new_q, v: new_v } = end;
    for fast in fast {
        for k in 0..2 {
            new_v.add(fast.sites[k], fast.velocity[k]);
            new_q.add(fast.sites[k], fast.position[k]);
        }
    }
}

/// A bond's impulse and moment along its path, and the energy its dashpot dissipates there
/// (0 for a conservative chain).
pub(super) fn bond_integrals(
    model: &Model,
    bond: usize,
    path: &BondPath,
    h: f64,
) -> (f64, f64, f64) {
    if model.is_dissipative() {
        let damping = model.damping();
        return with_law!(model.law(), |law| {
            damped_path_integrals(path, h, damped_force(law, damping, bond))
        });
    }
    let (impulse, moment) = with_law!(model.law(), |law| law.path_integrals(bond, path, h));
    (impulse, moment, 0.0)
}

/// A changed bond's correction over a step (`rule`) from the state `start` to `end` (the end
/// not yet corrected): the path integrals less the method's quadrature of the forces its
/// stages gave the bond, with its parts along the fast modes of exact resonators at its
/// members pushed to `fast`; and the energy its dashpot dissipated along the path. `None` when
/// its forces are [`negligible`]. One scene's states, or one lane's (`super::lanes`), are read
/// through [`Dofs`].
pub(super) fn bond_correction<const S: usize, D: Dofs + ?Sized>(
    model: &Model,
    Changed { bond, stage }: Changed<S>,
    (start, end): (Phase<'_, D>, Phase<'_, D>),
    Rule {
        h,
        quadrature,
        exact,
    }: Rule<'_, S>,
    fast: &mut Vec<FastModeCorrection>,
) -> Option<(Correction, f64)> {
    let path = bond_path(model, bond, start, end);
    if negligible(model, bond.index, stage, &path) {
        return None;
    }
    let (impulse, moment, lost) = bond_integrals(model, bond.index, &path, h);
    let (q0, q1) = quadrature(stage, h);
    let plain = (impulse - q0, moment - q1);
    if let Some(exact) = exact {
        for (member, sign) in [(bond.left, -1.0), (bond.right, 1.0)] {
            if let Some(pair) = member.and_then(|site| exact.host(site)) {
                let on = (bond.index, &path, stage);
                fast.push(fast_mode_correction(model, on, h, plain, (pair, sign)));
            }
        }
    }
    let correction = Correction {
        bond,
        impulse: plain.0,
        moment: plain.1,
    };
    Some((correction, lost))
}

/// A damped bond's total force and dashpot power at total overlap c closing at rate ċ, as the
/// path integrals and the switch search take them (the path is of the total overlap; the
/// force law takes the relative displacement, without the static overlap). Generic over the
/// law, so that the searches and quadratures that call it are compiled once per law with it
/// inlined.
#[inline(always)]
pub(super) fn damped_force<'a, L: Law>(
    law: &'a L,
    damping: Option<&'a Damping>,
    bond: usize,
) -> impl Fn(f64, f64) -> (f64, f64) + 'a {
    let delta = law.static_overlap(bond);
    move |c, rate| {
        let (force, power) = law.damped(damping, bond, c - delta, rate);
        (force.total, power)
    }
}

/// A bond's overlap and rate at both ends of a step, from the states at its `start` and `end`:
/// left member minus right member, a wall counting as at rest, plus the bond's static overlap
/// (a precompression's, or a gap's, negative).
/// The state may be a lane of four (`super::lanes`): it is read through [`Dofs`].
pub(super) fn bond_path<D: Dofs + ?Sized>(
    model: &Model,
    bond: Bond,
    start: Phase<'_, D>,
    end: Phase<'_, D>,
) -> BondPath {
    let member = |x: &D, site: Option<usize>| site.map_or(0.0, |i| x.at(i));
    let (left, right) = (bond.left, bond.right);
    let path = BondPath {
        d0: member(start.q, left) - member(start.q, right),
        rate0: member(start.v, left) - member(start.v, right),
        d1: member(end.q, left) - member(end.q, right),
        rate1: member(end.v, left) - member(end.v, right),
    };
    match with_law!(model.law(), |law| law.static_overlap(bond.index)) {
        // A precompression's overlap (δ > 0), or a gap (δ < 0): never −0.0, so `!= 0.0`
        // leaves every paper bond's path as it was.
        delta if delta != 0.0 => BondPath {
            d0: path.d0 + delta,
            d1: path.d1 + delta,
            ..path
        },
        _ => path,
    }
}
