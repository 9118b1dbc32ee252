//! The transmission measured from the scene's own nonlinear run, to set beside the linear one.
//!
//! The scene's impulse gives one site of the left lead a velocity V. In the linear chain its
//! wave reaching any site downstream has the Fourier transform (u(t) = 0 before the impulse,
//! V̂(ω) = ∫ v(t) e^{iωt} dt)
//!
//! ```text
//! |V̂_incident(ω)| = m V ω / (2 K sin q),     cos q = 1 − ω² m / (2K)   (lead m, K)
//! ```
//!
//! whatever the distance (a lossless lead only delays it), so the velocity v_p(t) recorded at a
//! probe site of the right lead gives |t(ω)| = |V̂_p(ω)| / |V̂_incident(ω)| with no reference
//! run. The transform is taken by the trapezoid rule over the samples, which is spectrally
//! accurate for a band-limited signal sampled well above its Nyquist rate.
//!
//! Two things bound what the run can measure, and both are checked rather than assumed:
//! - no echo may reach the probe before `t_end`: the fastest signal (the lead's sound speed
//!   c0 = sqrt(K/m) sites per unit time) must not come back from either wall in time;
//! - the wave at ω travels at the lead's group velocity c0 cos(q/2), so only frequencies whose
//!   group delay from the impulse to the probe is at most a quarter of `t_end` (`ARRIVED`) have
//!   arrived whole, and only those rows are given.

use std::f64::consts::PI;

use woodpile_scene::Scene;
use woodpile_sim::observe::SiteField;
use woodpile_sim::simulation::simulate;

use crate::analysis::Transmission;
use crate::scene::{Asked, Refusal, SceneSpectrum};

/// Sites of margin left between the fastest echo's arrival at the probe and `t_end`: the
/// lattice's front is not sharp, and ahead of it the signal is small but not zero.
const ECHO_MARGIN_SITES: f64 = 20.0;

/// The largest group delay from the impulse to the probe, as a share of the run, of a
/// frequency the run measures: its wave has then arrived whole well before the taper of
/// [`transform`] begins.
const ARRIVED: f64 = 0.25;

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

/// Runs `scene` and measures its transmission on the frequencies of `spectrum`'s transmission
/// that the run can resolve (see the module documentation); the probe is paper site `probe`,
/// by default as far past the region as the impulse is before it.
pub fn measure(
    scene: &Scene,
    spectrum: &SceneSpectrum,
    probe: Option<i64>,
) -> Result<Measured, Refusal> {
    let setup = setup(scene, spectrum, probe)?;
    let s = &scene.scenario;
    let (lead, t) = (&setup.transmission.scatterer.lead, setup.transmission);
    let mut field = SiteField::new(&s.model, setup.probe, setup.probe);
    simulate(s, &mut field).map_err(|e| Refusal {
        asked: Asked::Scene,
        reason: format!("the run failed: {e}"),
    })?;
    let c0 = (lead.stiffness() / lead.mass()).sqrt();
    let delay = |omega: f64| {
        let q = lead.wavenumber(omega).unwrap_or(PI);
        (setup.probe - s.impulse_site) as f64 / (c0 * (q / 2.0).cos())
    };
    let rows: Vec<_> = t
        .scattering
        .iter()
        .filter(|r| delay(r.omega) <= ARRIVED * s.t_end)
        .collect();
    let v = s.impulse_velocity;
    let incident = |omega: f64| {
        let q = lead.wavenumber(omega).unwrap_or(PI);
        lead.mass() * v * omega / (2.0 * lead.stiffness() * q.sin())
    };
    let delta0 = s
        .model
        .contacts()
        .map_or(0.0, |law| law.static_overlap(t.scatterer.sites.start));
    Ok(Measured {
        probe: spectrum.paper_site(setup.probe),
        amplitude: v.abs() / (c0 * delta0),
        omega: rows.iter().map(|r| r.omega).collect(),
        linear: rows.iter().map(|r| r.transmittance()).collect(),
        measured: rows
            .iter()
            .map(|r| (transform(&field.t, &field.velocity, r.omega) / incident(r.omega)).powi(2))
            .collect(),
    })
}

/// What a measurement needs, checked.
struct Setup<'a> {
    transmission: &'a Transmission,
    /// The probe (internal index).
    probe: usize,
}

/// Checks, without running it, that `scene` can be measured at `probe`: a lead and a region,
/// the impulse in the left lead, the probe in the right one, samples dense enough and no echo
/// within the run.
pub fn check(scene: &Scene, spectrum: &SceneSpectrum, probe: Option<i64>) -> Result<(), Refusal> {
    setup(scene, spectrum, probe).map(|_| ())
}

