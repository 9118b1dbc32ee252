//! From the raw file to a validated [`Scene`]: defaults, paper numbering, typed enums.
//!
//! One module per section of the file, each with the keys it owns: [`chain`] (`[chain]`,
//! `[[segment]]`), [`physical`] (`[physical]`, rods and materials), [`defects`]
//! (`[[defect]]`), [`excitation`] (`[impulse]`, `[striker]`) and [`run`] (`[run]`,
//! `[fractions]`, the budget). A new key goes into its section's module; [`resolve`] only
//! calls them in order.
//!
//! Paper numbering: sites n = -N..N with N = `chain.n` (or `chain.sites = [first, last]`); the
//! simulator's index is n - first, or n - first + 1 with a striker, which is index 0.

mod chain;
mod check;
mod damping;
mod defects;
mod excitation;
mod gravity;
mod physical;
mod run;
pub mod time;

use woodpile_sim::energy::Region;
use woodpile_sim::model::Model;
use woodpile_sim::simulation::Scenario;
use woodpile_sim::units::Scales;

use crate::raw;
use check::{invalid, Invalid};
use physical::Si;

pub use physical::DEFAULT_RESONATOR_SHARE;

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
    /// Other values derived from SI input (the regular rods' mass, contact and bending mode,
    /// the striker's mass and contact), by name, for the JSON's `physical` block.
    pub derived: Vec<(String, f64)>,
}

/// Dimensionless parameters derived for one defect of a physical scene. Serialised (field
/// names as keys) by `woodpile simulate` and in sweep manifests; a defect given by its rod
/// also lists what its bending mode gave.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct DerivedDefect {
    /// Paper site.
    pub site: i64,
    /// Host mass ratio M_defect / M.
    pub host_mass_ratio: f64,
    /// eps = m / M (M the regular site mass).
    pub eps: f64,
    /// kappa = K L^{p+1} / (M V^2).
    pub kappa: f64,
    /// A rod defect's host mass M in kg.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub host_mass_kg: Option<f64>,
    /// A rod defect's resonator mass m in kg.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resonator_mass_kg: Option<f64>,
    /// A rod defect's spring K = (2 pi f1)^2 M m / (M + m) in N/m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stiffness_n_per_m: Option<f64>,
    /// A rod defect's first free-free bending frequency f1 in Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bending_f1_hz: Option<f64>,
    /// A rod defect of its own diameter or material: its contacts' coefficient over the
    /// regular one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_ratio: Option<f64>,
}

/// The scene a file describes: its chain and sites (with their defects, segments and
/// excitation), then its run and fractions, then what an SI scene derived.
pub(crate) fn resolve(file: raw::SceneFile) -> Result<Scene, Invalid> {
    let chain_table = file.chain.as_ref();
    let (first, last) = chain::sites(chain_table)?;
    let si = physical::si(file.physical.as_ref(), file.striker.as_ref())?;
    let layout = chain::Layout {
        first,
        last,
        striker_sites: usize::from(file.striker.is_some()),
    };
    let built = model(&file, &layout, si.as_ref())?;
    // Named before `run` and `fractions` are taken from the file.
    let contact_dashpots = run::ContactDashpots::of(&file, &layout);
    let settings = run::settings(file.run, si.as_ref())?;
    let (region_paper, (lo, hi)) = run::region(file.fractions, &file.defect, &layout)?;
    let mut region = Region::new(lo as i64, hi as i64, layout.n_sites())
        .map_err(|e| invalid("fractions.region", e.to_string()))?;
    if file.striker.is_some() {
        region = region
            .with_striker()
            .map_err(|e| invalid("fractions.region", e.to_string()))?;
    }
    let scenario = Scenario {
        model: built.model,
        impulse_site: built.impulse.0,
        impulse_velocity: built.impulse.1,
        t_end: settings.t_end,
        region,
        method: settings.method,
        accuracy: settings.accuracy,
        sample_every: settings.sample_every,
    };
    let keys = run::StepKeys {
        defects: &file.defect,
        contact_dashpots,
    };
    run::within_budget(&scenario, settings.sample_every_given, &keys)?;
    let physical = si.map(|si| {
        let mut values = physical_values(si, built.derived, built.striker, &scenario);
        values.derived.extend(built.damping_values);
        values
    });
    Ok(Scene {
        scenario,
        first_site: layout.index_zero(),
        last_site: last,
        region_paper,
        physical,
    })
}

/// The chain a file builds, with where and how it is struck.
struct Built {
    model: Model,
    /// The struck site (the striker's, with one) and its velocity.
    impulse: (usize, f64),
    /// What each SI defect derived.
    derived: Vec<DerivedDefect>,
    /// A striker's mass and contact coefficient, over the regular ones.
    striker: Option<(f64, f64)>,
    /// An SI scene's dashpots and soft ends in the model's units, by name.
    damping_values: Vec<(String, f64)>,
}

