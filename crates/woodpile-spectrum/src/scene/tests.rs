//! Scenes as written in TOML: units, paper sites, and the refusals a caller names a key for.

use std::path::Path;

use super::*;
use crate::tables::{summary, table, Part, Values};

fn scene(text: &str) -> Scene {
    woodpile_scene::parse(text, Path::new("test.toml")).unwrap()
}

/// A precompressed scaled chain -30..30 with one linear resonator at site 0.
const ONE_DEFECT: &str = r#"
[chain]
n = 30
precompression = 1.0
[[defect]]
site = 0
eps = 0.5
kappa = 0.3
"#;

/// The quartz woodpile of 40 mm rods under 1 N, every rod carrying its bending mode.
fn forty_mm_rods() -> String {
    let defects: String = (-15..=15)
        .map(|s| format!("[[defect]]\nsite = {s}\nrod = {{ length = 0.040 }}\n"))
        .collect();
    format!(
        r#"
[chain]
sites = [-15, 15]
precompression = 1.0
[physical]
material = {{ youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }}
rod = {{ length = 0.040, diameter = 0.005 }}
velocity = 0.01
[impulse]
site = -14
{defects}"#
    )
}

#[test]
fn a_scaled_resonator_defect_is_found_and_blocks_its_frequency() {
    let s = scene_spectrum(&scene(ONE_DEFECT), &SceneRequest::default()).unwrap();
    let json = summary(&s);
    assert_eq!(json["frequency_unit"], "1/time");
    assert_eq!(json["transmission"]["region"], serde_json::json!([0, 0]));
    // Hertz about F0 = 1 (a = 1): K = (3/2) F0^{1/3}; the lead's cutoff 2 sqrt(K/m).
    let cutoff = json["transmission"]["lead_cutoff"].as_f64().unwrap();
    assert!(
        (cutoff - 2.0 * 1.5_f64.sqrt() / TAU).abs() < 1e-12,
        "{cutoff}"
    );
    // The resonator (m2 = 0.5, k2 = 0.3) blocks ω0 = sqrt(0.6) in the default grid's deepest
    // point, to the grid's spacing.
    let lowest = json["transmission"]["lowest_at"].as_f64().unwrap();
    assert!((TAU * lowest - 0.6_f64.sqrt()).abs() < 2.0 * 1.5_f64.sqrt() / 400.0);
}

#[test]
fn forty_mm_quartz_rods_under_one_newton_have_their_gap_in_khz() {
    let s = scene_spectrum(&scene(&forty_mm_rods()), &SceneRequest::default()).unwrap();
    let json = summary(&s);
    assert_eq!(json["frequency_unit"], "Hz");
    assert_eq!(json["cell"]["periodic"], true);
    let gap = &json["cell"]["gaps"][0];
    let (lower, upper) = (gap[0].as_f64().unwrap(), gap[1].as_f64().unwrap());
    // Computed by hand from the rods' geometry: 8.78 to 15.32 kHz.
    assert!((lower / 8.78e3 - 1.0).abs() < 5e-3, "{lower}");
    assert!((upper / 15.32e3 - 1.0).abs() < 5e-3, "{upper}");
    assert!(json["transmission"]["skipped"]
        .as_str()
        .unwrap()
        .contains("resonator"));
    let modes = table(&s, Part::Modes).unwrap();
    let Values::I64(localised) = &modes[3].values else {
        panic!("localised is a flag")
    };
    assert_eq!(localised.len(), 62);
}

#[test]
fn frequencies_with_units_are_read_in_hz() {
    let request = SceneRequest {
        frequencies: Some((Frequency::Text("2 kHz".into()), Frequency::Number(5e3), 4)),
        ..SceneRequest::default()
    };
    let mut text = forty_mm_rods();
    // Keep rods -15 and 15 plain, so the chain has leads.
    text = text.replacen("[[defect]]\nsite = -15\nrod = { length = 0.040 }\n", "", 1);
    text = text.replacen("[[defect]]\nsite = 15\nrod = { length = 0.040 }\n", "", 1);
    let s = scene_spectrum(&scene(&text), &request).unwrap();
    let Values::F64(f) = &table(&s, Part::Transmission).unwrap()[1].values else {
        panic!("frequency is real")
    };
    assert!(
        (f[0] - 2e3).abs() < 1e-9 && (f[3] - 5e3).abs() < 1e-9,
        "{f:?}"
    );
}

