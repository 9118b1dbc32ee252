//! From the raw file to a validated [`Scene`]: defaults, paper numbering, typed enums.
//!
//! Paper numbering: sites n = -N..N with N = `chain.n` (or `chain.sites = [first, last]`); the
//! simulator's index is n - first.

use woodpile_sim::energy::Region;
use woodpile_sim::integrate::MAX_STEPS;
use woodpile_sim::integrate::{Accuracy, Method, MethodChoice};
use woodpile_sim::model::{Boundary, Coupling, Model, Resonator};
use woodpile_sim::run::Scenario;
use woodpile_sim::units::Scales;
use woodpile_sim::SimError;
use woodpile_sim::{OverBudget, StepSetBy};

use crate::raw;

/// The paper's defaults ("unless stated").
const DEFAULT_N: i64 = 100;
const DEFAULT_IMPULSE_SITE: i64 = -25;
const DEFAULT_T_END: f64 = 150.0;
const DEFAULT_TOLERANCE: f64 = 1e-8;
const DEFAULT_SAMPLE_EVERY: f64 = 1.0;
/// Smallest tolerance accepted: the fractions are sums of hundreds of energies, each known to
/// about 1e-16 relative, so a finer target could never be verified.
const MIN_TOLERANCE: f64 = 1e-13;
/// Longest chain accepted: far beyond any paper scene, small enough to never exhaust memory.
const MAX_N: i64 = 5_000_000;

/// A validated scene: the simulator's [`Scenario`] plus what the file said in paper terms.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// What to simulate.
    pub scenario: Scenario,
    /// The paper number of the first site (-N for a chain -N..N): paper site n is index
    /// n - first_site.
    pub first_site: i64,
    /// The paper number of the last site.
    pub last_site: i64,
    /// The region in paper numbering.
    pub region_paper: [i64; 2],
    /// SI scales and derived parameters, for physical scenes.
    pub physical: Option<Physical>,
}

impl Scene {
    /// The internal indices of the paper sites `lo..=hi`, or why they are not a range of the
    /// chain's sites.
    pub fn site_range(&self, lo: i64, hi: i64) -> Result<(usize, usize), String> {
        let (first, last) = (self.first_site, self.last_site);
        if lo > hi || lo < first || hi > last {
            return Err(format!(
                "need {first} <= lo <= hi <= {last} (the chain's paper sites)"
            ));
        }
        Ok(((lo - first) as usize, (hi - first) as usize))
    }
}

/// What a physical scene derived from its SI parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Physical {
    /// The rescaling.
    pub scales: Scales,
    /// Per defect: the dimensionless values derived from SI.
    pub defects: Vec<DerivedDefect>,
}

/// Dimensionless parameters derived for one defect of a physical scene. Serialised (field
/// names as keys) by `woodpile simulate` and in sweep manifests.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DerivedDefect {
    /// Paper site.
    pub site: i64,
    /// Host mass ratio M_defect / M.
    pub host_mass_ratio: f64,
    /// eps = m / M (M the regular site mass).
    pub eps: f64,
    /// kappa = K L^{p+1} / (M V^2).
    pub kappa: f64,
}

type Invalid = (String, String);

fn invalid(key: impl Into<String>, reason: impl Into<String>) -> Invalid {
    (key.into(), reason.into())
}

fn finite(key: &str, x: f64) -> Result<f64, Invalid> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be a finite number, got {x}")))
    }
}

fn positive(key: &str, x: f64) -> Result<f64, Invalid> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be finite and > 0, got {x}")))
    }
}

fn non_negative(key: &str, x: f64) -> Result<f64, Invalid> {
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be finite and >= 0, got {x}")))
    }
}

