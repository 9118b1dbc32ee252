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
//! - the wave at ω travels at the lead's group velocity c0 cos(q/2), and the region holds it
//!   for its Wigner delay d arg t/dω (long near a narrow resonance), so only frequencies whose
//!   delay from the impulse to the probe, at every frequency the run's window blurs with it, is
//!   at most `ARRIVED` of `t_end` have
//!   arrived whole and are resolved; only those rows are given, and the run says how many
//!   it could not resolve.

use std::f64::consts::PI;

use woodpile_scene::Scene;
use woodpile_sim::integrate::Stoppable;
use woodpile_sim::observe::SiteField;
use woodpile_sim::simulation::simulate;

use crate::analysis::Transmission;
use crate::chain::LinearChain;
use crate::scene::{Asked, Measured, Refusal, SceneSpectrum};
use crate::transmission::{scatter, Lead};

/// Sites of margin left between the fastest echo's arrival at the probe and `t_end`: the
/// lattice's front is not sharp, and ahead of it the signal is small but not zero.
const ECHO_MARGIN_SITES: f64 = 20.0;

/// The largest delay from the impulse to the probe, as a share of the run, of a frequency the
/// run measures: its wave has then arrived whole well before the taper of [`transform`]
/// begins. Chosen by measurement: at 0.25 and 0.2 a narrow cavity resonance near the band edge
/// of the double defect rod still put |t| 1.2e-3 off; at 0.15 every measured scene keeps
/// within 1e-3 (docs/spectrum.md).
const ARRIVED: f64 = 0.15;

/// Runs `scene` and measures its transmission on the frequencies of `spectrum`'s transmission
/// that the run can resolve (see the module documentation); the probe is paper site `probe`,
/// by default as far past the region as the impulse is before it.
/// `stop` is asked at every sample: once it says so, the run ends as cancelled (Ctrl-C in
/// Python).
pub fn measure(
    scene: &Scene,
    spectrum: &SceneSpectrum,
    probe: Option<i64>,
    stop: &dyn Fn() -> bool,
) -> Result<Measured, Refusal> {
    let setup = setup(scene, spectrum, probe)?;
    let s = &scene.scenario;
    let (lead, t) = (&setup.transmission.scatterer.lead, setup.transmission);
    let mut probed = Stoppable {
        inner: SiteField::new(&s.model, setup.probe, setup.probe),
        stop,
    };
    simulate(s, &mut probed).map_err(|e| Refusal {
        asked: Asked::Run,
        reason: format!("the run failed: {e}"),
    })?;
    let field = probed.inner;
    let c0 = (lead.stiffness() / lead.mass()).sqrt();
    let distance = (setup.probe - s.impulse_site) as f64;
    let delays = Delays::over(lead, &t.scatterer.region, distance, s.t_end);
    let rows: Vec<_> = t
        .scattering
        .iter()
        .filter(|r| delays.longest_near(r.omega) <= ARRIVED * s.t_end)
        .collect();
    if rows.is_empty() {
        return Err(Refusal {
            asked: Asked::Window,
            reason: format!(
                "{}: no frequency of the transmission arrives at the probe early enough to be resolved; lengthen the run (and the chain)",
                spectrum.time_text(s.t_end)
            ),
        });
    }
    let v = s.impulse_velocity;
    let incident = |omega: f64| {
        let q = lead.wavenumber(omega).unwrap_or(PI);
        lead.mass() * v * omega / (2.0 * lead.stiffness() * q.sin())
    };
    let delta0 = s.model.static_overlap(t.scatterer.sites.start);
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

/// The time the wave at ω takes from the impulse to the probe, `distance` sites apart: the
/// lead's group delay over the distance, c0 cos(q/2) sites per unit time, plus the region's
/// own (Wigner) delay d arg t / dω, which is long near a narrow resonance, where the wave
/// rings in the region before it leaves. `None` where t vanishes (no phase) or the derivative
/// cannot be taken inside the band.
fn delay(lead: &Lead, region: &LinearChain, omega: f64, distance: f64, c0: f64) -> Option<f64> {
    let q = lead.wavenumber(omega).ok()?;
    let h = 1e-7 * lead.cutoff();
    let pair = scatter(lead, region, &[omega - h, omega + h]).ok()?;
    if pair.iter().any(|p| p.transmission.norm() == 0.0) {
        return None;
    }
    let turn = pair[1].phase() - pair[0].phase();
    // The phase is taken in (−π, π]: a step across the cut is a wrap, not a delay.
    let turn = turn - (2.0 * PI) * (turn / (2.0 * PI)).round();
    Some(distance / (c0 * (q / 2.0).cos()) + turn / (2.0 * h))
}

/// The delays on a grid fine enough to see what a window of the run's length blurs together.
struct Delays {
    /// Grid spacing.
    step: f64,
    /// The delay at each grid frequency (infinite where it cannot be taken).
    delay: Vec<f64>,
    /// The run's frequency resolution, 2π/t_end.
    resolution: f64,
}

impl Delays {
    /// [`delay`] on a grid of spacing 1/8 of the run's resolution over the lead's band.
    fn over(lead: &Lead, region: &LinearChain, distance: f64, t_end: f64) -> Delays {
        let resolution = 2.0 * PI / t_end;
        let step = resolution / 8.0;
        let count = (lead.cutoff() / step) as usize;
        let c0 = 0.5 * lead.cutoff();
        let delay = (1..count)
            .map(|i| delay(lead, region, i as f64 * step, distance, c0).unwrap_or(f64::INFINITY))
            .collect();
        Delays {
            step,
            delay,
            resolution,
        }
    }

    /// The longest delay within four resolutions of ω: the tapered window's transform at ω
    /// mixes in what rings there.
    fn longest_near(&self, omega: f64) -> f64 {
        let lo = ((omega - 4.0 * self.resolution) / self.step)
            .floor()
            .max(1.0) as usize;
        let hi = ((omega + 4.0 * self.resolution) / self.step).ceil() as usize;
        let slice = &self.delay[(lo - 1).min(self.delay.len())..hi.min(self.delay.len())];
        slice.iter().copied().fold(0.0, f64::max)
    }
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
    let time = |t: f64| spectrum.time_text(t);
    if sample_every * cutoff > PI / 2.0 {
        return Err(Refusal {
            asked: Asked::Sampling,
            reason: format!(
                "{} is too coarse: the transform needs four samples per period of the lead's highest frequency ({:.4} {}); sample every {} or less",
                time(sample_every),
                spectrum.frequency(cutoff),
                spectrum.frequency_unit(),
                time(PI / (2.0 * cutoff))
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
                "{} lets an echo from a wall reach the probe: end the run by {}, or lengthen the chain, or move the impulse and the probe away from the walls",
                time(t_end),
                time(echo / c0)
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
