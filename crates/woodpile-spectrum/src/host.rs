//! What a finite chain is built on: the repeating cell whose bands it has, and the uniform lead
//! whose waves its defect region scatters. Both are read off the [`LinearChain`] itself, so a
//! scene declares nothing beyond its chain.
//!
//! - **Cell.** Sites `first..first + p` repeat when every site's mass, resonators and ground
//!   dashpot, and every interior bond, equal those one period away, over the whole chain. The
//!   cell's bond 0 (from the previous cell) is the interior bond in front of a copy of its first
//!   site. A chain with at least two periods of a cell is *periodic*; [`detect_cell`] finds the
//!   shortest period, and a chain with none (a host with defects) falls back on its lead.
//! - **Lead.** The mass of site 0 (which must carry no resonator) and the stiffness of bond 1:
//!   the host the chain starts with. The *region* is the shortest run of sites outside of which
//!   every site and bond equals the lead's; its two end bonds then equal the lead's too.

use std::ops::Range;

use crate::bands::Cell;
use crate::chain::{LinearChain, LinearResonator};
use crate::error::SpectrumError;
use crate::transmission::Lead;

/// A cell of a chain: its sites and whether the whole chain repeats it.
#[derive(Debug, Clone, PartialEq)]
pub struct HostCell {
    /// The chain's sites that make the cell (0-based).
    pub sites: Range<usize>,
    /// Whether the chain is this cell repeated (false: the lead's one-site cell of a chain with
    /// defects).
    pub periodic: bool,
    /// The cell, its dashpots left out (bands are those of the conservative chain).
    pub cell: Cell,
}

/// The scattering problem of a chain: its lead and the region that differs from it.
#[derive(Debug, Clone, PartialEq)]
pub struct Scatterer {
    /// The uniform chain on both sides.
    pub lead: Lead,
    /// The chain's sites that differ from the lead (with its resonators), 0-based.
    pub sites: Range<usize>,
    /// Those sites as a chain whose end bonds join the leads.
    pub region: LinearChain,
}

/// The cell `sites` of `chain`, checked to repeat over the whole chain; the error names the
/// first site that breaks the pattern, numbered from `first` (a scene's paper numbering).
pub fn cell_of(
    chain: &LinearChain,
    sites: Range<usize>,
    first: i64,
) -> Result<HostCell, SpectrumError> {
    let paper = |site: usize| first + site as i64;
    let period = sites.len();
    let n = chain.n_sites();
    if period == 0 || sites.end > n || n < sites.start + 2 * period {
        return Err(SpectrumError::CellDoesNotRepeat {
            reason: format!(
                "a cell of {period} site(s) from site {} needs two copies in the chain's {n} sites",
                paper(sites.start)
            ),
        });
    }
    if let Some(site) = first_break(chain, period) {
        return Err(SpectrumError::CellDoesNotRepeat {
            reason: format!(
                "site {} differs from site {}, one period before",
                paper(site),
                paper(site - period)
            ),
        });
    }
    Ok(HostCell {
        cell: conservative_cell(chain, sites.clone())?,
        sites,
        periodic: true,
    })
}

/// The shortest cell the whole chain repeats (at least twice), or the lead's one-site cell when
/// it repeats none.
pub fn detect_cell(chain: &LinearChain, first: i64) -> Result<HostCell, SpectrumError> {
    let n = chain.n_sites();
    if let Some(period) = (1..=n / 2).find(|&p| first_break(chain, p).is_none()) {
        return cell_of(chain, 0..period, first);
    }
    let lead = lead_of(chain, first)?;
    Ok(HostCell {
        sites: 0..1,
        periodic: false,
        cell: Cell::new(vec![lead.mass()], vec![lead.stiffness()], Vec::new())?,
    })
}

