//! The damping keys of a scene (docs/scene.md, `[damping]`, a defect's `damping` or
//! `quality_factor`, a soft end): what they build, their SI conversion, and the refusals that
//! name the key.

mod common;

use std::path::Path;

use common::{invalid_key, scene};

use woodpile_sim::model::End;
use woodpile_sim::DashpotLaw;

const DAMPED: &str = r#"
[chain]
n = 30
boundary = { left = "free", right = { spring = 0.05, damping = 0.5 } }
[[defect]]
site = 0
eps = 0.5
damping = 0.05
[[defect]]
site = 3
eps = 2.0
quality_factor = 40.0
[damping]
contact = 0.1
law = "hertzian"
ground = 0.001
"#;

#[test]
fn the_keys_build_the_dissipation_they_name() {
    let s = scene(DAMPED);
    let model = &s.scenario.model;
    assert!(model.is_dissipative());
    let d = model.damping().unwrap();
    assert_eq!(
        (d.contact, d.law, d.ground),
        (0.1, DashpotLaw::Hertzian, 0.001)
    );
    assert_eq!(d.resonator[0], 0.05);
    // Q = mu omega / c for the pair of host mass 1 and eps 2 at kappa 1.
    let mu: f64 = 2.0 / 3.0;
    let expected = mu * (1.0 / mu).sqrt() / 40.0;
    assert!((d.resonator[1] - expected).abs() < 1e-15);
    assert_eq!(
        model.boundary().right(),
        End::Soft {
            spring: 0.05,
            damping: 0.5
        }
    );
    // Defaults: a [damping] table alone is a linear dashpot on every contact.
    let linear = scene("[damping]\ncontact = 0.2\n");
    assert_eq!(
        linear.scenario.model.damping().unwrap().law,
        DashpotLaw::Linear
    );
    // Every coefficient zero: no dissipation at all, and the paper's path.
    let none = scene("[damping]\ncontact = 0.0\n[[defect]]\nsite = 0\neps = 1.0\ndamping = 0.0\n");
    assert!(!none.scenario.model.is_dissipative());
}

#[test]
fn si_scenes_convert_each_coefficient_and_list_it() {
    let s = scene(
        r#"
[physical]
contact = 2.47e9
mass = 0.866e-3
velocity = 1.98
[chain]
n = 30
boundary = { left = "free", right = { spring = 3.0e4, damping = 2.0 } }
[[defect]]
site = 0
resonator_mass = 0.5e-3
stiffness = 3.961e6
damping = 1.5
[damping]
contact = 4.0
ground = 0.01
"#,
    );
    let p = s.physical.as_ref().unwrap();
    let scales = p.scales;
    let listed = |name: &str| {
        p.derived
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("{name} not listed in {:?}", p.derived))
            .1
    };
    let d = s.scenario.model.damping().unwrap();
    assert_eq!(d.contact, scales.dashpot(4.0));
    assert_eq!(listed("damping_contact"), d.contact);
    assert_eq!(listed("damping_ground"), scales.dashpot(0.01));
    assert_eq!(listed("defect_0__damping"), scales.dashpot(1.5));
    assert_eq!(listed("boundary_right_spring"), scales.spring(3.0e4));
    assert_eq!(listed("boundary_right_damping"), scales.dashpot(2.0));
    let hertzian = scene(
        "[physical]\ncontact = 2.47e9\nmass = 0.866e-3\nvelocity = 1.98\n[damping]\ncontact = 4.0\nlaw = \"hertzian\"\n",
    );
    let gamma = hertzian.scenario.model.damping().unwrap().contact;
    assert_eq!(gamma, scales.hertzian_dashpot(4.0));
}

#[test]
fn bad_damping_is_refused_naming_the_key() {
    let cases = [
        ("[damping]\ncontact = -0.1\n", "damping.contact"),
        ("[damping]\nground = nan\n", "damping.ground"),
        ("[damping]\ncontact = inf\n", "damping.contact"),
        ("[damping]\nlaw = \"viscous\"\n", "damping.law"),
        ("[[defect]]\nsite = 0\neps = 1.0\ndamping = -1.0\n", "defect[0].damping"),
        (
            "[[defect]]\nsite = 0\neps = 1.0\nquality_factor = 0.0\n",
            "defect[0].quality_factor",
        ),
        (
            "[[defect]]\nsite = 0\neps = 1.0\ndamping = 0.1\nquality_factor = 10.0\n",
            "defect[0].quality_factor",
        ),
        (
            "[[defect]]\nsite = 0\neps = 1.0\np = 3\nquality_factor = 10.0\n",
            "defect[0].quality_factor",
        ),
        (
            "[chain]\nboundary = { left = \"free\", right = { spring = -1.0 } }\n",
            "chain.boundary.right.spring",
        ),
        (
            "[chain]\nboundary = { left = { damping = 1.0, mass = 2.0 }, right = \"fixed\" }\n",
            "chain.boundary.left.mass",
        ),
        (
            "[chain]\nprecompression = 0.1\nboundary = { left = \"fixed\", right = { spring = 1.0 } }\n",
            "chain.precompression",
        ),
        (
            "[damping]\ncontact = 0.1\n[run]\nmethod = \"rkn6-contact\"\ndt = 0.01\n",
            "run.method",
        ),
        (
            "[damping]\ncontact = 0.1\n[run]\nmethod = \"verlet\"\ndt = 0.01\n",
            "run.method",
        ),
    ];
    // An unknown key is refused by the file's grammar, naming it.
    let unknown = woodpile_scene::parse("[damping]\nfriction = 1.0\n", Path::new("s.toml"));
    assert!(unknown.unwrap_err().to_string().contains("friction"));
    for (text, key) in cases {
        let refused = invalid_key(text);
        assert!(
            refused.starts_with(key),
            "{text:?}: refused for {refused}, expected {key}"
        );
    }
}
