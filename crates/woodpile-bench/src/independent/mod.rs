//! A reference for any chain that shares no force code with the simulator: the first-order
//! system `[x, v, D]` written afresh ([`chain`]) and integrated by DOP853 with every contact
//! switch located ([`stepper`]). The damped audit (`auto_audit --damped`) compares `auto`
//! against it; the simulator's own `rk4-contact`, which the audit used before, checked the
//! damped force code with itself.
//!
//! What it shares with the simulator: the scene ([`Scenario`], read through
//! [`woodpile_sim::model::Model::parts`]), DOP853's coefficients, and the split of a
//! per-site energy into shares ([`Fractions`]). What it does not: forces, dashpots and their
//! clip, powers, potentials, event handling, and the step.

pub mod chain;
pub mod stepper;

use chain::Chain;
use stepper::{Counts, Stepper};
use woodpile_sim::energy::Fractions;
use woodpile_sim::simulation::Scenario;

/// The reference's answer for one scene at one tolerance.
#[derive(Debug, Clone)]
pub struct Reference {
    /// R, T, E_tr, S and D at t_end; each normalised by E(0) on a dissipative chain.
    pub fractions: Fractions,
    /// |E(t_end) + D(t_end) − E(0)| / E(0): the ledger, which a constant-coupling scene must
    /// keep.
    pub ledger_drift: f64,
    /// The state at t_end, `[x, v, D]`.
    pub state: Vec<f64>,
    /// What the integration took.
    pub counts: Counts,
}

/// `scene` integrated to its `t_end` at relative and absolute tolerance `rtol`.
pub fn reference(scene: &Scenario, rtol: f64) -> Result<Reference, String> {
    let chain = Chain::of(&scene.model)?;
    let mut y = vec![0.0; chain.state_len()];
    y[chain.dof() + scene.impulse_site] = scene.impulse_velocity;
    let e_initial: f64 = chain.density(0.0, &y).iter().sum();
    let counts = Stepper::new(&chain, rtol).run(&mut y, scene.t_end)?;
    let density = chain.density(scene.t_end, &y);
    let dissipated = y[2 * chain.dof()];
    let held: f64 = density.iter().sum();
    let fractions = match scene.model.is_dissipative() {
        true => Fractions::of_ledger(&density, scene.region, dissipated, e_initial),
        false => Fractions::from_density(&density, scene.region),
    };
    if !fractions.sum().is_finite() {
        return Err("the reference's shares are not finite".into());
    }
    Ok(Reference {
        fractions,
        ledger_drift: ((held + dissipated - e_initial) / e_initial).abs(),
        state: y,
        counts,
    })
}
