//! Scene files resolved to scenes: the paper's defaults and numbering, regions, physical
//! units, and the errors that name the key (endless runs, impossible tolerances, defects).
#![allow(clippy::unwrap_used)]

mod common;

use common::invalid_key;

use std::path::Path;

use woodpile_scene::{parse, SceneError};

/// The paper's defaults and numbering: site n is index n + N.
#[test]
fn defaults_and_numbering() {
    let scene = parse("[[defect]]\nsite = 0\neps = 10.0\n", Path::new("s.toml")).unwrap();
    let s = &scene.scenario;
    assert_eq!(s.model.n_sites(), 201);
    assert_eq!(s.impulse_site, 75);
    assert_eq!(s.t_end, 150.0);
    assert_eq!(s.model.resonators()[0].site, 100);
    assert_eq!(scene.region_paper, [-1, 1]);
    assert_eq!((s.region.lo(), s.region.hi()), (99, 101));
}

/// `chain.sites` numbers an asymmetric chain: the woodpile's 40 rods -20..19.
#[test]
fn asymmetric_chain_numbering() {
    let text =
        "[chain]\nsites = [-20, 19]\n[impulse]\nsite = -20\n[[defect]]\nsite = 0\neps = 1.0\n";
    let scene = parse(text, Path::new("s.toml")).unwrap();
    let s = &scene.scenario;
    assert_eq!(s.model.n_sites(), 40);
    assert_eq!((scene.first_site, scene.last_site), (-20, 19));
    assert_eq!(s.impulse_site, 0);
    assert_eq!(s.model.resonators()[0].site, 20);
    assert_eq!(
        invalid_key("[chain]\nsites = [-20, 19]\n[impulse]\nsite = 20\n"),
        "impulse.site"
    );
    assert_eq!(
        invalid_key("[chain]\nn = 5\nsites = [-5, 5]\n"),
        "chain.sites"
    );
    assert_eq!(invalid_key("[chain]\nsites = [3, 3]\n"), "chain.sites");
    assert_eq!(invalid_key("[chain]\nsites = [1, 2, 3]\n"), "chain.sites");
    assert_eq!(
        invalid_key(&format!("[chain]\nsites = [{}, {}]\n", i64::MIN, i64::MAX)),
        "chain.sites"
    );
}

/// The default region spans the defects plus one site each side (paper Eqs. 10 and 11).
#[test]
fn default_region_spans_the_defects() {
    let text = "[[defect]]\nsite = 20\neps = 1.0\n[[defect]]\nsite = 0\neps = 1.0\n";
    assert_eq!(
        parse(text, Path::new("s.toml")).unwrap().region_paper,
        [-1, 21]
    );
}

#[test]
fn physical_and_dimensionless_keys_do_not_mix() {
    let physical = "[physical]\ncontact = 2.47e9\nmass = 1e-3\nvelocity = 2.0\n";
    assert_eq!(
        invalid_key(&format!("{physical}[[defect]]\nsite = 0\neps = 1.0\n")),
        "defect[0].eps"
    );
    assert_eq!(
        invalid_key("[[defect]]\nsite = 0\neps = 1.0\nstiffness = 5.0\n"),
        "defect[0].stiffness"
    );
    assert_eq!(
        invalid_key(&format!("{physical}[impulse]\nvelocity = 2.0\n")),
        "impulse.velocity"
    );
}

