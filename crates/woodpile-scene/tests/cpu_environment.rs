//! The edges hand the simulator the environment's CPU choices (`woodpile_scene::cpu`): a cap
//! of the SIMD tier and lanes off. Its own test binary, since both are decided once per process.
#![allow(clippy::unwrap_used)]

use woodpile_sim::integrate::lanes;
use woodpile_sim::simd::{self, Tier};

#[test]
fn the_environments_cpu_choices_reach_the_simulator() {
    assert!(lanes::enabled());
    woodpile_scene::cpu::apply(Some("baseline"), Some("off"));
    assert_eq!(simd::tier(), Tier::Baseline);
    assert!(!lanes::enabled());
    // The cap is decided once: a later one changes nothing.
    simd::cap(Tier::Avx512);
    assert_eq!(simd::tier(), Tier::Baseline);
    assert_eq!(Tier::cap_named("avx2"), Some(Tier::Avx2));
    assert_eq!(Tier::cap_named("fast"), None);
}