fn setup<'a>(
    scene: &Scene,
    spectrum: &'a SceneSpectrum,
    probe: Option<i64>,
) -> Result<Setup<'a>, Refusal> {
    let refuse = |asked: Asked, reason: String| Refusal { asked, reason };
    let t = spectrum.analysis.transmission.as_ref().map_err(|reason| {
        refuse(
            Asked::Scene,
            format!("no transmission to measure: {reason}"),
        )
    })?;
    let s = &scene.scenario;
    let (n, region) = (spectrum.n_sites, &t.scatterer.sites);
    let impulse = s.impulse_site;
    if impulse >= region.start || s.region.has_striker() {
        return Err(refuse(
            Asked::Scene,
            format!(
                "the impulse (site {}) must strike the left lead, before the region {}..={}",
                spectrum.paper_site(impulse),
                spectrum.paper_site(region.start),
                spectrum.paper_site(region.end - 1)
            ),
        ));
    }
    let probe = match probe {
        Some(p) => p - spectrum.first_site,
        None => (region.end - 1 + (region.start - impulse)).min(n - 2) as i64,
    };
    if probe < region.end as i64 || probe >= n as i64 {
        return Err(refuse(
            Asked::Probe,
            format!(
                "must lie in the right lead, paper sites {}..={}",
                spectrum.paper_site(region.end),
                spectrum.paper_site(n - 1)
            ),
        ));
    }
    let probe = probe as usize;
    let lead = &t.scatterer.lead;
    let c0 = (lead.stiffness() / lead.mass()).sqrt();
    check_window(
        spectrum,
        s.t_end,
        s.sample_every,
        c0,
        lead.cutoff(),
        [impulse, probe],
    )?;
    Ok(Setup {
        transmission: t,
        probe,
    })
}

/// Refuses a run whose samples are too sparse for the lead's band, or whose window lets an
/// echo from a wall reach the probe.
fn check_window(
    spectrum: &SceneSpectrum,
    t_end: f64,
    sample_every: f64,
    c0: f64,
    cutoff: f64,
    [impulse, probe]: [usize; 2],
) -> Result<(), Refusal> {
    if sample_every * cutoff > PI / 2.0 {
        return Err(Refusal {
            asked: Asked::Sampling,
            reason: format!(
                "{sample_every} samples the lead's band (up to ω = {cutoff}) less than twice per Nyquist interval; at most {} is needed",
                PI / (2.0 * cutoff)
            ),
        });
    }
    let n = spectrum.n_sites as f64;
    let (s, p) = (impulse as f64, probe as f64);
    let echo = (s + p + 1.0).min(2.0 * n - 1.0 - s - p) - ECHO_MARGIN_SITES;
    if t_end * c0 > echo {
        return Err(Refusal {
            asked: Asked::Window,
            reason: format!(
                "{t_end} lets an echo from a wall reach the probe (the lead carries sound at {c0} sites per unit time); at most {} for this chain, or lengthen it",
                echo / c0
            ),
        });
    }
    Ok(())
}

/// Where the taper of [`transform`] begins, as a share of the window.
const TAPER_FROM: f64 = 0.6;

/// |∫ w(t) v(t) e^{iωt} dt| over the samples, by the trapezoid rule, where w is 1 up to
/// [`TAPER_FROM`] of the window and falls to 0 at its end as a half cosine: the waves still
/// arriving at the end (near the band edge, where the group velocity vanishes) are faded out
/// rather than cut, so they do not leak into the frequencies that have arrived.
fn transform(t: &[f64], v: &[f64], omega: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    let last = t.len().saturating_sub(1);
    let end = t.last().copied().unwrap_or(0.0);
    let taper = |time: f64| {
        let x = (time / end - TAPER_FROM) / (1.0 - TAPER_FROM);
        match x > 0.0 {
            true => 0.5 * (1.0 + (PI * x.min(1.0)).cos()),
            false => 1.0,
        }
    };
    for (k, (&time, &value)) in t.iter().zip(v).enumerate() {
        let weight = taper(time) * if k == 0 || k == last { 0.5 } else { 1.0 };
        let step = match k {
            0 => t.get(1).map_or(0.0, |next| next - time),
            _ => time - t[k - 1],
        };
        let (sin, cos) = (omega * time).sin_cos();
        re += weight * step * value * cos;
        im += weight * step * value * sin;
    }
    re.hypot(im)
}

#[cfg(test)]
mod tests;