/// Runs that could never finish are refused before they start, naming the key that makes
/// them too long; the reason carries the estimate.
#[test]
fn endless_runs_are_refused_up_front_naming_the_key() {
    // Each key, with the scenes it makes endless.
    #[rustfmt::skip]
    let cases: [(&str, &[&str]); 6] = [
        ("run.t_end", &["[run]\nt_end = 1e12\n", "[run]\nt_end = 1e8\nsample_every = 1e3\n"]),
        ("run.dt", &["[run]\nmethod = \"rk4\"\ndt = 1e-300\n"]),
        ("run.tolerance", &["[run]\ntolerance = 1e-12\nt_end = 1e5\n"]),
        ("run.sample_every", &["[run]\nsample_every = 1e-12\n"]),
        ("defect[0]", &["[[defect]]\nsite = 0\neps = 1e-300\n", "[[defect]]\nsite = 0\neps = 1e-300\n[run]\nmethod = \"dop853\"\n"]),
        ("defect[1]", &["[[defect]]\nsite = 0\neps = 1.0\n[[defect]]\nsite = 3\neps = 1e-300\n"]),
    ];
    for (key, texts) in cases {
        for text in texts {
            assert_eq!(invalid_key(text), key, "{text}");
        }
    }
    match parse(
        "[run]\nmethod = \"rk4\"\ndt = 1e-300\n",
        Path::new("s.toml"),
    ) {
        Err(SceneError::Invalid { reason, .. }) => {
            assert!(reason.contains("1.500e302 steps"), "{reason}")
        }
        other => panic!("{other:?}"),
    }
    // The budget is generous: the paper's tightest scenes pass.
    assert!(parse("[run]\ntolerance = 1e-10\n", Path::new("s.toml")).is_ok());
}

#[test]
fn tolerances_below_what_doubles_can_verify_are_refused() {
    assert_eq!(invalid_key("[run]\ntolerance = 1e-30\n"), "run.tolerance");
}

#[test]
fn a_standing_impulse_has_no_fractions() {
    assert_eq!(
        invalid_key("[impulse]\nvelocity = 0.0\n"),
        "impulse.velocity"
    );
    assert!(parse("[impulse]\nvelocity = -1.0\n", Path::new("s.toml")).is_ok());
}

#[test]
fn defects_are_capped_at_the_chains_sites() {
    let mut text = String::from("[chain]\nn = 2\n");
    for _ in 0..6 {
        text.push_str("[[defect]]\nsite = 0\neps = 1.0\n");
    }
    assert_eq!(invalid_key(&text), "defect");
}

#[test]
fn two_defects_on_one_site_are_refused() {
    let text = "[[defect]]\nsite = 3\neps = 1.0\n[[defect]]\nsite = 3\neps = 2.0\n";
    assert_eq!(invalid_key(text), "defect[1].site");
}

#[test]
fn dt_needs_a_fixed_step_method() {
    assert_eq!(invalid_key("[run]\ndt = 0.01\n"), "run.dt");
    assert_eq!(
        invalid_key("[run]\nmethod = \"dop853\"\ndt = 0.01\n"),
        "run.dt"
    );
    assert!(parse(
        "[run]\nmethod = \"verlet\"\ndt = 0.01\n",
        Path::new("s.toml")
    )
    .is_ok());
}

/// `auto` announces a run it forecasts long, before it starts, and says nothing of a short one
/// or of a named method's.
#[test]
fn long_runs_are_forecast_before_they_start() {
    let long = woodpile_scene::parse(
        "[chain]\nn = 5000\n[run]\nt_end = 5000.0\ntolerance = 1e-8\n",
        std::path::Path::new("long.toml"),
    )
    .unwrap();
    let note = woodpile_scene::report::cost_note(&long).expect("a note");
    assert!(
        note.contains("first rung") && note.contains("every halving"),
        "{note}"
    );
    let short =
        woodpile_scene::parse("[run]\nt_end = 100.0\n", std::path::Path::new("s.toml")).unwrap();
    assert_eq!(woodpile_scene::report::cost_note(&short), None);
    let named = woodpile_scene::parse(
        "[chain]\nn = 5000\n[run]\nt_end = 5000.0\nmethod = \"rk4\"\ndt = 0.01\n",
        std::path::Path::new("named.toml"),
    )
    .unwrap();
    assert_eq!(woodpile_scene::report::cost_note(&named), None);
    let f = woodpile_sim::simulation::budget::forecast(&long.scenario).unwrap();
    // The first rung is a coarse run (half the fine one's steps) and a fine one; the ladder
    // adds fine runs of 2, 4, ..., 64 times its steps: (0.5 + 127) / 1.5 = 85 first rungs.
    assert!((f.whole_ladder_s / f.first_rung_s - 85.0).abs() < 1e-9);
}

