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
    #[serde(default)]
    pub segment: Vec<Segment>,
    pub striker: Option<Striker>,
    pub damping: Option<DampingTable>,
}

/// `[damping]`: contact dashpots and ground damping.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DampingTable {
    /// γ of every contact.
    pub contact: Option<f64>,
    /// `"linear"` or `"hertzian"`.
    pub law: Option<String>,
    /// g, on every site.
    pub ground: Option<f64>,
    /// Instead of `contact`: the restitution an isolated pair of regular sites shows.
    pub restitution: Option<Restitution>,
}

/// `restitution = { e = 0.9, velocity = 1.0 }`: the coefficient of restitution of two regular
/// sites meeting at `velocity` (m/s, or text such as "1 m/s", in a `[physical]` scene).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Restitution {
    pub e: Option<f64>,
    pub velocity: Option<toml::Value>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Chain {
    pub n: Option<i64>,
    /// `[first, last]` paper sites: an asymmetric chain (the woodpile experiment's 40 rods),
    /// instead of `n`.
    pub sites: Option<Vec<i64>>,
    /// `"fixed"`, `"free"` or `{ left = .., right = .. }`, read by hand for precise messages.
    pub boundary: Option<toml::Value>,
    /// The exponent alpha of every contact.
    pub exponent: Option<f64>,
    /// The static force F0 held by the walls.
    pub precompression: Option<f64>,
    /// The coefficient a of the two wall contacts.
    pub wall_contact: Option<f64>,
    /// g: the chain stands upright, its first site on top.
    pub gravity: Option<f64>,
}

/// Site properties over a range of paper sites.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Segment {
    pub sites: Option<Vec<i64>>,
    /// A number, or a list repeated from the segment's first site.
    pub mass: Option<toml::Value>,
    /// A number, or a list repeated from the segment's first contact.
    pub contact: Option<toml::Value>,
    /// γ of the contacts between its sites, instead of `[damping] contact`.
    pub damping: Option<f64>,
    /// Or γ calibrated so that the segment's first two sites part with this e.
    pub restitution: Option<Restitution>,
}

/// A body that strikes the first site, instead of `[impulse]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Striker {
    pub mass: Option<f64>,
    pub velocity: Option<f64>,
    pub contact: Option<f64>,
    /// SI scenes: a sphere whose Hertz coefficient against the first rod is derived.
    pub sphere: Option<Sphere>,
    /// γ of its contact with the first site, instead of `[damping] contact`.
    pub damping: Option<f64>,
    /// Or γ calibrated so that it and the first site part with this e.
    pub restitution: Option<Restitution>,
}

/// A spherical striker of an SI scene.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Sphere {
    pub diameter: Option<f64>,
    pub material: Option<Material>,
}

/// An elastic material in SI units.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Material {
    pub youngs_modulus: Option<f64>,
    pub poisson_ratio: Option<f64>,
    pub density: Option<f64>,
}

/// A rod's geometry in metres.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Rod {
    pub length: Option<f64>,
    pub diameter: Option<f64>,
}

/// A defect rod of an SI scene: its length, and optionally its own diameter and material.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DefectRod {
    pub length: Option<f64>,
    pub diameter: Option<f64>,
    pub material: Option<Material>,
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
    /// Physical scenes: the defect rod's geometry, instead of mass, resonator_mass, stiffness.
    pub rod: Option<DefectRod>,
    /// Physical scenes with `rod`: the share of the rod's mass carried by the resonator.
    pub resonator_share: Option<f64>,
    /// The resonator's dashpot c_j (N·s/m in SI scenes).
    pub damping: Option<f64>,
    /// The resonator's quality factor Q, instead of `damping`: c_j = μ ω / Q.
    pub quality_factor: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Run {
    pub t_end: Option<Time>,
    pub method: Option<String>,
    pub tolerance: Option<f64>,
    pub dt: Option<Time>,
    pub sample_every: Option<Time>,
}

/// A time: a number in the model's scaled time, or (in a `[physical]` scene) text with a unit,
/// `"1.5 ms"`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Time {
    /// Scaled time, as every scene has always written it.
    Scaled(f64),
    /// Seconds with a unit.
    Text(String),
}

impl<'de> Deserialize<'de> for Time {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Time, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = Time;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a number (scaled time) or, in a [physical] scene, a time with a unit such as \"1.5 ms\"")
            }
            fn visit_f64<E>(self, x: f64) -> Result<Time, E> {
                Ok(Time::Scaled(x))
            }
            fn visit_i64<E>(self, x: i64) -> Result<Time, E> {
                Ok(Time::Scaled(x as f64))
            }
            fn visit_u64<E>(self, x: u64) -> Result<Time, E> {
                Ok(Time::Scaled(x as f64))
            }
            fn visit_str<E>(self, text: &str) -> Result<Time, E> {
                Ok(Time::Text(text.to_string()))
            }
        }
        deserializer.deserialize_any(Visitor)
    }
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
    pub contact: Option<f64>,
    /// Mass M of a regular site in kg (the reference mass).
    pub mass: Option<f64>,
    /// Impact velocity V in m/s (a striker's velocity instead, when there is one).
    pub velocity: Option<f64>,
    /// The regular rods' material, with `rod`, instead of `contact` and `mass`.
    pub material: Option<Material>,
    /// The regular rods' geometry.
    pub rod: Option<Rod>,
}