pub(crate) fn resolve(file: raw::SceneFile) -> Result<Scene, Invalid> {
    let chain = file.chain.unwrap_or(raw::Chain {
        n: None,
        sites: None,
        boundary: None,
    });
    let (first, last) = match (chain.n, chain.sites.as_deref()) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                "chain.sites",
                "give either chain.n (sites -n..n) or chain.sites = [first, last], not both",
            ))
        }
        (_, Some(&[first, last])) => {
            if first >= last || last.checked_sub(first).is_none_or(|w| w > 2 * MAX_N) {
                return Err(invalid(
                    "chain.sites",
                    format!("must be [first, last] with first < last and at most {} sites, got [{first}, {last}]", 2 * MAX_N + 1),
                ));
            }
            (first, last)
        }
        (_, Some(other)) => {
            return Err(invalid(
                "chain.sites",
                format!("must be [first, last], got {} values", other.len()),
            ))
        }
        (n, None) => {
            let n = n.unwrap_or(DEFAULT_N);
            if !(1..=MAX_N).contains(&n) {
                return Err(invalid(
                    "chain.n",
                    format!("must be an integer in 1..={MAX_N}, got {n}"),
                ));
            }
            (-n, n)
        }
    };
    let n_sites = (last - first + 1) as usize;
    let boundary = match chain.boundary.as_deref().unwrap_or("fixed") {
        "fixed" => Boundary::Fixed,
        "free" => Boundary::Free,
        other => {
            return Err(invalid(
                "chain.boundary",
                format!("must be \"fixed\" or \"free\", got \"{other}\""),
            ))
        }
    };
    let on_chain = |key: &str, site: i64| -> Result<usize, Invalid> {
        if (first..=last).contains(&site) {
            Ok((site - first) as usize)
        } else {
            Err(invalid(
                key,
                format!("site {site} is off the chain (sites run from {first} to {last})"),
            ))
        }
    };

    let scales = match &file.physical {
        Some(p) => Some(
            Scales::new(
                positive("physical.mass", p.mass)?,
                positive("physical.contact", p.contact)?,
                positive("physical.velocity", p.velocity)?,
            )
            .map_err(|e| invalid("physical", e.to_string()))?,
        ),
        None => None,
    };

    if file.defect.len() > n_sites.min(crate::MAX_DEFECTS) {
        return Err(invalid(
            "defect",
            format!(
                "{} defects on a chain of {n_sites} sites: at most one resonator per site, and at most {} in a scene",
                file.defect.len(),
                crate::MAX_DEFECTS
            ),
        ));
    }
    let mut resonators = Vec::with_capacity(file.defect.len());
    let mut masses = vec![1.0; n_sites];
    let mut derived = Vec::new();
    let mut taken = std::collections::HashMap::new();
    for (i, d) in file.defect.iter().enumerate() {
        let key = |k: &str| format!("defect[{i}].{k}");
        let site_paper = d.site.ok_or_else(|| invalid(key("site"), "is required"))?;
        let site = on_chain(&key("site"), site_paper)?;
        if let Some(first) = taken.insert(site_paper, i) {
            return Err(invalid(
                key("site"),
                format!(
                    "site {site_paper} already has defect[{first}]: at most one resonator per site"
                ),
            ));
        }
        let p = d.p.unwrap_or(1);
        if !(p == 1 || (p >= 3 && p % 2 == 1 && p <= 99)) {
            return Err(invalid(
                key("p"),
                format!("must be 1 or an odd integer from 3 to 99, got {p}"),
            ));
        }
        let p = p as u32;
        let (eps, coupling) = match scales {
            None => {
                reject_present(
                    &key,
                    &[
                        ("mass", d.mass.is_some()),
                        ("resonator_mass", d.resonator_mass.is_some()),
                        ("stiffness", d.stiffness.is_some()),
                    ],
                    "is only allowed in a scene with a [physical] table",
                )?;
                let eps = positive(
                    &key("eps"),
                    d.eps.ok_or_else(|| invalid(key("eps"), "is required"))?,
                )?;
                let coupling = match &d.kappa {
                    None => Coupling::Constant(1.0),
                    Some(v) => coupling(&key("kappa"), v)?,
                };
                (eps, coupling)
            }
            Some(sc) => {
                reject_present(
                    &key,
                    &[("eps", d.eps.is_some()), ("kappa", d.kappa.is_some())],
                    "is derived in a [physical] scene: give resonator_mass (kg) and stiffness (N/m^p) instead",
                )?;
                let m = positive(
                    &key("resonator_mass"),
                    d.resonator_mass.ok_or_else(|| {
                        invalid(key("resonator_mass"), "is required in a [physical] scene")
                    })?,
                )?;
                let k = non_negative(
                    &key("stiffness"),
                    d.stiffness.ok_or_else(|| {
                        invalid(key("stiffness"), "is required in a [physical] scene")
                    })?,
                )?;
                let host = positive(&key("mass"), d.mass.unwrap_or(sc.mass_kg))?;
                masses[site] = sc.mass_ratio(host);
                let (eps, kappa) = (sc.mass_ratio(m), sc.kappa(k, p));
                derived.push(DerivedDefect {
                    site: site_paper,
                    host_mass_ratio: masses[site],
                    eps,
                    kappa,
                });
                (eps, Coupling::Constant(kappa))
            }
        };
        resonators.push(Resonator {
            site,
            eps,
            coupling,
            p,
        });
    }
    let model = Model::with_masses(n_sites, boundary, resonators, Some(masses))
        .map_err(|e| invalid("defect", e.to_string()))?;

    let impulse = file.impulse.unwrap_or(raw::Impulse {
        site: None,
        velocity: None,
    });
    let impulse_site = on_chain("impulse.site", impulse.site.unwrap_or(DEFAULT_IMPULSE_SITE))?;
    let impulse_velocity = match (impulse.velocity, scales) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                "impulse.velocity",
                "is physical.velocity in a [physical] scene",
            ));
        }
        (Some(0.0), None) => {
            return Err(invalid(
                "impulse.velocity",
                "is 0: no wave enters the chain, so there is no energy to split and the fractions are undefined",
            ));
        }
        (Some(v), None) => finite("impulse.velocity", v)?,
        (None, _) => 1.0,
    };

    let run = file.run.unwrap_or(raw::Run {
        t_end: None,
        method: None,
        tolerance: None,
        dt: None,
        sample_every: None,
    });
    let t_end = positive("run.t_end", run.t_end.unwrap_or(DEFAULT_T_END))?;
    let method = match run.method.as_deref().unwrap_or("auto") {
        "auto" => MethodChoice::Auto,
        name => MethodChoice::Named(Method::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
            invalid(
                "run.method",
                format!(
                    "unknown method \"{name}\"; expected \"auto\" or one of {}",
                    names.join(", ")
                ),
            )
        })?),
    };
    let tolerance = positive("run.tolerance", run.tolerance.unwrap_or(DEFAULT_TOLERANCE))?;
    if tolerance < MIN_TOLERANCE {
        return Err(invalid(
            "run.tolerance",
            format!("{tolerance:e} is below {MIN_TOLERANCE:e}: fractions summed over a chain in double precision cannot be verified that closely"),
        ));
    }
    let dt = run.dt.map(|dt| positive("run.dt", dt)).transpose()?;
    if let Some(dt) = dt {
        match method {
            MethodChoice::Auto => {
                return Err(invalid(
                    "run.dt",
                    "needs a fixed-step method; \"auto\" chooses its own step from run.tolerance",
                ))
            }
            MethodChoice::Named(m) if m.is_adaptive() => {
                return Err(invalid(
                    "run.dt",
                    format!(
                        "method \"{}\" is adaptive and takes run.tolerance, not dt",
                        m.name()
                    ),
                ))
            }
            _ if dt > t_end => {
                return Err(invalid(
                    "run.dt",
                    format!("{dt} is longer than run.t_end = {t_end}"),
                ))
            }
            _ => {}
        }
    }
    let sample_every = positive(
        "run.sample_every",
        run.sample_every.unwrap_or(DEFAULT_SAMPLE_EVERY),
    )?;

    let region_paper = match file.fractions.and_then(|f| f.region) {
        Some(r) => {
            let [lo, hi] = r[..] else {
                return Err(invalid(
                    "fractions.region",
                    format!("must be [lo, hi], got {} values", r.len()),
                ));
            };
            if lo > hi {
                return Err(invalid(
                    "fractions.region",
                    format!("lo = {lo} is greater than hi = {hi}"),
                ));
            }
            [lo, hi]
        }
        None => default_region(&file.defect),
    };
    let lo = on_chain("fractions.region", region_paper[0])?;
    let hi = on_chain("fractions.region", region_paper[1])?;
    let region = Region::new(lo as i64, hi as i64, n_sites)
        .map_err(|e| invalid("fractions.region", e.to_string()))?;

    let scenario = Scenario {
        model,
        impulse_site,
        impulse_velocity,
        t_end,
        region,
        method,
        accuracy: Accuracy {
            tolerance,
            tolerance_explicit: run.tolerance.is_some(),
            dt,
        },
        sample_every,
    };
    within_budget(&scenario, run.sample_every.is_some())?;
    let physical = scales.map(|scales| Physical {
        scales,
        defects: derived,
    });
    Ok(Scene {
        scenario,
        first_site: first,
        last_site: last,
        region_paper,
        physical,
    })
}

