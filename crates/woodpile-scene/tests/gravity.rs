//! `chain.gravity`: the upright chain's rest state under its own weight, against closed forms,
//! and what it refuses.

mod common;

use common::{invalid_key, scene};
use woodpile_sim::simulation::simulate;

/// A scaled chain -10..9 standing on a wall in gravity 0.01, a dimer of masses 1 and 2, two
/// linear resonators, struck on its top site with `velocity`.
fn standing(velocity: f64) -> String {
    format!(
        r#"
[chain]
sites = [-10, 9]
boundary = {{ left = "free", right = "fixed" }}
gravity = 0.01
[[segment]]
sites = [-10, 9]
mass = [1.0, 2.0]
[[defect]]
site = -5
eps = 0.5
[[defect]]
site = 4
eps = 1.5
kappa = 0.7
[impulse]
site = -10
velocity = {velocity:?}
[run]
t_end = 60.0
tolerance = 1e-9
"#
    )
}

/// Each contact's static overlap is the closed form: the weight above it, g Σ m (sites and
/// resonators), over its coefficient, to the power 1/α.
#[test]
fn each_contact_carries_the_weight_above_it() {
    let s = scene(&standing(1.0));
    let law = s.scenario.model.contacts().unwrap();
    let masses: Vec<f64> = (0..20)
        .map(|n| if n % 2 == 0 { 1.0 } else { 2.0 })
        .collect();
    let mut above = 0.0;
    for bond in 1..=20 {
        above += masses[bond - 1]
            + match bond - 1 {
                5 => 0.5,
                14 => 1.5,
                _ => 0.0,
            };
        let expected = (0.01 * above).powf(1.0 / 1.5);
        let got = law.static_overlap(bond);
        assert!(
            (got - expected).abs() <= 1e-15 * expected,
            "bond {bond}: {got} against {expected}"
        );
    }
    assert_eq!(law.static_overlap(0), 0.0);
}

/// The rest state is an exact equilibrium: every acceleration is zero there, and a chain left
/// at rest stays at rest.
#[test]
fn a_loaded_chain_at_rest_stays_at_rest() {
    let s = scene(&standing(1.0));
    let model = &s.scenario.model;
    let q = vec![0.0; model.n_dof()];
    let mut acc = vec![1.0; model.n_dof()];
    model.accelerations(0.0, &q, &mut acc);
    assert!(acc.iter().all(|&a| a == 0.0), "{acc:?}");
    // Stepped from rest for 1,000 steps (RK4 on the whole right-hand side, resonators
    // included), it stays there.
    let n = 2 * model.n_dof();
    let (mut y, h) = (vec![0.0; n], 0.05);
    let mut k = vec![vec![0.0; n]; 4];
    for step in 0..1000 {
        let t = step as f64 * h;
        model.rhs(t, &y, &mut k[0]);
        let stage = |y: &[f64], k: &[f64], c: f64| -> Vec<f64> {
            y.iter().zip(k).map(|(a, b)| a + c * h * b).collect()
        };
        let y2 = stage(&y, &k[0], 0.5);
        model.rhs(t, &y2, &mut k[1]);
        let y3 = stage(&y, &k[1], 0.5);
        model.rhs(t, &y3, &mut k[2]);
        let y4 = stage(&y, &k[2], 1.0);
        model.rhs(t, &y4, &mut k[3]);
        for i in 0..n {
            y[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
        }
    }
    let drift = y.iter().fold(0.0_f64, |m, &v| m.max(v.abs()));
    assert!(drift <= 1e-12, "{drift}");
}

/// Energy, gravity's potential included, is conserved: the shares sum to 1 and the drift is
/// the tolerance's.
#[test]
fn the_ledger_includes_the_weights() {
    let s = scene(&standing(1.0));
    let out = simulate(&s.scenario, &mut ()).unwrap();
    let f = out.fractions;
    assert!((f.reflected + f.transmitted + f.trapped - 1.0).abs() < 1e-9);
    assert!(
        out.stats.max_energy_drift < 1e-7,
        "{}",
        out.stats.max_energy_drift
    );
}

#[test]
fn a_chain_that_cannot_stand_is_refused_naming_the_key() {
    let text = standing(1.0);
    let cases = [
        (
            text.replace(
                "left = \"free\", right = \"fixed\"",
                "left = \"fixed\", right = \"fixed\"",
            ),
            "chain.gravity",
        ),
        (
            text.replace(
                "left = \"free\", right = \"fixed\"",
                "left = \"free\", right = \"free\"",
            ),
            "chain.gravity",
        ),
        (
            text.replace("gravity = 0.01", "gravity = -1.0"),
            "chain.gravity",
        ),
        (
            text.replace("kappa = 0.7", "kappa = 0.7\np = 3"),
            "defect[1]",
        ),
    ];
    for (scene_text, key) in cases {
        assert_eq!(invalid_key(&scene_text), key, "{scene_text}");
    }
}

/// The linear sound speed at depth: a pulse far below the static forces (a top-site impulse
/// of 1e-3) crosses the sites from depth 50 to 150 in Σ 1/c_d, with c_d = √(K_d / m) and
/// K_d = (3/2) a δ_d^{1/2} the stiffness of the contact under the weight of the d + 1 sites
/// above it (unit masses and coefficients: δ_d = ((d + 1) g)^{2/3}). The front is read where
/// a site's speed first passes a thousandth of the impulse: the lattice's dispersion sends a
/// precursor ahead of the sound speed, and the front so read crosses the 100 sites 1.7% early.
/// The test allows 5%; a stiffness without its factor 3/2 would be 22% off.
#[test]
fn a_small_pulse_travels_at_the_sound_speed_of_each_depth() {
    let (g, n) = (1.0, 200);
    let s = scene(&format!(
        r#"
[chain]
sites = [{first}, {last}]
boundary = {{ left = "free", right = "fixed" }}
gravity = {g:?}
[impulse]
site = {first}
velocity = 1e-3
[run]
t_end = 90.0
method = "rkn6-contact"
dt = 0.01
sample_every = 0.02
"#,
        first = -n,
        last = n,
    ));
    let sites = s.scenario.model.n_sites();
    let mut field = woodpile_sim::observe::SiteField::new(&s.scenario.model, 0, sites - 1);
    simulate(&s.scenario, &mut field).unwrap();
    let arrival = |site: usize| -> f64 {
        let samples = field.t.len();
        let first = (0..samples)
            .find(|&i| field.velocity[i * sites + site].abs() > 1e-6)
            .unwrap_or_else(|| panic!("the pulse never reached depth {site}"));
        field.t[first]
    };
    let expected: f64 = (50..150)
        .map(|d| {
            let stiffness = 1.5 * ((d as f64 + 1.0) * g).powf(1.0 / 3.0);
            1.0 / stiffness.sqrt()
        })
        .sum();
    let measured = arrival(150) - arrival(50);
    assert!(
        (measured / expected - 1.0).abs() < 0.05,
        "measured {measured}, expected {expected}"
    );
}
