//! Known answers for the chain an experiment builds (docs/scene.md, `[chain]`, `[[segment]]`,
//! `[striker]`): energy and momentum conserved with every feature, a precompressed chain at
//! rest, the long-wave speed and the dimer's band edges of a precompressed chain, and a heavy
//! striker's train of solitary waves.

mod common;

use common::{invalid_key, scene};

use woodpile_sim::energy::{total_energy, total_momentum};
use woodpile_sim::integrate::{Accuracy, Method, MethodChoice, Plan};
use woodpile_sim::observe::SiteField;
use woodpile_sim::simulation::simulate;

fn fixed(dt: f64) -> Accuracy {
    Accuracy {
        tolerance: 1e-8,
        tolerance_explicit: false,
        dt: Some(dt),
    }
}

/// Every feature at once: segments of masses and contacts, another exponent, wall contacts,
/// a precompression and resonators; then a striker on a free chain. Energy measured from the
/// rest state is kept to the accuracy of the step.
#[test]
fn energy_is_conserved_with_every_feature() {
    let walled = scene(
        r#"
[chain]
n = 30
exponent = 2.2
precompression = 0.05
wall_contact = 0.7
[[segment]]
sites = [-30, 0]
mass = [1.0, 0.4, 2.0]
contact = [1.0, 1.8]
[[segment]]
sites = [1, 30]
mass = 1.5
[impulse]
site = -10
velocity = 0.8
[[defect]]
site = 5
eps = 0.6
kappa = 0.4
[[defect]]
site = 9
eps = 2.0
kappa = 1.3
p = 3
[run]
t_end = 80.0
method = "rkn6-contact"
dt = 0.005
"#,
    );
    let struck = scene(
        r#"
[chain]
n = 30
boundary = { left = "free", right = "fixed" }
[[segment]]
sites = [-30, 30]
mass = [1.0, 0.5]
[striker]
mass = 3.0
velocity = 0.9
contact = 1.6
[[defect]]
site = 0
eps = 1.0
[run]
t_end = 80.0
method = "rkn6-contact"
dt = 0.005
"#,
    );
    for scene in [walled, struck] {
        let s = &scene.scenario;
        let out = simulate(s, &mut ()).unwrap();
        assert!(
            out.stats.max_energy_drift < 1e-9,
            "drift {}",
            out.stats.max_energy_drift
        );
        let e_end = total_energy(&s.model, s.t_end, &out.final_state);
        assert!((e_end - out.e_initial).abs() < 1e-9 * out.e_initial);
        let f = out.fractions;
        let sum = f.reflected + f.transmitted + f.trapped + f.striker;
        assert!((sum - 1.0).abs() < 1e-12, "R + T + E_tr + S = {sum}");
    }
}

/// Free ends on both sides: no external force, so the total momentum stays M_s V.
#[test]
fn momentum_is_conserved_on_a_free_chain() {
    let scene = scene(
        r#"
[chain]
n = 20
boundary = "free"
exponent = 1.7
[[segment]]
sites = [-20, 20]
mass = [1.0, 2.5, 0.7]
contact = [1.0, 0.5]
[striker]
mass = 4.0
velocity = 1.2
[[defect]]
site = 3
eps = 0.8
[run]
t_end = 60.0
method = "rkn6-contact"
dt = 0.01
"#,
    );
    let s = &scene.scenario;
    let out = simulate(s, &mut ()).unwrap();
    let initial = 4.0 * 1.2;
    let end = total_momentum(&s.model, &out.final_state);
    assert!(
        (end - initial).abs() < 1e-12 * initial,
        "{end} vs {initial}"
    );
}