/// Refuses a scene whose run could never finish within the simulator's budgets, naming the key
/// that makes it so (`t_end` when even the largest step of any method would be too many).
fn within_budget(scenario: &Scenario, sample_every_given: bool) -> Result<(), Invalid> {
    let error = match woodpile_sim::run::budget::check(scenario) {
        Ok(()) => return Ok(()),
        Err(SimError::OverBudget(over)) => over,
        Err(other) => return Err(invalid("run", other.to_string())),
    };
    let longest_step = 0.25;
    let key = match &error {
        OverBudget::Samples { .. } if sample_every_given => "run.sample_every".to_string(),
        OverBudget::Samples { .. } => "run.t_end".to_string(),
        OverBudget::Steps { .. } if scenario.t_end / longest_step > MAX_STEPS as f64 => {
            "run.t_end".to_string()
        }
        OverBudget::Steps { set_by, .. } => match set_by {
            StepSetBy::Dt => "run.dt".to_string(),
            StepSetBy::Tolerance => "run.tolerance".to_string(),
            StepSetBy::Resonator(i) => format!("defect[{i}]"),
        },
    };
    Err(invalid(key, error.to_string()))
}

/// Rejects the first of `keys` that is present: those keys do not belong in this kind of scene.
fn reject_present(
    key: &dyn Fn(&str) -> String,
    keys: &[(&str, bool)],
    reason: &str,
) -> Result<(), Invalid> {
    match keys.iter().find(|(_, present)| *present) {
        Some((name, _)) => Err(invalid(key(name), reason)),
        None => Ok(()),
    }
}

