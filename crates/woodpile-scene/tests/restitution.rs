//! `damping.restitution`: the contact dashpot calibrated so that two regular sites meeting at
//! the given velocity part with the given e. Checked by simulating that very collision.

#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;

use common::{collision_run, invalid_key, parting_restitution, scene};

/// Two free sites, the first struck at `v`, run past their parting; e from their velocities
/// at the end: (v1 − v0) / v.
fn simulated_restitution(law: &str, e: f64, v: f64) -> f64 {
    let s = scene(&format!(
        r#"
[chain]
sites = [0, 1]
boundary = "free"
[impulse]
site = 0
velocity = {v:?}
[damping]
law = "{law}"
restitution = {{ e = {e:?}, velocity = {v:?} }}
{run}"#,
        run = collision_run(v, 40.0),
    ));
    parting_restitution(&s, v)
}

#[test]
fn a_simulated_collision_parts_with_the_asked_restitution() {
    for law in ["linear", "hertzian"] {
        for (e, v) in [(0.9, 1.0), (0.6, 0.05)] {
            let got = simulated_restitution(law, e, v);
            assert!((got - e).abs() < 1e-6, "{law}, e {e}, v {v}: {got}");
        }
    }
}

#[test]
fn restitution_one_is_no_dashpot() {
    let s = scene("[damping]\nrestitution = { e = 1.0, velocity = 1.0 }\n");
    assert_eq!(s.scenario.model.damping().map_or(0.0, |d| d.contact), 0.0);
}

#[test]
fn a_physical_scene_lists_the_calibrated_dashpot_in_si() {
    let s = scene(
        r#"
[chain]
sites = [-10, 9]
boundary = "free"
[physical]
material = { youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }
rod = { length = 0.020, diameter = 0.005 }
velocity = 1.0
[impulse]
site = -10
[damping]
law = "hertzian"
restitution = { e = 0.9, velocity = "1 m/s" }
"#,
    );
    let derived = &s.physical.as_ref().unwrap().derived;
    let si = derived
        .iter()
        .find(|(name, _)| name == "damping_contact_si")
        .unwrap()
        .1;
    let scaled = s.scenario.model.damping().unwrap().contact;
    assert!(si > 0.0 && scaled > 0.0);
    let listed = derived
        .iter()
        .find(|(name, _)| name == "damping_contact")
        .unwrap()
        .1;
    assert_eq!(listed, scaled);
}

#[test]
fn bad_restitutions_are_refused_naming_the_key() {
    let cases = [
        (
            "restitution = { e = 1.5, velocity = 1.0 }",
            "damping.restitution",
            "(0, 1]",
        ),
        (
            "restitution = { e = 0.0, velocity = 1.0 }",
            "damping.restitution",
            "(0, 1]",
        ),
        (
            "restitution = { velocity = 1.0 }",
            "damping.restitution.e",
            "required",
        ),
        (
            "restitution = { e = 0.9 }",
            "damping.restitution.velocity",
            "required",
        ),
        (
            "restitution = { e = 0.9, velocity = -1.0 }",
            "damping.restitution.velocity",
            "> 0",
        ),
        (
            "restitution = { e = 0.9, velocity = \"1 m/s\" }",
            "damping.restitution.velocity",
            "[physical]",
        ),
        (
            "contact = 0.1\nrestitution = { e = 0.9, velocity = 1.0 }",
            "damping.restitution",
            "not both",
        ),
    ];
    for (table, key, reason) in cases {
        let text = format!("[damping]\n{table}\n");
        assert_eq!(invalid_key(&text), key, "{table}");
        let message = woodpile_scene::parse(&text, Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(message.contains(reason), "{table}: {message}");
    }
}
