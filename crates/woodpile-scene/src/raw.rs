//! The scene file exactly as written: every key optional where the contract gives a default,
//! unknown keys rejected by serde with the offending key and line.

use serde::Deserialize;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SceneFile {
    pub chain: Option<Chain>,
    pub impulse: Option<Impulse>,
    #[serde(default)]
    pub defect: Vec<Defect>,
    pub run: Option<Run>,
    pub fractions: Option<FractionsTable>,
    pub physical: Option<Physical>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Chain {
    pub n: Option<i64>,
    /// `[first, last]` paper sites: an asymmetric chain (the woodpile experiment's 40 rods),
    /// instead of `n`.
    pub sites: Option<Vec<i64>>,
    pub boundary: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Impulse {
    pub site: Option<i64>,
    pub velocity: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Defect {
    pub site: Option<i64>,
    pub eps: Option<f64>,
    /// `kappa = 2.5` or `kappa = { k1 = 0.0, k2 = 2.5, t0 = 40.0, tau = 0.1 }`, read by hand so
    /// that a malformed ramp gets a precise message.
    pub kappa: Option<toml::Value>,
    pub p: Option<i64>,
    /// Physical scenes: primary (host) mass of the defect site in kg.
    pub mass: Option<f64>,
    /// Physical scenes: resonator mass m in kg.
    pub resonator_mass: Option<f64>,
    /// Physical scenes: spring constant K in N/m^p.
    pub stiffness: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Run {
    pub t_end: Option<f64>,
    pub method: Option<String>,
    pub tolerance: Option<f64>,
    pub dt: Option<f64>,
    pub sample_every: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct FractionsTable {
    pub region: Option<Vec<i64>>,
}

/// Optional SI description (paper Eq. 1): the defects then give masses and stiffnesses.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Physical {
    /// Hertz contact constant a in N/m^{3/2}.
    pub contact: f64,
    /// Mass M of a regular site in kg (the reference mass).
    pub mass: f64,
    /// Impact velocity V in m/s.
    pub velocity: f64,
}
