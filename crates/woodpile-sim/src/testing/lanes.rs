//! Scenes for the SIMD lanes' checks (`tests/lanes.rs`, the `lanes_audit` example): a sweep's
//! neighbouring points around a scene, and each run by lanes and alone.

use crate::error::SimError;
use crate::model::{Model, Resonator};
use crate::observe::FractionSeries;
use crate::simulation::{simulate, Scenario};

/// Eight F7 fine points (ε1, ε2; defects at 0 and 20, tolerance 1e-5) in two groups of four,
/// the five at 0, 2, 4, 6 and 7 needing a third run: ladders that wait for a later rung
/// together, across groups.
pub const THIRD_RUN_POINTS: [(f64, f64); 8] = [
    (0.59, 0.96),
    (0.29, 0.64),
    (0.79, 0.92),
    (0.36, 0.46),
    (0.57, 0.30),
    (1.0, 0.42),
    (0.82, 0.95),
    (0.57, 0.61),
];

/// Four neighbouring points of a sweep around `base`, as a sweep hands them to the SIMD lanes
/// (`crate::simulation::simulate_batch`): the impulse's site two apart from point to point
/// (so that on a chain of alternating masses the struck sites have the same mass, and the
/// impact the same energy); for `k % 4 == 3` the last point's resonators also a thousandth
/// lighter, which may change its first step and keep the group out of lanes.
pub fn lane_neighbours(base: &Scenario, k: usize) -> Vec<Scenario> {
    let last = base.model.n_sites() - 1;
    let mut scenes: Vec<Scenario> = (0..crate::integrate::lanes::LANES)
        .map(|j| Scenario {
            impulse_site: (base.impulse_site + 2 * j).min(last),
            ..base.clone()
        })
        .collect();
    if k % 4 == 3 {
        let lighter = with_resonator_masses_scaled(&scenes[3], 0.999);
        scenes[3] = lighter;
    }
    scenes
}

/// `base` with its resonators' masses scaled by `factor`: a neighbouring point of a sweep
/// over them, on the same chain.
pub fn with_resonator_masses_scaled(base: &Scenario, factor: f64) -> Scenario {
    let m = &base.model;
    let resonators = m
        .resonators()
        .iter()
        .map(|r| Resonator {
            eps: r.eps * factor,
            ..*r
        })
        .collect();
    let masses = (0..m.n_sites()).map(|i| m.site_mass(i)).collect();
    let mut model = Model::with_masses(m.n_sites(), m.boundary(), resonators, Some(masses))
        .and_then(|model| model.with_law(m.law().clone()))
        .expect("the base's chain, valid");
    if let Some(damping) = m.damping() {
        model = model
            .with_damping(damping.clone())
            .expect("the base's damping, valid");
    }
    Scenario {
        model,
        ..base.clone()
    }
}

/// One scene's run, as an outcome (or the error that stopped it) and its recorded samples.
pub type RecordedRun = (Result<crate::simulation::Outcome, SimError>, FractionSeries);

/// Each of `scenes` run by `simulate_batch` (four neighbours at a time in SIMD lanes where
/// they can) and by `simulate` alone, with every sample recorded: pairs that must be equal.
pub fn by_lanes_and_alone(scenes: &[Scenario]) -> Vec<(RecordedRun, RecordedRun)> {
    let refs: Vec<&Scenario> = scenes.iter().collect();
    let mut series: Vec<FractionSeries> = scenes
        .iter()
        .map(|s| FractionSeries::new(&s.model, s.region))
        .collect();
    let batched = crate::simulation::simulate_batch(&refs, &mut series);
    batched
        .into_iter()
        .zip(series)
        .zip(scenes)
        .map(|(lanes, s)| {
            let mut alone = FractionSeries::new(&s.model, s.region);
            let outcome = simulate(s, &mut alone);
            (lanes, (outcome, alone))
        })
        .collect()
}