/// u = 0 is the equilibrium of a precompressed chain, exactly: no site accelerates, however
/// heterogeneous its contacts and masses.
#[test]
fn a_precompressed_chain_at_rest_stays_at_rest() {
    let scene = scene(
        r#"
chain = { n = 15, precompression = 2.5, exponent = 1.5, wall_contact = 3.0 }
segment = [{ sites = [-15, 15], mass = [1.0, 0.3], contact = [0.4, 1.0, 7.0] }]
impulse = { site = 0 }
defect = [{ site = 0, eps = 1.0 }]
"#,
    );
    let model = &scene.scenario.model;
    let mut y = model.rest_state();
    let plan = Plan::choose(model, MethodChoice::Named(Method::Rkn6Contact), fixed(0.01)).unwrap();
    plan.integrate(model, &mut y, 20.0, 1.0, &mut ()).unwrap();
    assert!(y.iter().all(|&x| x == 0.0), "the rest state moved");
}

/// Small waves in a precompressed uniform chain travel at the long-wave speed
/// c = sqrt(alpha a delta^(alpha-1) / m) sites per unit time, with delta = (F0/a)^(1/alpha). The
/// front of an impulse's displacement step is an Airy-type front whose value is a third of the
/// step exactly where n = c t, which is what is timed at two far sites.
#[test]
fn small_waves_travel_at_the_long_wave_speed() {
    let (alpha, a, f0, m) = (2.5_f64, 1.7_f64, 0.8_f64, 1.3_f64);
    let scene = scene(&format!(
        r#"
[chain]
n = 200
exponent = {alpha}
precompression = {f0}
[[segment]]
sites = [-200, 200]
mass = {m}
contact = {a}
[impulse]
site = 0
velocity = 1e-4
[fractions]
region = [-1, 1]
[run]
t_end = 150.0
method = "rkn6-contact"
dt = 0.02
sample_every = 0.02
"#
    ));
    let delta = (f0 / a).powf(1.0 / alpha);
    let c = (alpha * a * delta.powf(alpha - 1.0) / m).sqrt();
    let s = &scene.scenario;
    let mut field = SiteField::new(&s.model, 200, 200 + 160);
    simulate(s, &mut field).unwrap();
    let width = 161;
    let crossing = |k: usize| {
        let u = |i: usize| field.displacement[i * width + k];
        let plateau = u(field.t.len() - 1);
        let i = (0..field.t.len()).find(|&i| u(i) >= plateau / 3.0).unwrap();
        field.t[i]
    };
    let (near, far) = (60, 150);
    let speed = (far - near) as f64 / (crossing(far) - crossing(near));
    assert!(
        (speed - c).abs() < 0.01 * c,
        "speed {speed}, long-wave speed {c}"
    );
}

/// A precompressed dimer's linear band edges at the zone boundary: a standing wave on the heavy
/// sites alone (light sites at rest) oscillates at sqrt(2k/M), one on the light sites alone at
/// sqrt(2k/m), k = alpha a delta^(alpha-1). Started with a small amplitude, each returns to its
/// start after one period.
#[test]
fn a_precompressed_dimer_vibrates_at_its_band_edges() {
    let (heavy, light, f0) = (1.0_f64, 0.35_f64, 1.0_f64);
    let k = 1.5 * f0.powf(1.0 / 1.5).sqrt();
    for (moving, mass, pattern) in [
        (0, heavy, format!("[{heavy}, {light}]")),
        (1, light, format!("[{heavy}, {light}]")),
    ] {
        // Walls beyond sites that move: the heavy edge's chain starts and ends on heavy sites,
        // the light edge's on light ones (n = 10 gives 21 sites; the light case drops one).
        let (first, last) = if moving == 0 { (-10, 10) } else { (-9, 11) };
        let pattern = if moving == 0 {
            pattern
        } else {
            format!("[{light}, {heavy}]")
        };
        let scene = scene(&format!(
            "[chain]\nsites = [{first}, {last}]\nprecompression = {f0}\n[[segment]]\nsites = [{first}, {last}]\nmass = {pattern}\n[impulse]\nsite = {first}\n"
        ));
        let model = &scene.scenario.model;
        let n = model.n_sites();
        let n_dof = model.n_dof();
        let amplitude = 1e-5;
        let mut y = model.rest_state();
        for (j, site) in (0..n).step_by(2).enumerate() {
            y[site] = if j % 2 == 0 { amplitude } else { -amplitude };
        }
        let start = y.clone();
        let omega = (2.0 * k / mass).sqrt();
        let period = 2.0 * std::f64::consts::PI / omega;
        let steps = 2000.0;
        let plan = Plan::choose(
            model,
            MethodChoice::Named(Method::Rkn6Contact),
            fixed(period / steps),
        )
        .unwrap();
        plan.integrate(model, &mut y, period, period, &mut ())
            .unwrap();
        let worst = (0..n).map(|i| (y[i] - start[i]).abs()).fold(0.0, f64::max);
        assert!(worst < 1e-3 * amplitude, "mode {moving}: off by {worst:e}");
        // Half a period later each site is at the opposite extreme.
        let mut y = start.clone();
        plan.integrate(model, &mut y, 0.5 * period, 0.5 * period, &mut ())
            .unwrap();
        let worst = (0..n).map(|i| (y[i] + start[i]).abs()).fold(0.0, f64::max);
        assert!(
            worst < 1e-3 * amplitude,
            "mode {moving} at half period: {worst:e}"
        );
        assert!(y[n_dof..]
            .iter()
            .all(|v| v.abs() < 1e-3 * amplitude * omega));
    }
}

