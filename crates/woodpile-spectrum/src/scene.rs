//! A scene's linear picture in the scene's own terms: paper site numbers, and frequencies in Hz
//! for a `[physical]` scene (cycles per unit of scaled time otherwise). What `woodpile
//! spectrum`, the `spectrum` stage and Python's `woodpile.spectrum` share; each turns
//! [`SceneSpectrum`] into its own output ([`crate::tables`] gives the columns).
//!
//! The scene is linearised about its static state ([`crate::linearise_precompressed`]), with
//! its resonators' couplings at t = 0. Frequencies asked for may be numbers (in the scene's
//! frequency unit) or, for a physical scene, text with a unit: `"12.5 kHz"` (Hz, kHz, MHz).

use std::f64::consts::TAU;
use std::ops::Range;

use woodpile_scene::units_out::{SiFactors, Units};
use woodpile_scene::Scene;

use crate::analysis::{analyse, Analysis, FrequencyGrid, Request};
use crate::error::{RangeFault, SpectrumError};
use crate::linearise::linearise_precompressed;

/// What is asked of a scene's spectrum, in the scene's terms.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneRequest {
    /// The host cell, paper sites `[lo, hi]` inclusive; `None` finds it.
    pub cell: Option<[i64; 2]>,
    /// The transmission's frequencies in the scene's frequency unit, and how many.
    pub frequencies: Option<(Frequency, Frequency, usize)>,
}

/// A frequency as written: a number in the scene's unit, or text with a unit.
#[derive(Debug, Clone, PartialEq)]
pub enum Frequency {
    /// In the scene's frequency unit.
    Number(f64),
    /// `"<number> <Hz|kHz|MHz>"`.
    Text(String),
}

/// Which part of a request a refusal is about, for the caller to name its own key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Asked {
    /// The scene itself (no static load, a chain too short): no key of the request.
    Scene,
    /// The cell.
    Cell,
    /// The frequency range.
    Frequencies,
    /// The probe site of a measured transmission.
    Probe,
    /// The run's sampling (`run.sample_every`), for a measured transmission.
    Sampling,
    /// The run's length (`run.t_end`), for a measured transmission.
    Window,
    /// Not the request: the run of a measured transmission failed.
    Run,
}

/// A refusal, and the part of the request it is about.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// The part asked.
    pub asked: Asked,
    /// Why.
    pub reason: String,
}

/// The linear picture of a scene, with what converts it to the scene's units.
#[derive(Debug, Clone)]
pub struct SceneSpectrum {
    /// The picture, in the model's units.
    pub analysis: Analysis,
    /// The paper number of internal site 0.
    pub first_site: i64,
    /// Number of sites.
    pub n_sites: usize,
    /// Units per unit of model time (seconds for a physical scene, else 1).
    pub time_unit: f64,
    /// Whether frequencies are in Hz (a physical scene).
    pub si: bool,
    /// The paper sites of resonators left out of the linear picture (no linear coupling).
    pub detached: Vec<i64>,
    /// Number of resonators in the linear picture.
    pub resonators: usize,
    /// Whether the linear chain has dashpots.
    pub damped: bool,
    /// Whether the chain is graded (in gravity): it has no host cell, no lead, and no mode
    /// counts as localised.
    pub graded: bool,
    /// The transmission measured from the scene's own run, once [`crate::measured::measure`]
    /// has run it.
    pub measured: Option<Measured>,
}

/// The transmission measured from a run, on the frequencies that arrived.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The probe, paper numbering.
    pub probe: i64,
    /// The impulse's amplitude over the precompression's own velocity scale c0 δ0 (the
    /// particle velocity of a strain equal to the static one): the linear limit is ≪ 1.
    pub amplitude: f64,
    /// ω of each row (model units).
    pub omega: Vec<f64>,
    /// |t|² of the linear picture.
    pub linear: Vec<f64>,
    /// |t|² measured from the run.
    pub measured: Vec<f64>,
}

impl Measured {
    /// The largest difference of |t| between the run and the linear picture, over the rows.
    pub fn departure(&self) -> f64 {
        self.linear
            .iter()
            .zip(&self.measured)
            .map(|(a, b)| (a.sqrt() - b.sqrt()).abs())
            .fold(0.0, f64::max)
    }
}

impl SceneSpectrum {
    /// ω in model units → the scene's frequency unit.
    pub fn frequency(&self, omega: f64) -> f64 {
        omega / (TAU * self.time_unit)
    }

    /// A rate in model units (per unit time) → per the scene's time unit.
    pub fn rate(&self, rate: f64) -> f64 {
        rate / self.time_unit
    }

