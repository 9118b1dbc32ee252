//! The whole linear picture of one chain, as `woodpile spectrum`, the `spectrum` stage and
//! Python ask for it: its host cell's bands and the attenuation in their gaps, its modes (all of
//! them where a dense solve fits, else those in the host's stop bands), and the transmission of
//! its defect region. Everything is in the chain's own units (ω in rad per unit time); callers
//! convert.
//!
//! A part that does not apply to a chain (no lead to scatter from, a chain too long for every
//! mode) is returned as the reason it does not, so the rest of the picture is still given; a
//! request that cannot be met (a cell that does not repeat, an empty or out-of-band frequency
//! range) is an error.

use std::ops::Range;

use crate::bands::{Bands, Interval, Wavenumber};
use crate::chain::LinearChain;
use crate::damped::{damped_modes, DampedMode};
use crate::error::{RangeFault, SpectrumError};
use crate::host::{cell_of, detect_cell, scatterer, HostCell, Scatterer};
use crate::localised::localised_modes;
use crate::modes::{normal_modes, Mode, MAX_DENSE_ORDER};
use crate::transmission::{scatter, Scattering};

/// Wavenumbers sampled over [0, π] for the bands.
pub const BAND_WAVENUMBERS: usize = 201;
/// Frequencies sampled for the complex wavenumber, from 0 to [`WAVENUMBER_SPAN`] times the top
/// band's upper edge.
pub const WAVENUMBER_FREQUENCIES: usize = 401;
/// How far above the top band the complex wavenumber is sampled.
pub const WAVENUMBER_SPAN: f64 = 1.25;
/// Why a graded chain has no transmission.
const GRADED: &str = "a chain in gravity is graded (its contacts stiffen with depth), so it has no uniform lead to scatter from; its modes are every mode of the chain";

/// Frequencies in the default transmission grid.
pub const DEFAULT_POINTS: usize = 400;

/// What to compute beyond the defaults.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Request {
    /// The host cell (0-based sites); `None` finds it ([`crate::host::detect_cell`]).
    pub cell: Option<Range<usize>>,
    /// The transmission's frequencies: `[lower, upper]` (ω) and how many; `None` for
    /// [`DEFAULT_POINTS`] spread evenly inside the leads' band.
    pub frequencies: Option<FrequencyGrid>,
    /// The number messages give site 0 (a scene's paper numbering).
    pub first_site: i64,
    /// Whether the chain is graded (in gravity, its contacts stiffen with depth): it then has
    /// no uniform lead to scatter from, and no host whose stop bands make a mode localised.
    pub graded: bool,
}

/// `points` frequencies evenly spaced over [lower, upper] (ω), ends included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrequencyGrid {
    /// First frequency.
    pub lower: f64,
    /// Last frequency.
    pub upper: f64,
    /// How many (≥ 2, or 1 with lower = upper).
    pub points: usize,
}

/// The linear picture of a chain (see the module documentation).
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The host cell.
    pub host: HostCell,
    /// ω_j(q) of the host cell on [`BAND_WAVENUMBERS`] wavenumbers.
    pub bands: Bands,
    /// Its pass bands and gaps.
    pub pass_bands: Vec<Interval>,
    /// Its gaps.
    pub gaps: Vec<Interval>,
    /// (ω, q + iκ) of the host cell, on a grid over and above its bands.
    pub wavenumbers: Vec<(f64, Wavenumber)>,
    /// The windows where modes count as localised: the host's stop bands below the chain's
    /// frequency bound.
    pub windows: Vec<Interval>,
    /// The modes.
    pub modes: Modes,
    /// The transmission, or why the chain has none.
    pub transmission: Result<Transmission, String>,
}

/// A chain's modes.
#[derive(Debug, Clone)]
pub struct Modes {
    /// Every mode (`complete`), or those in the stop bands.
    pub undamped: Vec<Mode>,
    /// Whether `undamped` is every mode of the chain.
    pub complete: bool,
    /// With dashpots, the damped modes (complex frequencies), or why they were not computed.
    pub damped: Option<Result<Vec<DampedMode>, String>>,
}

/// The scattering of the chain's region between its leads.
#[derive(Debug, Clone)]
pub struct Transmission {
    /// The leads and the region.
    pub scatterer: Scatterer,
    /// t and r at each frequency.
    pub scattering: Vec<Scattering>,
}

