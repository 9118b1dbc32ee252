//! The known-answer case the tests and the coverage study share: a 20-rod chain in SI with a
//! Hertzian contact dashpot γ and one defect rod of quality factor Q, struck at its first rod,
//! traced at three rods every 2 µs for 0.3 ms with 5% noise.

use woodpile_scene::Scene;

use crate::keys::Parameter;
use crate::synthetic::noisy_trace;
use crate::trace::Trace;

/// The true γ, N·s/m^{3/2} (the Hertzian dashpot, γ √c ċ).
pub const GAMMA: f64 = 1800.0;
/// The true Q.
pub const Q: f64 = 30.0;

/// The true scene.
pub const SCENE: &str = r#"
[chain]
sites = [-10, 9]
boundary = "free"
[impulse]
site = -10
[physical]
contact = 2.47e9
mass = 0.866e-3
velocity = 1.0
[[defect]]
site = 0
mass = 0.838e-3
resonator_mass = 0.894e-3
stiffness = 3.961e6
quality_factor = 30.0
[damping]
contact = 1800.0
law = "hertzian"
[run]
t_end = "1 ms"
tolerance = 1e-6
"#;

/// γ and Q, with boxes a lab would give and starts well off the truth.
pub fn parameters() -> Vec<Parameter> {
    vec![
        Parameter {
            key: "damping.contact".into(),
            min: 100.0,
            max: 20000.0,
            start: Some(3000.0),
        },
        Parameter {
            key: "defect[0].quality_factor".into(),
            min: 2.0,
            max: 500.0,
            start: Some(80.0),
        },
    ]
}

/// The true scene's trace at rods −5, 1 and 8 with 5% noise from `seed`.
pub fn trace(truth: &Scene, seed: u64) -> Trace {
    match noisy_trace(truth, &[-5, 0, 8], 2e-6, 1e-3, 0.05, seed) {
        Ok(trace) => trace,
        Err(reason) => panic!("the known scene's trace: {reason}"),
    }
}