/// A striker of the chain's own mass hands the chain one solitary wave and stops; one ten times
/// heavier keeps pushing and launches a train of them (the paper's note on its experiment).
/// Counted as the velocity maxima that pass a far site, above a tenth of the largest.
#[test]
fn a_heavy_striker_launches_a_train_of_solitary_waves() {
    let count = |striker_mass: f64| {
        let scene = scene(&format!(
            r#"
[chain]
n = 150
boundary = {{ left = "free", right = "fixed" }}
[striker]
mass = {striker_mass}
velocity = 1.0
[fractions]
region = [-1, 1]
[run]
t_end = 220.0
tolerance = 1e-6
sample_every = 0.05
"#
        ));
        let s = &scene.scenario;
        let watched = (100 + 1) as usize; // paper site -50: index 1 + 100
        let mut field = SiteField::new(&s.model, watched, watched);
        let out = simulate(s, &mut field).unwrap();
        let v = &field.velocity;
        let top = v.iter().cloned().fold(0.0, f64::max);
        let peaks = (1..v.len() - 1)
            .filter(|&i| v[i] > v[i - 1] && v[i] >= v[i + 1] && v[i] > 0.1 * top)
            .count();
        (peaks, out.fractions.striker)
    };
    let (single, _) = count(1.0);
    let (train, striker_share) = count(10.0);
    assert_eq!(
        single, 1,
        "an equal-mass striker launches one solitary wave"
    );
    assert!(train >= 3, "a heavy striker launched {train} waves");
    assert!(
        striker_share < 0.05,
        "the heavy striker kept {striker_share}"
    );
}