/// A stiff contact dashpot is announced (issue 55, B6): its onset costs `auto` most of its
/// halvings and a damped step costs about four undamped ones, so the forecast counts the
/// whole ladder at the damped rate. The same chain without it says nothing.
#[test]
fn a_stiff_contact_dashpot_is_forecast_long() {
    let scene = |damping: &str| {
        let text = format!(
            "[chain]\nn = 30\n[impulse]\nsite = -10\n[[defect]]\nsite = 0\neps = 2.0\n{damping}[run]\nt_end = 30.0\n"
        );
        woodpile_scene::parse(&text, std::path::Path::new("dashpot.toml")).unwrap()
    };
    let damped = scene("[damping]\ncontact = 1000.0\n");
    let note = woodpile_scene::report::cost_note(&damped).expect("a note");
    assert!(note.contains("contact dashpot"), "{note}");
    assert_eq!(woodpile_scene::report::cost_note(&scene("")), None);
    // Ground damping is smooth: the forecast keeps the first rung as its measure.
    let ground =
        woodpile_sim::simulation::budget::forecast(&scene("[damping]\nground = 0.001\n").scenario);
    assert!(!ground.unwrap().halvings_likely);
}

/// B6: when a contact dashpot makes the halvings likely and even the finest rung `auto` may
/// need is beyond the step budget, the scene is refused at once, naming the key that declares
/// the dashpot: the ladder would otherwise spend every rung before it to be stopped at the
/// last. A named method with its own dt runs once, and is admitted.
#[test]
fn a_contact_dashpot_whose_finest_rung_is_unaffordable_is_refused() {
    let scene = |damping: &str, run: &str| {
        let text = format!("[chain]\nn = 30\n[impulse]\nsite = -10\n{damping}[run]\n{run}");
        woodpile_scene::parse(&text, std::path::Path::new("dashpot.toml"))
    };
    // Each past the budget at its finest rung (first rung x 64), within it at its first.
    for (damping, key, t_end) in [
        ("[damping]\ncontact = 1000.0\n", "damping.contact", 5000.0),
        (
            "[damping]\nrestitution = { e = 0.2, velocity = 1.0 }\n",
            "damping.restitution",
            20000.0,
        ),
        (
            "[[segment]]\nsites = [-15, 14]\ndamping = 1000.0\n",
            "segment[0].damping",
            5000.0,
        ),
        // A dashpot of 0 declares nothing that acts: the first that acts is blamed.
        (
            "[[segment]]\nsites = [-15, -1]\ndamping = 0.0\n[[segment]]\nsites = [0, 14]\ndamping = 1000.0\n",
            "segment[1].damping",
            5000.0,
        ),
    ] {
        let error = scene(damping, &format!("t_end = {t_end:?}\n"))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains(&format!("key `{key}`")) && error.contains("finest rung"),
            "{error}"
        );
        assert!(scene(damping, "t_end = 30.0\n").is_ok(), "{damping}");
        let named = format!("t_end = {t_end:?}\nmethod = \"rk4-contact\"\ndt = 0.01\n");
        let named = scene(damping, &named);
        assert!(named.is_ok(), "{damping}: {:?}", named.err());
    }
    // Without a contact dashpot the same run is admitted: its halvings are not likely.
    assert!(scene("[damping]\nground = 0.001\n", "t_end = 5000.0\n").is_ok());
    // A striker's own dashpot is blamed before a segment's, unless it is 0.
    let struck = |striker_damping: f64| {
        let text = format!(
            "[chain]\nsites = [0, 30]\nboundary = \"free\"\n[striker]\nmass = 2.0\n\
             damping = {striker_damping:?}\n[[segment]]\nsites = [5, 25]\ndamping = 1000.0\n\
             [run]\nt_end = 5000.0\n"
        );
        let error = woodpile_scene::parse(&text, std::path::Path::new("struck.toml"));
        let error = error.unwrap_err().to_string();
        assert!(error.contains("finest rung"), "{error}");
        error
    };
    assert!(struck(1000.0).contains("key `striker.damping`"));
    assert!(struck(0.0).contains("key `segment[0].damping`"));
}