/// An SI scene's soft ends, converted, for the JSON's `physical` block.
fn soft_end_values(boundary: woodpile_sim::Boundary, si: bool) -> Vec<(String, f64)> {
    let ends = [("left", boundary.left()), ("right", boundary.right())];
    ends.into_iter()
        .filter(|_| si)
        .filter_map(|(side, end)| end.soft().map(|soft| (side, soft)))
        .flat_map(|(side, (spring, damping))| {
            [
                (format!("boundary_{side}_spring"), spring),
                (format!("boundary_{side}_damping"), damping),
            ]
        })
        .collect()
}

/// The model of `file`'s chain: sites, defects, segments, the excitation and the contact law,
/// each section's keys resolved by its own module.
fn model(file: &raw::SceneFile, layout: &chain::Layout, si: Option<&Si>) -> Result<Built, Invalid> {
    let chain_table = file.chain.as_ref();
    let boundary = chain::boundary(chain_table, si)?;
    let mut sites = chain::Sites::regular(layout);
    let (resonators, derived) = defects::resonators(&file.defect, layout, si, &mut sites)?;
    chain::segments(&file.segment, layout, si, &mut sites)?;
    let impulse = match &file.striker {
        None => excitation::impulse(file.impulse.as_ref(), layout, si)?,
        Some(striker) => {
            excitation::striker(striker, file.impulse.is_some(), boundary, si, &mut sites)?
        }
    };
    // What each site carries down the chain: its own mass and its resonators'.
    let mut carried = sites.masses.clone();
    for r in &resonators {
        carried[r.site] += r.eps;
    }
    let law = chain::contact_law(
        chain_table,
        (boundary, file.striker.is_some()),
        si,
        &mut sites,
        &carried,
    )?;
    if law.as_ref().is_some_and(|l| l.gravity() > 0.0) {
        gravity::check_resonators(&resonators)?;
    }
    let striker = file
        .striker
        .as_ref()
        .map(|_| (sites.masses[0], sites.contacts[1]));
    let dissipation = damping::damping(file, &resonators, (&sites, layout), si)?;
    let model = Model::with_masses(layout.n_sites(), boundary, resonators, Some(sites.masses))
        .map_err(|e| invalid("defect", e.to_string()))?;
    let mut model = match law {
        None => model,
        Some(law) => model
            .with_contacts(law)
            .map_err(|e| invalid("chain", e.to_string()))?,
    };
    let mut damping_values = soft_end_values(boundary, si.is_some());
    if let Some((damping, listed)) = dissipation {
        model = model
            .with_damping(damping)
            .map_err(|e| invalid("damping", e.to_string()))?;
        damping_values.extend(listed);
    }
    no_ramp_with_losses(file, &model)?;
    Ok(Built {
        model,
        impulse,
        derived,
        striker,
        damping_values,
    })
}

/// Refuses a κ ramp in a chain that dissipates. A dissipative chain's shares are normalised by
/// E(0), with D for what the dashpots took, so that they sum to 1; a ramp does work on the
/// chain that this ledger has no term for, and the shares would sum to far more than 1.
fn no_ramp_with_losses(file: &raw::SceneFile, model: &Model) -> Result<(), Invalid> {
    if !(model.is_time_dependent() && model.is_dissipative()) {
        return Ok(());
    }
    let ramp = file
        .defect
        .iter()
        .position(|d| matches!(d.kappa, Some(toml::Value::Table(_))))
        .unwrap_or(0);
    let lossy = file
        .defect
        .iter()
        .position(|d| d.damping.is_some() || d.quality_factor.is_some());
    let losses = match (&file.damping, lossy) {
        (Some(_), _) => "damping".to_string(),
        (None, Some(j)) => match file.defect[j].damping {
            Some(_) => format!("defect[{j}].damping"),
            None => format!("defect[{j}].quality_factor"),
        },
        (None, None) => "chain.boundary".to_string(),
    };
    Err(invalid(
        format!("defect[{ramp}].kappa"),
        format!("a ramp cannot be combined with losses (`{losses}`): the ramp's work on the chain has no place in the energy ledger of a damped chain, whose shares would then not sum to 1; drop the ramp or the losses"),
    ))
}

/// What an SI scene reports under `physical`: its scales, its defects' derived values, and the
/// striker's and precompression's in the model's units.
fn physical_values(
    si: Si,
    defects: Vec<DerivedDefect>,
    striker: Option<(f64, f64)>,
    scenario: &Scenario,
) -> Physical {
    let mut values = si.derived;
    if let Some((mass, contact)) = striker {
        values.push(("striker_mass".into(), mass));
        values.push(("striker_contact".into(), contact));
    }
    if let Some(law) = scenario
        .model
        .contacts()
        .filter(|l| l.precompression() > 0.0)
    {
        values.push(("precompression".into(), law.precompression()));
    }
    if let Some(law) = scenario.model.contacts().filter(|l| l.gravity() > 0.0) {
        values.push(("gravity".into(), law.gravity()));
    }
    Physical {
        scales: si.scales,
        defects,
        derived: values,
    }
}