#[test]
fn refusals_say_which_part_of_the_request_they_are_about() {
    let ask =
        |text: &str, request: SceneRequest| scene_spectrum(&scene(text), &request).unwrap_err();
    let vacuum = ask("[chain]\nn = 30\n", SceneRequest::default());
    assert_eq!(vacuum.asked, Asked::Scene);
    assert!(vacuum.reason.contains("sonic vacuum"), "{}", vacuum.reason);
    let cell = ask(
        ONE_DEFECT,
        SceneRequest {
            cell: Some([-30, -29]),
            ..SceneRequest::default()
        },
    );
    assert_eq!(cell.asked, Asked::Cell);
    assert!(cell.reason.contains("differs"), "{}", cell.reason);
    let units = ask(
        ONE_DEFECT,
        SceneRequest {
            frequencies: Some((Frequency::Text("1 kHz".into()), Frequency::Number(0.2), 3)),
            ..SceneRequest::default()
        },
    );
    assert_eq!(units.asked, Asked::Frequencies);
    assert!(units.reason.contains("[physical]"), "{}", units.reason);
    let band = ask(
        ONE_DEFECT,
        SceneRequest {
            frequencies: Some((Frequency::Number(0.1), Frequency::Number(1.0), 3)),
            ..SceneRequest::default()
        },
    );
    assert_eq!(band.asked, Asked::Frequencies);
    assert!(band.reason.contains("pass band"), "{}", band.reason);
}

#[test]
fn tables_have_equal_columns_in_paper_sites() {
    let s = scene_spectrum(&scene(ONE_DEFECT), &SceneRequest::default()).unwrap();
    for part in Part::LINEAR {
        let Ok(columns) = table(&s, part) else {
            assert_eq!(part, Part::Damped);
            continue;
        };
        let len = |v: &Values| match v {
            Values::F64(x) => x.len(),
            Values::I64(x) => x.len(),
        };
        let first = len(&columns[0].values);
        assert!(
            first > 0 && columns.iter().all(|c| len(&c.values) == first),
            "{part:?}"
        );
    }
    let shapes = table(&s, Part::Shapes).unwrap();
    let Values::I64(sites) = &shapes[1].values else {
        panic!("sites are integers")
    };
    assert_eq!((sites[0], sites[60]), (-30, 30));
}

/// A chain in gravity has a linear regime too: each contact's stiffness is
/// K(z) = (3/2) a δ(z)^{1/2} with δ(z) the overlap under the weight above it, so the sound
/// speed sqrt(K/m) grows with depth.
#[test]
fn a_chain_in_gravity_stiffens_with_depth() {
    let s = scene(
        "[chain]\nsites = [0, 29]\nboundary = { left = \"free\", right = \"fixed\" }\ngravity = 0.01\n[impulse]\nsite = 0\n",
    );
    let linear = crate::linearise_precompressed(&s.scenario.model, 0.0).unwrap();
    let chain = &linear.chain;
    assert_eq!(chain.stiffness(0), 0.0, "the top is free");
    for bond in 1..=30 {
        let delta = (0.01 * bond as f64).powf(2.0 / 3.0);
        let expected = 1.5 * delta.sqrt();
        let got = chain.stiffness(bond);
        assert!(
            (got - expected).abs() <= 1e-14 * expected,
            "bond {bond}: {got}"
        );
    }
    // Graded, it has no bands, no lead and no host whose stop bands localise a mode: said so,
    // rather than measured against its top site.
    let spectrum = scene_spectrum(&s, &SceneRequest::default()).unwrap();
    assert!(spectrum.analysis.modes.complete);
    let json = summary(&spectrum);
    assert!(json["cell"]["skipped"]
        .as_str()
        .unwrap()
        .contains("gravity"));
    assert!(json["transmission"]["skipped"]
        .as_str()
        .unwrap()
        .contains("gravity"));
    assert_eq!(json["modes"]["localised"], serde_json::json!([]));
    assert!(table(&spectrum, Part::Bands).is_err());
}