    /// A time of the model as the scene writes it: seconds for a physical scene.
    pub fn time_text(&self, t: f64) -> String {
        match self.si {
            true => format!("{:.4e} s", t * self.time_unit),
            false => format!("{t:.4}"),
        }
    }

    /// The paper number of internal site `site`.
    pub fn paper_site(&self, site: usize) -> i64 {
        self.first_site + site as i64
    }

    /// The scene's frequency unit: `"Hz"`, or `"1/time"` for scaled scenes.
    pub fn frequency_unit(&self) -> &'static str {
        match self.si {
            true => "Hz",
            false => "1/time",
        }
    }
}

/// The linear picture of `scene` (see the module documentation).
pub fn scene_spectrum(scene: &Scene, request: &SceneRequest) -> Result<SceneSpectrum, Refusal> {
    let refuse = |asked: Asked| {
        move |e: SpectrumError| Refusal {
            asked,
            reason: e.to_string(),
        }
    };
    let si = SiFactors::of(scene, Units::Si).ok().flatten();
    let time_unit = si.map_or(1.0, |f| f.time_s);
    let model = &scene.scenario.model;
    let linear = linearise_precompressed(model, 0.0).map_err(refuse(Asked::Scene))?;
    let cell = match request.cell {
        None => None,
        Some([lo, hi]) => Some(paper_range(scene, lo, hi)?),
    };
    let frequencies = match &request.frequencies {
        None => None,
        Some((lower, upper, points)) => {
            let omega = |f: &Frequency| Ok(TAU * time_unit * hertz(f, si.is_some())?);
            Some(FrequencyGrid {
                lower: omega(lower)?,
                upper: omega(upper)?,
                points: *points,
            })
        }
    };
    let in_hz = |omega: f64| omega / (TAU * time_unit);
    let unit = if si.is_some() {
        "Hz"
    } else {
        "cycles per unit time"
    };
    let graded = model.contacts().is_some_and(|law| law.gravity() > 0.0);
    let request = Request {
        cell,
        frequencies,
        first_site: scene.first_site,
        graded,
    };
    let analysis = analyse(&linear.chain, &request).map_err(|e| match e {
        SpectrumError::CellDoesNotRepeat { .. } => refuse(Asked::Cell)(e),
        SpectrumError::NoLead { .. } => refuse(Asked::Frequencies)(e),
        // Said in the unit the range was given in.
        SpectrumError::BadRange {
            lower,
            upper,
            points,
            fault,
        } => Refusal {
            asked: Asked::Frequencies,
            reason: match fault {
                RangeFault::OutsideBand { cutoff } => format!(
                    "[{}, {}] {unit} must lie inside the leads' pass band (0, {}) {unit}, where a wave travels to scatter",
                    in_hz(lower),
                    in_hz(upper),
                    in_hz(cutoff)
                ),
                fault => format!("[{}, {}] {unit} with {points} point(s): {fault}", in_hz(lower), in_hz(upper)),
            },
        },
        _ => refuse(Asked::Scene)(e),
    })?;
    let resonators = model.resonators();
    Ok(SceneSpectrum {
        resonators: linear.chain.resonators().len(),
        damped: linear.chain.is_damped(),
        graded,
        detached: linear
            .detached
            .iter()
            .map(|&j| scene.first_site + resonators[j].site as i64)
            .collect(),
        analysis,
        first_site: scene.first_site,
        n_sites: model.n_sites(),
        time_unit,
        si: si.is_some(),
        measured: None,
    })
}

/// The internal sites of paper sites `lo..=hi`.
fn paper_range(scene: &Scene, lo: i64, hi: i64) -> Result<Range<usize>, Refusal> {
    let (a, b) = scene.site_range(lo, hi).map_err(|reason| Refusal {
        asked: Asked::Cell,
        reason,
    })?;
    Ok(a..b + 1)
}

/// A frequency in the scene's unit: a number as it is, text parsed with its unit (physical
/// scenes only).
fn hertz(f: &Frequency, si: bool) -> Result<f64, Refusal> {
    let refuse = |reason: String| Refusal {
        asked: Asked::Frequencies,
        reason,
    };
    let text = match f {
        Frequency::Number(x) => return Ok(*x),
        Frequency::Text(text) => text.trim(),
    };
    if !si {
        return Err(refuse(format!(
            "`{text}`: a frequency with a unit needs a [physical] scene; give a number in cycles per unit time"
        )));
    }
    woodpile_scene::quantity::parse(text, "frequency").map_err(refuse)
}

#[cfg(test)]
mod tests;
