//! The nonlinear run against the linear picture: at a small impulse they agree to 1e-3 in |t|
//! over the frequencies the run resolves; as the impulse grows they part.

use std::path::Path;

use super::*;
use crate::scene::{scene_spectrum, SceneRequest};

/// A precompressed chain -400..400 (F0 = 1, so δ0 = 1 and c0 = sqrt(3/2)) with one linear
/// resonator at site 0, struck at -30 with `velocity`, and run until just before an echo.
fn scene(velocity: f64, method: &str) -> Scene {
    let text = format!(
        r#"
[chain]
n = 400
precompression = 1.0
[[defect]]
site = 0
eps = 0.5
kappa = 0.3
[impulse]
site = -30
velocity = {velocity}
[run]
t_end = 600.0
sample_every = 0.1
{method}
"#
    );
    woodpile_scene::parse(&text, Path::new("measured.toml")).unwrap()
}

fn departure(velocity: f64) -> (Measured, f64) {
    let scene = scene(velocity, "method = \"rkn6-contact\"\ndt = 0.02");
    let spectrum = scene_spectrum(&scene, &SceneRequest::default()).unwrap();
    let measured = measure(&scene, &spectrum, None, &|| false).unwrap();
    let d = measured.departure();
    (measured, d)
}

#[test]
fn a_small_impulse_transmits_as_the_linear_chain_does() {
    let (measured, d) = departure(1e-4);
    assert_eq!(measured.probe, 30);
    assert!(measured.amplitude < 1e-3, "{}", measured.amplitude);
    // Most of the band arrives within the window.
    assert!(measured.omega.len() > 300, "{}", measured.omega.len());
    assert!(d < 1e-3, "|t| differs by {d}");
}

#[test]
fn a_strong_impulse_parts_from_the_linear_chain() {
    let (_, d) = departure(0.3);
    assert!(d > 1e-2, "|t| differs by only {d}");
}

#[test]
fn a_window_that_lets_an_echo_in_is_refused() {
    let text = "[chain]\nn = 60\nprecompression = 1.0\n[[defect]]\nsite = 0\neps = 0.5\n[impulse]\nsite = -30\nvelocity = 1e-4\n[run]\nt_end = 600.0\nsample_every = 0.1\n";
    let scene = woodpile_scene::parse(text, Path::new("short.toml")).unwrap();
    let spectrum = scene_spectrum(&scene, &SceneRequest::default()).unwrap();
    let refusal = measure(&scene, &spectrum, None, &|| false).unwrap_err();
    assert_eq!(refusal.asked, Asked::Window);
    let sparse = text.replace("sample_every = 0.1", "sample_every = 2.0");
    let scene = woodpile_scene::parse(&sparse, Path::new("sparse.toml")).unwrap();
    let refusal = measure(&scene, &spectrum, None, &|| false).unwrap_err();
    assert_eq!(refusal.asked, Asked::Sampling);
    let refusal = measure(&scene, &spectrum, Some(-5), &|| false).unwrap_err();
    assert_eq!(refusal.asked, Asked::Probe);
}
