//! A scene's linear picture as tables of named columns and one JSON summary: what the CLI
//! writes as parquet and prints, the stage writes as its table, and Python returns as arrays.
//! Frequencies are in the scene's unit ([`SceneSpectrum::frequency_unit`]), ω in the model's
//! rad per unit time, sites in paper numbering.

use serde_json::{json, Value};

use crate::bands::Interval;
use crate::modes::Mode;
use crate::scene::SceneSpectrum;

/// Why a chain in gravity has no bands.
const GRADED_CELL: &str =
    "a chain in gravity is graded (its contacts stiffen with depth): it repeats no cell, so it has no bands";

/// One column's values.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Real numbers.
    F64(Vec<f64>),
    /// Integers (indices, paper sites, flags as 1 and 0, which a figure can select on).
    I64(Vec<i64>),
}

/// A named column.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// Its name.
    pub name: &'static str,
    /// Its values.
    pub values: Values,
}

/// The tables of a picture.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// `band, q, omega, frequency`: ω_j(q) of the host cell.
    Bands,
    /// `omega, frequency, q, attenuation`: the host's complex wavenumber per cell.
    Wavenumber,
    /// `mode, omega, frequency, localised (1 in a stop band of the host, else 0), peak_site,
    /// participation, localisation_length`.
    Modes,
    /// `mode, omega, frequency, decay_rate, q_factor`: with dashpots.
    Damped,
    /// `mode, site, displacement`: the undamped mode shapes over the sites.
    Shapes,
    /// `omega, frequency, transmittance, reflectance, absorbance, phase, log_transmission`.
    Transmission,
    /// `omega, frequency, linear, measured`: |t|² of the linear picture and of the scene's
    /// own run ([`crate::measured`]), on the frequencies the run resolves.
    Measured,
}

impl Part {
    /// Every part of the linear picture (no run needed), in the order they are written.
    pub const LINEAR: [Part; 6] = [
        Part::Bands,
        Part::Wavenumber,
        Part::Modes,
        Part::Damped,
        Part::Shapes,
        Part::Transmission,
    ];

    /// Its name: the file stem and the stage's `table`.
    pub fn name(self) -> &'static str {
        match self {
            Part::Bands => "bands",
            Part::Wavenumber => "wavenumber",
            Part::Modes => "modes",
            Part::Damped => "damped",
            Part::Shapes => "shapes",
            Part::Transmission => "transmission",
            Part::Measured => "measured",
        }
    }

    /// The part named `name`.
    pub fn parse(name: &str) -> Result<Part, String> {
        let all = || Part::LINEAR.into_iter().chain([Part::Measured]);
        all().find(|p| p.name() == name).ok_or_else(|| {
            let names: Vec<&str> = all().map(|p| p.name()).collect();
            format!("`{name}` is not one of {}", names.join(", "))
        })
    }
}

fn f64s(name: &'static str, values: impl IntoIterator<Item = f64>) -> Column {
    Column {
        name,
        values: Values::F64(values.into_iter().collect()),
    }
}

fn i64s(name: &'static str, values: impl IntoIterator<Item = i64>) -> Column {
    Column {
        name,
        values: Values::I64(values.into_iter().collect()),
    }
}

/// The columns of `part`, or why the scene has no such table (no leads, no dashpots).
pub fn table(s: &SceneSpectrum, part: Part) -> Result<Vec<Column>, String> {
    let a = &s.analysis;
    if s.graded && matches!(part, Part::Bands | Part::Wavenumber) {
        return Err(GRADED_CELL.into());
    }
    Ok(match part {
        Part::Bands => {
            let rows = a.bands.q.iter().zip(&a.bands.omega);
            let rows: Vec<(usize, f64, f64)> = rows
                .flat_map(|(&q, omegas)| omegas.iter().enumerate().map(move |(j, &w)| (j, q, w)))
                .collect();
            vec![
                i64s("band", rows.iter().map(|r| r.0 as i64)),
                f64s("q", rows.iter().map(|r| r.1)),
                f64s("omega", rows.iter().map(|r| r.2)),
                f64s("frequency", rows.iter().map(|r| s.frequency(r.2))),
            ]
        }
        Part::Wavenumber => vec![
            f64s("omega", a.wavenumbers.iter().map(|w| w.0)),
            f64s("frequency", a.wavenumbers.iter().map(|w| s.frequency(w.0))),
            f64s("q", a.wavenumbers.iter().map(|w| w.1.q)),
            f64s("attenuation", a.wavenumbers.iter().map(|w| w.1.attenuation)),
        ],
        Part::Modes => modes(s, &a.modes.undamped),
        Part::Damped => damped(s)?,
        Part::Shapes => shapes(s),
        Part::Transmission => transmission(s)?,
        Part::Measured => {
            let m = s.measured.as_ref().ok_or("the scene has not been run")?;
            vec![
                f64s("omega", m.omega.iter().copied()),
                f64s("frequency", m.omega.iter().map(|&w| s.frequency(w))),
                f64s("linear", m.linear.iter().copied()),
                f64s("measured", m.measured.iter().copied()),
            ]
        }
    })
}

fn modes(s: &SceneSpectrum, modes: &[Mode]) -> Vec<Column> {
    let windows = &s.analysis.windows;
    vec![
        i64s("mode", 0..modes.len() as i64),
        f64s("omega", modes.iter().map(|m| m.omega)),
        f64s("frequency", modes.iter().map(|m| s.frequency(m.omega))),
        i64s(
            "localised",
            modes.iter().map(|m| i64::from(m.in_any(windows))),
        ),
        i64s(
            "peak_site",
            modes.iter().map(|m| s.paper_site(m.localisation.peak_site)),
        ),
        f64s(
            "participation",
            modes.iter().map(|m| m.localisation.participation),
        ),
        f64s(
            "localisation_length",
            modes.iter().map(|m| m.localisation.length),
        ),
    ]
}

