//! What the scene crate's tests share.
#![allow(dead_code, clippy::unwrap_used)]

use std::path::Path;

use woodpile_scene::{parse, Scene, SceneError};
use woodpile_sim::observe::SiteField;
use woodpile_sim::simulation::simulate;

/// The scene `toml` (named `test.toml` in messages), which must resolve.
pub fn scene(toml: &str) -> Scene {
    parse(toml, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// The restitution two bodies part with, the first two of `scene`'s chain (internal sites 0
/// and 1, a striker and the first rod where there is one) after the first struck at `v`:
/// (v1 − v0) / v from their velocities at the end of the run.
pub fn parting_restitution(scene: &Scene, v: f64) -> f64 {
    let mut field = SiteField::new(&scene.scenario.model, 0, 1);
    simulate(&scene.scenario, &mut field).unwrap();
    let last = field.t.len() - 1;
    let (v0, v1) = (field.velocity[2 * last], field.velocity[2 * last + 1]);
    (v1 - v0) / v
}

/// The `[run]` table of a two-body collision at `v` simulated past its parting: `rk4-contact`
/// at a step fine enough for e to 1e-6, to t_end = `lasting` · v^{-1/5} (the elastic contact
/// lasts about 3 c_max / v with c_max ~ v^{4/5}), sampled at its end only.
pub fn collision_run(v: f64, lasting: f64) -> String {
    let t_end = lasting * v.powf(-0.2);
    let dt = 1e-4 * v.powf(-0.2);
    format!("[run]\nt_end = {t_end:?}\nmethod = \"rk4-contact\"\ndt = {dt:?}\nsample_every = {t_end:?}\n")
}

/// The key a scene file `text` is refused for (it must be refused for an invalid key).
pub fn invalid_key(text: &str) -> String {
    match parse(text, Path::new("s.toml")) {
        Err(SceneError::Invalid { key, .. }) => key,
        other => panic!("expected an invalid key for {text:?}, got {other:?}"),
    }
}