/// The lead and the region of `chain` (see the module documentation); messages number sites
/// from `first`.
pub fn scatterer(chain: &LinearChain, first: i64) -> Result<Scatterer, SpectrumError> {
    let lead = lead_of(chain, first)?;
    let n = chain.n_sites();
    let differs = |site: usize| {
        chain.mass(site) != lead.mass()
            || !chain.resonators_on(site).is_empty()
            || chain.ground_damping(site) != 0.0
            || [site, site + 1].iter().any(|&b| {
                (1..n).contains(&b)
                    && (chain.stiffness(b) != lead.stiffness() || chain.bond_damping(b) != 0.0)
            })
    };
    let top = (0..n).find(|&s| differs(s));
    let bottom = (0..n).rev().find(|&s| differs(s));
    let sites = match (top, bottom) {
        (Some(a), Some(b)) => a..b + 1,
        // A uniform chain: one of its own sites, which scatters nothing.
        _ => 1..2,
    };
    if sites.start == 0 || sites.end >= n {
        return Err(SpectrumError::NoLead {
            reason: format!(
                "sites {}..={} differ from the lead and reach the chain's end: keep a lead site at each end",
                first + sites.start as i64,
                first + sites.end as i64 - 1
            ),
        });
    }
    Ok(Scatterer {
        region: chain.sub_chain(sites.clone())?,
        lead,
        sites,
    })
}

/// The lead the chain starts with: its first site's mass and the bond after it.
fn lead_of(chain: &LinearChain, first: i64) -> Result<Lead, SpectrumError> {
    let no_lead = |reason: &str| SpectrumError::NoLead {
        reason: reason.to_string(),
    };
    if chain.n_sites() < 3 {
        return Err(no_lead("a chain of fewer than 3 sites has no lead"));
    }
    if !chain.resonators_on(0).is_empty() {
        return Err(no_lead(&format!(
            "its first site, {first}, carries a resonator, so the chain starts with no uniform lead"
        )));
    }
    if (0..chain.n_sites()).any(|s| chain.ground_damping(s) != 0.0) {
        return Err(no_lead(
            "ground damping acts on every site, so no lead carries a wave without loss",
        ));
    }
    Lead::new(chain.mass(0), chain.stiffness(1))
}

/// The first site (≥ period) whose mass, resonators, ground dashpot or interior bond on the
/// left differ from those one period before, if any.
fn first_break(chain: &LinearChain, period: usize) -> Option<usize> {
    let resonators = |site: usize| -> Vec<LinearResonator> {
        let mut list: Vec<LinearResonator> = chain
            .resonators_on(site)
            .iter()
            .map(|&j| chain.resonators()[j])
            .map(|r| LinearResonator { site: 0, ..r })
            .collect();
        list.sort_by(|a, b| {
            (a.mass, a.stiffness, a.damping)
                .partial_cmp(&(b.mass, b.stiffness, b.damping))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        list
    };
    let bond = |b: usize| (chain.stiffness(b), chain.bond_damping(b));
    (period..chain.n_sites()).find(|&site| {
        let before = site - period;
        chain.mass(site) != chain.mass(before)
            || chain.ground_damping(site) != chain.ground_damping(before)
            || resonators(site) != resonators(before)
            || (before >= 1 && bond(site) != bond(before))
    })
}

/// The cell of sites `sites` of a chain that repeats it, without dashpots.
fn conservative_cell(chain: &LinearChain, sites: Range<usize>) -> Result<Cell, SpectrumError> {
    let period = sites.len();
    let masses = sites.clone().map(|s| chain.mass(s)).collect();
    // The bond in front of each cell site, taken where it is interior (a later copy for site 0).
    let bonds = sites
        .clone()
        .map(|s| chain.stiffness(if s == 0 { s + period } else { s }))
        .collect();
    let resonators = sites
        .clone()
        .flat_map(|s| {
            chain
                .resonators_on(s)
                .iter()
                .map(move |&j| LinearResonator {
                    site: s - sites.start,
                    damping: 0.0,
                    ..chain.resonators()[j]
                })
        })
        .collect();
    Cell::new(masses, bonds, resonators)
}

#[cfg(test)]
mod tests;
