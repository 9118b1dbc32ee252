//! The independent reference of damped chains (`woodpile_bench::independent`) against closed
//! forms, against its own ledger, and against the simulator it is there to check.
#![allow(clippy::unwrap_used)]

use woodpile_bench::independent::reference;
use woodpile_sim::energy::Region;
use woodpile_sim::integrate::MethodChoice;
use woodpile_sim::simulation::{simulate, Scenario};
use woodpile_sim::testing::{damped_audit_scene, tolerance, Lcg};
use woodpile_sim::{Boundary, ContactLaw, Damping, DashpotLaw, Model};

/// Two unit masses touching at rest, the left one struck at unit speed, joined by a contact
/// of exponent `exponent` and unit coefficient with a dashpot `gamma` of `law`.
fn pair(exponent: f64, gamma: f64, law: DashpotLaw, t_end: f64) -> Scenario {
    let model = Model::new(2, Boundary::Free, vec![])
        .and_then(|m| m.with_contacts(ContactLaw::new(vec![1.0; 3], exponent, 0.0)?))
        .and_then(|m| m.with_damping(Damping::new(gamma, law, 0.0, vec![])?))
        .unwrap();
    Scenario {
        model,
        impulse_site: 0,
        impulse_velocity: 1.0,
        t_end,
        region: Region::new(1, 1, 2).unwrap(),
        method: MethodChoice::Auto,
        accuracy: tolerance(1e-8),
        sample_every: t_end,
    }
}

/// The relative velocity c' = u0' - u1' after a linear spring (k = 1) and a linear dashpot γ
/// part, in closed form. In the relative coordinate (reduced mass 1/2) c'' + 2γ c' + 2c = 0
/// from c = 0, c' = 1, so c = e^{-γt} sin(ωt)/ω with ω² = 2 − γ². The contact stops pushing
/// where its force k c + γ c' = −c''/2 reaches zero, at ωt* = π − atan(2γω / (ω² − γ²)).
fn linear_pair_exit_rate(gamma: f64) -> f64 {
    let omega = (2.0 - gamma * gamma).sqrt();
    let t = (std::f64::consts::PI - (2.0 * gamma * omega / (omega * omega - gamma * gamma)).atan())
        / omega;
    (-gamma * t).exp() * ((omega * t).cos() - gamma / omega * (omega * t).sin())
}

#[test]
fn a_linear_spring_and_dashpot_pair_leaves_at_the_closed_form_restitution() {
    let gamma = 0.3;
    let scene = pair(1.0, gamma, DashpotLaw::Linear, 6.0);
    let r = reference(&scene, 1e-13).unwrap();
    let (v0, v1) = (r.state[2], r.state[3]);
    let exit = linear_pair_exit_rate(gamma);
    assert!(exit < 0.0 && exit > -1.0, "a damped pair separates: {exit}");
    assert!(
        (v0 - v1 - exit).abs() < 1e-11,
        "c' = {} against {exit}",
        v0 - v1
    );
    assert!((v0 + v1 - 1.0).abs() < 1e-12, "momentum: {}", v0 + v1);
    // All of the spring's energy at the clip is dissipated while it opens: D is what the
    // relative motion lost, (1 - c'^2) / 4 of E(0) = 1/2.
    let d = (1.0 - exit * exit) / 2.0;
    assert!((r.fractions.dissipated - d).abs() < 1e-11);
    assert!(r.ledger_drift < 1e-12, "ledger {:e}", r.ledger_drift);
    assert!(
        r.counts.switches >= 2,
        "the clip and the opening are located"
    );
}

#[test]
fn an_undamped_hertzian_pair_exchanges_velocities() {
    let scene = pair(1.5, 0.0, DashpotLaw::Hertzian, 8.0);
    let r = reference(&scene, 1e-13).unwrap();
    assert!(r.state[2].abs() < 1e-11, "striker left at {}", r.state[2]);
    assert!(
        (r.state[3] - 1.0).abs() < 1e-11,
        "target left at {}",
        r.state[3]
    );
    assert!(r.ledger_drift < 1e-12);
}

#[test]
fn a_hertzian_dashpot_pair_keeps_its_ledger_and_loses_energy() {
    let scene = pair(1.5, 0.2, DashpotLaw::Hertzian, 8.0);
    let r = reference(&scene, 1e-13).unwrap();
    let exit = r.state[2] - r.state[3];
    assert!(exit < 0.0 && exit > -1.0, "c' after = {exit}");
    assert!(r.fractions.dissipated > 0.01);
    assert!(r.ledger_drift < 1e-12, "ledger {:e}", r.ledger_drift);
}

#[test]
fn the_simulator_agrees_with_the_independent_reference_on_damped_audit_scenes() {
    let mut rng = Lcg(2026);
    let scenes: Vec<Scenario> = (0..6).map(|_| damped_audit_scene(&mut rng)).collect();
    // Scenes 2 and 5 of seed 2026: a plain and an experiment's chain, a few hundred switches.
    for k in [2, 5] {
        let scene = &scenes[k];
        let fine = reference(scene, 1e-13).unwrap();
        let coarse = reference(scene, 1e-12).unwrap();
        let bound = fine.fractions.largest_difference(&coarse.fractions);
        assert!(
            bound < 1e-10,
            "scene {k}: the reference's own bound {bound:e}"
        );
        assert!(
            fine.ledger_drift < 1e-10,
            "scene {k}: ledger {:e}",
            fine.ledger_drift
        );
        let tol = 1e-7;
        let auto = simulate(
            &Scenario {
                accuracy: tolerance(tol),
                ..scene.clone()
            },
            &mut (),
        )
        .unwrap();
        let error = auto.fractions.largest_difference(&fine.fractions);
        assert!(error < tol, "scene {k}: auto is {error:e} off at {tol:e}");
    }
}

/// The reference models gapped linear contacts (`LinearGap`) as the simulator's own known
/// answer has them: two unit beads between walls, every contact of stiffness k across a gap g,
/// the left one struck at v, repeat after T = 6g/v + π/√(2k) + 2π/√k
/// (`contact::linear_gap`'s test, where the period is derived).
#[test]
fn a_bouncing_pair_across_gaps_repeats_with_its_closed_form_period() {
    use std::f64::consts::PI;
    let (k, g, v) = (2.0, 1.0, 0.5);
    let law = woodpile_sim::contact::LinearGap::new(vec![k; 3], vec![g; 3]).unwrap();
    let model = Model::new(2, Boundary::Fixed, vec![])
        .and_then(|m| m.with_law(law))
        .unwrap();
    let period = 6.0 * g / v + PI / (2.0 * k).sqrt() + 2.0 * PI / k.sqrt();
    let scene = Scenario {
        model,
        impulse_site: 0,
        impulse_velocity: v,
        t_end: period,
        region: Region::new(1, 1, 2).unwrap(),
        method: MethodChoice::Auto,
        accuracy: tolerance(1e-8),
        sample_every: period,
    };
    let r = reference(&scene, 1e-13).unwrap();
    for (got, want) in r.state.iter().zip([0.0, 0.0, v, 0.0]) {
        assert!(
            (got - want).abs() < 1e-9,
            "{:?} after T = {period}",
            r.state
        );
    }
    assert!(r.ledger_drift < 1e-12, "ledger {:e}", r.ledger_drift);
}
