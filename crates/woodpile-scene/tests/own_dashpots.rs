//! A segment's and the striker's own contact dashpots (`damping` or `restitution` on
//! `[[segment]]` and `[striker]`): they override `[damping] contact` on their own contacts
//! only, a striker's restitution is that of the striker and the first site, and a segment
//! covering the whole chain is the chain's own dashpot, bit for bit.

#![allow(clippy::unwrap_used)]

mod common;

use common::{collision_run, invalid_key, parting_restitution, scene};
use woodpile_scene::Scene;
use woodpile_sim::simulation::simulate;

/// A striker of mass 3 hitting a free site of mass 1 through a contact of 2 at `v`: e from
/// their velocities once apart, (v1 − v0) / v. (The site's neighbour is held off by a contact
/// of 1e-12, whose force over the run is below 1e-9.)
fn striker_restitution(law: &str, e: f64, v: f64) -> f64 {
    let s = scene(&format!(
        r#"
[chain]
sites = [0, 1]
boundary = "free"
[[segment]]
sites = [0, 1]
contact = 1e-12
[striker]
mass = 3.0
velocity = {v:?}
contact = 2.0
restitution = {{ e = {e:?}, velocity = {v:?} }}
[damping]
law = "{law}"
{run}"#,
        run = collision_run(v, 60.0),
    ));
    let d = s.scenario.model.damping().unwrap();
    assert_eq!(d.contact_at(0), 0.0, "the wall keeps [damping] contact");
    parting_restitution(&s, v)
}

#[test]
fn a_striker_parts_from_the_first_site_with_its_own_restitution() {
    for law in ["linear", "hertzian"] {
        let got = striker_restitution(law, 0.8, 1.0);
        assert!((got - 0.8).abs() < 1e-6, "{law}: {got}");
    }
}

#[test]
fn a_segment_over_the_whole_chain_is_the_chains_own_dashpot() {
    let base = "[chain]\nn = 20\n[[defect]]\nsite = 0\neps = 2.0\n[impulse]\nsite = -10\n[run]\nt_end = 30.0\nmethod = \"rk4-contact\"\ndt = 0.01\n";
    let global = scene(&format!("{base}[damping]\ncontact = 0.05\n"));
    let own = scene(&format!(
        "{base}[[segment]]\nsites = [-20, 20]\ndamping = 0.05\n"
    ));
    let d = own.scenario.model.damping().unwrap();
    assert_eq!(d.contact_at(0), 0.0, "the walls are not the segment's");
    assert_eq!(d.contact_at(5), 0.05);
    let walls = scene(&format!(
        "{base}[damping]\ncontact = 0.05\n[[segment]]\nsites = [-20, 20]\ndamping = 0.05\n"
    ));
    let run = |s: &Scene| {
        let mut none = ();
        simulate(&s.scenario, &mut none).unwrap().fractions
    };
    // Walls that the wave never reaches: the same bits with one γ or a γ per contact.
    assert_eq!(run(&global), run(&walls));
    assert!(run(&own).dissipated > 0.0);
}

#[test]
fn a_segment_dashpot_acts_on_its_contacts_only() {
    let s = scene(
        "[chain]\nn = 10\n[impulse]\nsite = -5\n[[segment]]\nsites = [2, 4]\ndamping = 0.3\n[damping]\ncontact = 0.1\n",
    );
    let d = s.scenario.model.damping().unwrap();
    let first = 10 + 2; // internal index of paper site 2
    assert_eq!(d.contact_at(first), 0.1, "the contact before the segment");
    assert_eq!(d.contact_at(first + 1), 0.3);
    assert_eq!(d.contact_at(first + 2), 0.3);
    assert_eq!(d.contact_at(first + 3), 0.1, "the contact after it");
}

#[test]
fn own_dashpots_are_refused_where_they_cannot_be_read() {
    let cases = [
        (
            "[[segment]]\nsites = [2, 2]\ndamping = 0.3\n",
            "segment[0].damping",
        ),
        (
            "[[segment]]\nsites = [2, 4]\ndamping = 0.3\nrestitution = { e = 0.9, velocity = 1.0 }\n",
            "segment[0].restitution",
        ),
        (
            "[[segment]]\nsites = [2, 4]\ndamping = -1.0\n",
            "segment[0].damping",
        ),
        (
            "[chain]\nboundary = { left = \"free\" }\n[striker]\nmass = 1.0\nrestitution = { e = 1.5, velocity = 1.0 }\n",
            "striker.restitution",
        ),
    ];
    for (text, key) in cases {
        assert_eq!(invalid_key(text), key, "{text}");
    }
}

#[test]
fn a_step_budget_refusal_names_the_dashpot_that_sets_the_step() {
    let stiff_segment = "[chain]\nsites = [-20, 20]\nboundary = \"free\"\n[impulse]\nsite = -20\n\
        [damping]\ncontact = 0.01\n[[segment]]\nsites = [0, 5]\ndamping = 1e7\n";
    assert_eq!(invalid_key(stiff_segment), "segment[0].damping");
    let stiff_striker = "[chain]\nsites = [0, 30]\nboundary = \"free\"\n\
        [striker]\nmass = 2.0\ndamping = 1e7\n[damping]\ncontact = 0.01\n";
    assert_eq!(invalid_key(stiff_striker), "striker.damping");
    let stiff_chain = "[chain]\nsites = [-20, 20]\nboundary = \"free\"\n[impulse]\nsite = -20\n\
        [damping]\ncontact = 1e7\n[[segment]]\nsites = [0, 5]\ndamping = 0.01\n";
    assert_eq!(invalid_key(stiff_chain), "damping.contact");
}
