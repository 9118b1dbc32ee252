//! Traces made by a known scene plus Gaussian noise: the known answers a calibration must
//! recover (the tests, and the coverage study of docs/calibration.md).

use woodpile_scene::Scene;

use crate::prediction::{predict, Stepping};
use crate::trace::Trace;

/// The velocities `scene` (run as written) gives `rods` every `spacing` seconds up to `end`,
/// with Gaussian noise of standard deviation `noise` times the largest |velocity| added,
/// drawn from `seed`. The trace's `sigma` is left out: the fit must estimate it.
pub fn noisy_trace(
    scene: &Scene,
    rods: &[i64],
    spacing: f64,
    end: f64,
    noise: f64,
    seed: u64,
) -> Result<Trace, String> {
    let samples = (end / spacing).round() as usize;
    let mut trace = Trace::default();
    for &rod in rods {
        for k in 1..=samples {
            trace.t.push(k as f64 * spacing);
            trace.rod.push(rod);
        }
    }
    trace.velocity = vec![0.0; trace.t.len()];
    let (clean, _) = predict(scene, &trace, Stepping::AsWritten)?;
    let peak = clean.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
    let mut normal = Normal::new(seed);
    trace.velocity = clean
        .iter()
        .map(|v| v + noise * peak * normal.next())
        .collect();
    Ok(trace)
}

/// Standard normal deviates: xorshift64* and Box–Muller, so that a seed means the same trace
/// on every machine without a random-number crate.
struct Normal {
    state: u64,
    spare: Option<f64>,
}

impl Normal {
    fn new(seed: u64) -> Normal {
        Normal {
            state: seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1,
            spare: None,
        }
    }

    fn uniform(&mut self) -> f64 {
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        let bits = self.state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        (bits as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn next(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u, v) = (self.uniform(), self.uniform());
        let r = (-2.0 * u.ln()).sqrt();
        let angle = std::f64::consts::TAU * v;
        self.spare = Some(r * angle.sin());
        r * angle.cos()
    }
}
