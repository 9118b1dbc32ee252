//! The CPU choices a user makes in the environment, read once by the edges (the command line,
//! the Python module, the bench) and handed to the simulator, which reads no environment:
//! `WOODPILE_SIMD=baseline` or `avx2` caps the copy of the hot loops taken
//! ([`woodpile_sim::simd::cap`]), and `WOODPILE_LANES=off` runs every scene alone
//! ([`woodpile_sim::integrate::lanes::turn_off`]). Both give the same numbers: they exist so
//! that every path can be run, compared and timed on one machine.

/// Hands `WOODPILE_SIMD` and `WOODPILE_LANES` to the simulator. Call it before the first run.
pub fn apply_environment() {
    apply(
        std::env::var("WOODPILE_SIMD").ok().as_deref(),
        std::env::var("WOODPILE_LANES").ok().as_deref(),
    );
}

/// Hands the values of `WOODPILE_SIMD` and `WOODPILE_LANES` (each `None` when unset) to the
/// simulator.
pub fn apply(simd: Option<&str>, lanes: Option<&str>) {
    if let Some(tier) = simd.and_then(woodpile_sim::simd::Tier::cap_named) {
        woodpile_sim::simd::cap(tier);
    }
    if lanes == Some("off") {
        woodpile_sim::integrate::lanes::turn_off();
    }
}
