//! The force loop of four lanes: the chain's force kernel ([`crate::chain_force`]) run four
//! scenes wide, recording every bond force; and `patch`, the same forces evaluated again at a
//! few sites of one lane.

use super::{Lane, LaneChain, LaneMut, Lanes};
use crate::chain_force::{chain_accelerations, Coupled, Frame, Lossless};
use crate::contact::{with_law, ChainLaw};
use crate::model::Window;

impl LaneChain {
    /// The contact law the lanes share.
    pub(super) fn law(&self) -> &ChainLaw {
        &self.law
    }

    /// What the force loops read of the chain besides its law, resonators and masses.
    fn frame(&self) -> Frame {
        Frame {
            n_sites: self.n_sites,
            walls: self.walls,
            soft_ends: self.springs.map(|spring| spring.map(|s| (s, 0.0))),
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
    let resonators = chain.resonators.iter().map(|r| Coupled {
        site: r.site,
        p: r.p,
        eps: r.eps,
        kappa: move || r.kappa,
    });
    let frame = chain.frame();
    with_law!(chain.law(), |law| chain_accelerations(
        (law, &frame),
        resonators,
        &mut Lossless {
            masses: chain.masses.as_deref()
        },
        (q, acc),
        window,
        Some(record)
    ));
}

/// Lane `l`'s forces of the state `q` near `site`, whose position a contact correction moved
/// after the forces `acc` and `record` (a whole evaluation's) were taken, bit for bit as
/// [`accelerations`] gives them ([`crate::chain_force::patch`]). Returns the sites whose
/// accelerations it wrote.
pub(super) fn patch(
    chain: &LaneChain,
    q: &[Lanes],
    (acc, record): (&mut [Lanes], &mut [Lanes]),
    (window, l): (Window, usize),
    site: usize,
) -> std::ops::RangeInclusive<usize> {
    let resonators = chain.resonators.iter().map(move |r| Coupled {
        site: r.site,
        p: r.p,
        eps: r.eps[l],
        kappa: move || r.kappa[l],
    });
    let masses = chain.masses.as_deref().map(|m| Lane(m, l));
    let forces = (&mut LaneMut(acc, l), &mut LaneMut(record, l));
    let frame = chain.frame();
    with_law!(chain.law(), |law| crate::chain_force::patch(
        (law, &frame),
        resonators,
        masses.as_ref(),
        &Lane(q, l),
        forces,
        window,
        site..=site
    ))
}