fn damped(s: &SceneSpectrum) -> Result<Vec<Column>, String> {
    let modes = match &s.analysis.modes.damped {
        None => return Err("the linear chain has no dashpot".into()),
        Some(Err(reason)) => return Err(reason.clone()),
        Some(Ok(modes)) => modes,
    };
    Ok(vec![
        i64s("mode", 0..modes.len() as i64),
        f64s("omega", modes.iter().map(|m| m.omega())),
        f64s("frequency", modes.iter().map(|m| s.frequency(m.omega()))),
        f64s("decay_rate", modes.iter().map(|m| s.rate(m.decay_rate()))),
        f64s("q_factor", modes.iter().map(|m| m.q_factor())),
    ])
}

fn shapes(s: &SceneSpectrum) -> Vec<Column> {
    let modes = &s.analysis.modes.undamped;
    let n = s.n_sites;
    let rows = modes.len() * n;
    vec![
        i64s("mode", (0..rows).map(|i| (i / n) as i64)),
        i64s("site", (0..rows).map(|i| s.paper_site(i % n))),
        f64s(
            "displacement",
            modes.iter().flat_map(|m| m.sites(n).iter().copied()),
        ),
    ]
}

fn transmission(s: &SceneSpectrum) -> Result<Vec<Column>, String> {
    let t = s.analysis.transmission.as_ref().map_err(Clone::clone)?;
    let rows = &t.scattering;
    Ok(vec![
        f64s("omega", rows.iter().map(|r| r.omega)),
        f64s("frequency", rows.iter().map(|r| s.frequency(r.omega))),
        f64s("transmittance", rows.iter().map(|r| r.transmittance())),
        f64s("reflectance", rows.iter().map(|r| r.reflectance())),
        f64s("absorbance", rows.iter().map(|r| r.absorbance())),
        f64s("phase", rows.iter().map(|r| r.phase())),
        f64s("log_transmission", rows.iter().map(|r| r.log_transmission)),
    ])
}

/// The JSON summary: the chain, the host cell's bands and gaps, the localised modes, and the
/// transmission's range and deepest point.
pub fn summary(s: &SceneSpectrum) -> Value {
    let a = &s.analysis;
    let intervals = |list: &[Interval]| -> Value {
        list.iter()
            .map(|i| json!([s.frequency(i.lower), s.frequency(i.upper)]))
            .collect()
    };
    let cell = &a.host.sites;
    json!({
        "units": if s.si { "SI" } else { "scaled" },
        "frequency_unit": s.frequency_unit(),
        "chain": {
            "sites": s.n_sites,
            "resonators": s.resonators,
            "detached_resonators": s.detached,
            "damped": s.damped,
        },
        "cell": match s.graded {
            true => json!({ "skipped": GRADED_CELL }),
            false => json!({
                "sites": [s.paper_site(cell.start), s.paper_site(cell.end - 1)],
                "periodic": a.host.periodic,
                "pass_bands": intervals(&a.pass_bands),
                "gaps": intervals(&a.gaps),
            }),
        },
        "modes": modes_summary(s),
        "transmission": transmission_summary(s),
        "measured": s.measured.as_ref().map(|m| json!({
            "probe": m.probe,
            "amplitude": m.amplitude,
            "points": m.omega.len(),
            "range": [
                m.omega.first().map(|&w| s.frequency(w)),
                m.omega.last().map(|&w| s.frequency(w)),
            ],
            "departure": m.departure(),
        })),
    })
}

fn modes_summary(s: &SceneSpectrum) -> Value {
    let m = &s.analysis.modes;
    let localised: Vec<Value> = m
        .undamped
        .iter()
        .filter(|mode| mode.in_any(&s.analysis.windows))
        .map(|mode| {
            json!({
                "frequency": s.frequency(mode.omega),
                "peak_site": s.paper_site(mode.localisation.peak_site),
                "localisation_length": mode.localisation.length,
            })
        })
        .collect();
    let damped = match &m.damped {
        None => Value::Null,
        Some(Err(reason)) => json!({ "skipped": reason }),
        Some(Ok(modes)) => json!({
            "count": modes.len(),
            "lowest_q": modes.iter().map(|d| d.q_factor()).fold(f64::INFINITY, f64::min),
        }),
    };
    json!({
        "count": m.undamped.len(),
        "complete": m.complete,
        "localised": localised,
        "damped": damped,
    })
}

fn transmission_summary(s: &SceneSpectrum) -> Value {
    let t = match &s.analysis.transmission {
        Err(reason) => return json!({ "skipped": reason }),
        Ok(t) => t,
    };
    let rows = &t.scattering;
    let deepest = rows
        .iter()
        .min_by(|a, b| a.log_transmission.total_cmp(&b.log_transmission));
    let lead = &t.scatterer.lead;
    json!({
        "lead_cutoff": s.frequency(lead.cutoff()),
        "region": [s.paper_site(t.scatterer.sites.start), s.paper_site(t.scatterer.sites.end - 1)],
        "points": rows.len(),
        "range": [
            rows.first().map(|r| s.frequency(r.omega)),
            rows.last().map(|r| s.frequency(r.omega)),
        ],
        "lowest_transmittance": deepest.map(|r| r.transmittance()),
        "lowest_at": deepest.map(|r| s.frequency(r.omega)),
    })
}