impl FrequencyGrid {
    /// The frequencies.
    pub fn omegas(&self) -> Vec<f64> {
        match self.points {
            1 => vec![self.lower],
            n => (0..n)
                .map(|i| self.lower + (self.upper - self.lower) * i as f64 / (n - 1) as f64)
                .collect(),
        }
    }

    /// Checks it holds frequencies and lies inside (0, `cutoff`).
    fn check(&self, cutoff: f64) -> Result<(), SpectrumError> {
        let fault = if !(self.lower.is_finite() && self.upper.is_finite()) {
            RangeFault::NotFinite
        } else if self.points == 0
            || self.lower > self.upper
            || (self.points == 1) != (self.lower == self.upper)
        {
            RangeFault::Empty
        } else if self.lower <= 0.0 || self.upper >= cutoff {
            RangeFault::OutsideBand { cutoff }
        } else {
            return Ok(());
        };
        Err(SpectrumError::BadRange {
            lower: self.lower,
            upper: self.upper,
            points: self.points,
            fault,
        })
    }
}

/// The linear picture of `chain` (see the module documentation).
pub fn analyse(chain: &LinearChain, request: &Request) -> Result<Analysis, SpectrumError> {
    let host = match &request.cell {
        Some(sites) => cell_of(chain, sites.clone(), request.first_site)?,
        None => detect_cell(chain, request.first_site)?,
    };
    let pass_bands = host.cell.pass_bands()?;
    let top = pass_bands.last().map_or(0.0, |band| band.upper);
    let wavenumbers = (0..WAVENUMBER_FREQUENCIES)
        .map(|i| {
            let omega = WAVENUMBER_SPAN * top * i as f64 / (WAVENUMBER_FREQUENCIES - 1) as f64;
            Ok((omega, host.cell.wavenumber(omega)?))
        })
        .collect::<Result<_, SpectrumError>>()?;
    let windows = match request.graded {
        true => Vec::new(),
        false => host.cell.stop_bands(chain.frequency_bound())?,
    };
    let transmission = match request.graded {
        true => Ok(Err(GRADED.to_string())),
        false => transmission(chain, request.frequencies, request.first_site),
    }?;
    Ok(Analysis {
        bands: host.cell.bands(BAND_WAVENUMBERS)?,
        gaps: host.cell.gaps()?,
        pass_bands,
        wavenumbers,
        modes: modes(chain, &windows)?,
        windows,
        host,
        transmission,
    })
}

/// Every mode when the dense solve fits, else the modes in `windows`; the damped modes too
/// when the chain has dashpots and they fit.
fn modes(chain: &LinearChain, windows: &[Interval]) -> Result<Modes, SpectrumError> {
    let complete = chain.n_dof() <= MAX_DENSE_ORDER;
    let undamped = match complete {
        true => normal_modes(chain)?,
        false => localised_modes(chain, windows)?,
    };
    let damped = chain
        .is_damped()
        .then(|| damped_modes(chain).map_err(|e| e.to_string()));
    Ok(Modes {
        undamped,
        complete,
        damped,
    })
}

/// The transmission over the asked grid (checked against the leads' band), or why the chain
/// has no leads.
fn transmission(
    chain: &LinearChain,
    grid: Option<FrequencyGrid>,
    first_site: i64,
) -> Result<Result<Transmission, String>, SpectrumError> {
    let scatterer = match scatterer(chain, first_site) {
        Ok(s) => s,
        Err(SpectrumError::NoLead { reason }) => {
            if grid.is_some() {
                return Err(SpectrumError::NoLead { reason });
            }
            return Ok(Err(reason));
        }
        Err(e) => return Err(e),
    };
    let cutoff = scatterer.lead.cutoff();
    let grid = grid.unwrap_or(FrequencyGrid {
        lower: cutoff / (DEFAULT_POINTS + 1) as f64,
        upper: cutoff * DEFAULT_POINTS as f64 / (DEFAULT_POINTS + 1) as f64,
        points: DEFAULT_POINTS,
    });
    grid.check(cutoff)?;
    let scattering = scatter(&scatterer.lead, &scatterer.region, &grid.omegas())?;
    Ok(Ok(Transmission {
        scatterer,
        scattering,
    }))
}

#[cfg(test)]
mod tests;