/// The paper's region (Eqs. 10 and 11) spans the defects and one neighbour on each side, [min - 1, max + 1]
/// (adjacent defects 0..L give [-1, L + 1]; separated d1 < d2 give [d1 - 1, d2 + 1]). Without
/// defects, the single-defect region [-1, 1].
fn default_region(defects: &[raw::Defect]) -> [i64; 2] {
    let sites = defects.iter().filter_map(|d| d.site);
    let lo = sites.clone().min().unwrap_or(0);
    let hi = sites.max().unwrap_or(0);
    [lo - 1, hi + 1]
}

fn coupling(key: &str, value: &toml::Value) -> Result<Coupling, Invalid> {
    let number = |k: &str, v: &toml::Value| -> Result<f64, Invalid> {
        match v {
            toml::Value::Float(x) => Ok(*x),
            toml::Value::Integer(i) => Ok(*i as f64),
            other => Err(invalid(
                k,
                format!("must be a number, got {}", other.type_str()),
            )),
        }
    };
    match value {
        toml::Value::Table(t) => {
            for k in t.keys() {
                if !["k1", "k2", "t0", "tau"].contains(&k.as_str()) {
                    return Err(invalid(
                        format!("{key}.{k}"),
                        "unknown key; a ramp has k1, k2, t0, tau",
                    ));
                }
            }
            let get = |k: &str| -> Result<f64, Invalid> {
                let full = format!("{key}.{k}");
                let v = t
                    .get(k)
                    .ok_or_else(|| invalid(&full, "is required in a ramp { k1, k2, t0, tau }"))?;
                number(&full, v)
            };
            Ok(Coupling::Ramp {
                k1: non_negative(&format!("{key}.k1"), get("k1")?)?,
                k2: non_negative(&format!("{key}.k2"), get("k2")?)?,
                t0: finite(&format!("{key}.t0"), get("t0")?)?,
                tau: positive(&format!("{key}.tau"), get("tau")?)?,
            })
        }
        v => Ok(Coupling::Constant(non_negative(key, number(key, v)?)?)),
    }
}
