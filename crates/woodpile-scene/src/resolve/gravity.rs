//! `chain.gravity`: the chain stands upright in gravity g (m/s² in an SI scene, the model's
//! units otherwise), its first site on top and its last resting on the right end's support.
//! Each contact then carries the weight of every body above it (sites, their resonators, a
//! striker), which fixes its static overlap; the motion is about that rest state, and the
//! weights enter as the contacts' static forces (`woodpile_sim::ContactLaw::under_gravity`).

use woodpile_sim::model::Coupling;
use woodpile_sim::model::{Boundary, End, Resonator};

use super::check::{invalid, non_negative, Invalid};
use super::physical::Si;
use crate::raw;

/// g in the model's units, or `None` without gravity (absent or 0); refused where the chain
/// cannot stand: a top end that is not free, no support at the bottom, or a precompression.
pub(crate) fn gravity(
    chain: Option<&raw::Chain>,
    boundary: Boundary,
    si: Option<&Si>,
) -> Result<Option<f64>, Invalid> {
    let Some(g) = chain.and_then(|c| c.gravity) else {
        return Ok(None);
    };
    let g = non_negative("chain.gravity", g)?;
    if g == 0.0 {
        return Ok(None);
    }
    if !matches!(boundary.left(), End::Free) {
        return Err(invalid(
            "chain.gravity",
            "the chain stands on its right end with its first site on top: the left (top) end must be free (chain.boundary = { left = \"free\", right = \"fixed\" })",
        ));
    }
    if matches!(boundary.right(), End::Free) {
        return Err(invalid(
            "chain.gravity",
            "has no support to rest on: the right (bottom) end must be fixed or soft",
        ));
    }
    if chain
        .and_then(|c| c.precompression)
        .is_some_and(|f0| f0 > 0.0)
    {
        return Err(invalid(
            "chain.gravity",
            "and chain.precompression both load the chain statically: give one",
        ));
    }
    // An acceleration's scale is L / T².
    Ok(Some(si.map_or(g, |si| {
        g * si.scales.time_s().powi(2) / si.scales.length_m()
    })))
}

/// Refuses resonators whose rest state gravity would move: a nonlinear coupling (its static
/// stretch has no linear part to stand on) or a ramp (its rest state changes as it runs).
pub(crate) fn check_resonators(resonators: &[Resonator]) -> Result<(), Invalid> {
    for (j, r) in resonators.iter().enumerate() {
        if r.p != 1 || !matches!(r.coupling, Coupling::Constant(_)) {
            return Err(invalid(
                format!("defect[{j}]"),
                "in gravity a resonator hangs on its host: it needs a linear coupling (p = 1) with a constant kappa",
            ));
        }
    }
    Ok(())
}