/// Each refusal names its key: the scene format's contract for the chain's new keys.
#[test]
fn bad_chains_are_refused_naming_the_key() {
    let striker = "[striker]\nmass = 2.0\n";
    let free_left = "[chain]\nboundary = { left = \"free\", right = \"fixed\" }\n";
    #[rustfmt::skip]
    let cases = [
        ("[chain]\nboundary = \"free\"\nprecompression = 1.0\n", "chain.precompression"),
        ("[chain]\nboundary = { left = \"free\", right = \"fixed\" }\nprecompression = 1.0\n[striker]\nmass = 2.0\n", "chain.precompression"),
        (striker, "striker"),
        (&format!("{free_left}{striker}[impulse]\nsite = 0\n"), "impulse"),
        ("[[segment]]\nsites = [0, 10]\nmass = 2.0\n[[segment]]\nsites = [10, 20]\nmass = 1.0\n", "segment[1].sites"),
        ("[[segment]]\nsites = [90, 101]\nmass = 2.0\n", "segment[0].sites"),
        ("[[segment]]\nsites = [0, 3]\nmass = [1.0, 0.0]\n", "segment[0].mass[1]"),
        ("[[segment]]\nsites = [0, 3]\ncontact = -1.0\n", "segment[0].contact"),
        ("[chain]\nexponent = 0.5\n", "chain.exponent"),
        ("[chain]\nexponent = 6.0\n", "chain.exponent"),
        ("[chain]\nexponent = nan\n", "chain.exponent"),
        ("[chain]\nwall_contact = 0.0\n", "chain.wall_contact"),
        ("[chain]\nprecompression = -1.0\n", "chain.precompression"),
        ("[chain]\nboundary = { left = \"free\", right = \"sticky\" }\n", "chain.boundary.right"),
        (&format!("{free_left}[striker]\nmass = -2.0\n"), "striker.mass"),
        (&format!("{free_left}[striker]\nvelocity = 1.0\n"), "striker.mass"),
        ("[physical]\nvelocity = 1.0\nmass = 1e-3\ncontact = 2.47e9\n[[defect]]\nsite = 0\nmass = 1e-3\nresonator_mass = 1e-3\nstiffness = 1e6\n[[segment]]\nsites = [-2, 2]\nmass = 2e-3\n", "segment[0].mass"),
        ("[physical]\nvelocity = 1.0\nmaterial = { youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }\nrod = { length = 0.02, diameter = 0.005 }\n[[defect]]\nsite = 0\nrod = { length = 0.04 }\nresonator_share = 1.5\n", "defect[0].resonator_share"),
        ("[physical]\nvelocity = 1.0\nmass = 1e-3\ncontact = 2.47e9\n[[defect]]\nsite = 0\nrod = { length = 0.04 }\n", "defect[0].rod.diameter"),
        ("[physical]\nvelocity = 1.0\nmass = 1e-3\ncontact = 2.47e9\n[chain]\nexponent = 2.0\n", "chain.exponent"),
    ];
    for (text, key) in cases {
        assert_eq!(invalid_key(text), key, "for {text:?}");
    }
}

/// The woodpile as the experiment built it, from geometry: the rods' mass and coefficient, the
/// 40 mm defect's bending mode, and the glass sphere's contact, listed in the scene's physical
/// values.
#[test]
fn rods_and_a_sphere_from_their_geometry() {
    let scene = scene(
        r#"
[chain]
sites = [-20, 19]
boundary = { left = "free", right = "fixed" }
[physical]
material = { youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }
rod = { length = 0.02, diameter = 0.005 }
[striker]
velocity = 1.98
sphere = { diameter = 0.01, material = { youngs_modulus = 70e9, poisson_ratio = 0.23, density = 2500.0 } }
[[defect]]
site = 0
rod = { length = 0.04 }
[run]
t_end = 60.0
tolerance = 1e-6
"#,
    );
    let physical = scene.physical.as_ref().unwrap();
    let value = |name: &str| {
        physical
            .derived
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("no {name}"))
            .1
    };
    assert!((value("contact_N_per_m1.5") - 2.47e9).abs() < 0.005 * 2.47e9);
    // The sphere (1.31 g) is about one and a half regular rods (0.864 g).
    let striker_mass = value("striker_mass");
    assert!(
        (striker_mass - 1.309 / 0.8639).abs() < 0.01,
        "{striker_mass}"
    );
    let defect = physical.defects[0];
    assert!((defect.bending_f1_hz.unwrap() - 15.2e3).abs() < 0.02 * 15.2e3);
    assert!(
        (defect.eps - 0.894 / 0.8639).abs() < 0.01,
        "eps {}",
        defect.eps
    );
    let out = simulate(&scene.scenario, &mut ()).unwrap();
    let f = out.fractions;
    assert!((f.reflected + f.transmitted + f.trapped + f.striker - 1.0).abs() < 1e-12);
}
