//! The point key sees every key a scene can set: every key the parser accepts is in
//! docs/scene.md's table; for a handful of scenes that between them use every key in that
//! table, each leaf value is changed in turn, and the changed scene must hash to a different key
//! (or fail to load, naming why). Spellings that mean the same scene must hash alike.

#![allow(clippy::unwrap_used)]

use std::collections::BTreeSet;
use std::path::Path;

use woodpile_files::Key;
use woodpile_points::canonical::scene_json;

const MATERIAL: &str = "{ youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }";

/// Scenes that, between them, use every documented key (some keys exclude others).
fn maximal_scenes() -> Vec<String> {
    let damped = r#"
[chain]
n = 12
boundary = { left = { spring = 0.5, damping = 0.1 }, right = "fixed" }
exponent = 1.6
wall_contact = 1.2
[[segment]]
sites = [3, 6]
mass = [1.0, 0.5]
contact = 1.1
damping = 0.02
[impulse]
site = -8
velocity = 1.2
[[defect]]
site = 0
eps = 2.0
kappa = 1.3
p = 1
damping = 0.01
[[defect]]
site = 2
eps = 1.5
kappa = 0.5
p = 3
[damping]
contact = 0.05
law = "hertzian"
ground = 0.001
[run]
t_end = 20.0
method = "auto"
tolerance = 1e-6
sample_every = 0.5
[fractions]
region = [-1, 3]
"#;
    let ramp = r#"
[chain]
sites = [-10, 9]
boundary = { left = "free", right = "fixed" }
[impulse]
site = -6
[[defect]]
site = 0
eps = 2.0
kappa = { k1 = 0.5, k2 = 2.5, t0 = 4.0, tau = 0.5 }
[run]
t_end = 12.0
method = "rk4"
dt = 0.01
"#;
    let loaded = r#"
[chain]
n = 10
precompression = 0.1
[[defect]]
site = 0
eps = 2.0
quality_factor = 50.0
[impulse]
site = -5
[run]
t_end = 12.0
"#;
    let struck = r#"
[chain]
n = 10
boundary = { left = "free" }
[striker]
mass = 2.0
velocity = 0.8
contact = 1.5
damping = 0.01
[[defect]]
site = 0
eps = 1.0
[run]
t_end = 12.0
"#;
    let upright = r#"
[chain]
n = 10
boundary = { left = "free", right = "fixed" }
gravity = 0.5
[[defect]]
site = 0
eps = 1.0
[impulse]
site = -10
[run]
t_end = 12.0
"#;
    let rods = format!(
        r#"
[chain]
sites = [-10, 9]
boundary = {{ left = "free", right = "free" }}
[physical]
material = {MATERIAL}
rod = {{ length = 0.020, diameter = 0.005 }}
[striker]
velocity = 1.98
sphere = {{ diameter = 0.010, material = {{ youngs_modulus = 70e9, poisson_ratio = 0.23, density = 2500.0 }} }}
restitution = {{ e = 0.8, velocity = "1.2 m/s" }}
[[defect]]
site = 0
rod = {{ length = 0.040, diameter = 0.006, material = {MATERIAL} }}
resonator_share = 0.5
[damping]
restitution = {{ e = 0.9, velocity = "1 m/s" }}
[run]
t_end = "0.2 ms"
tolerance = 1e-5
"#
    );
    let masses = r#"
[chain]
sites = [-10, 9]
boundary = "free"
[impulse]
site = -10
[physical]
contact = 2.47e9
mass = 0.866e-3
velocity = 1.98
[[segment]]
sites = [1, 3]
restitution = { e = 0.95, velocity = "0.5 m/s" }
[[defect]]
site = 0
mass = 0.838e-3
resonator_mass = 0.894e-3
stiffness = 3.961e6
[run]
t_end = "0.1 ms"
method = "rk4"
dt = "0.5 us"
sample_every = "10 us"
"#;
    [damped, ramp, loaded, struck, upright, &rods, masses]
        .map(String::from)
        .to_vec()
}

fn key_of(text: &str) -> Result<Key, String> {
    woodpile_scene::parse(text, Path::new("scene.toml"))
        .map(|scene| Key::of(&scene_json(&scene)))
        .map_err(|e| e.to_string())
}

/// Every leaf of `table` with its path (`defect[1].kappa.k1`).
fn leaves(prefix: &str, value: &toml::Value, out: &mut Vec<String>) {
    match value {
        toml::Value::Table(table) => {
            for (key, v) in table {
                let path = if prefix.is_empty() {
                    key.clone()
                } else {
                    format!("{prefix}.{key}")
                };
                leaves(&path, v, out);
            }
        }
        toml::Value::Array(items) if items.iter().all(toml::Value::is_table) => {
            for (i, v) in items.iter().enumerate() {
                leaves(&format!("{prefix}[{i}]"), v, out);
            }
        }
        _ => out.push(prefix.to_string()),
    }
}

fn get_mut<'a>(root: &'a mut toml::Value, path: &str) -> &'a mut toml::Value {
    path.split('.')
        .fold(root, |v, part| match part.split_once('[') {
            Some((name, index)) => {
                let i: usize = index.trim_end_matches(']').parse().unwrap();
                &mut v[name][i]
            }
            None => &mut v[part],
        })
}

/// Other values for a leaf, tried in turn until one loads.
fn alternatives(value: &toml::Value) -> Vec<toml::Value> {
    use toml::Value::{Array, Boolean, Float, Integer, String as Text};
    match value {
        Float(x) if *x == 0.0 => vec![Float(0.01)],
        Float(x) => vec![Float(x * 1.1), Float(x * 0.9)],
        Integer(i) => vec![Integer(i + 1), Integer(i - 1), Integer(i + 2)],
        Boolean(b) => vec![Boolean(!b)],
        Text(s) => text_alternatives(s).into_iter().map(Text).collect(),
        Array(items) => (0..items.len())
            .flat_map(|i| {
                alternatives(&items[i]).into_iter().map(move |other| {
                    let mut changed = items.clone();
                    changed[i] = other;
                    changed
                })
            })
            .map(Array)
            .collect(),
        _ => vec![],
    }
}

fn text_alternatives(text: &str) -> Vec<String> {
    let swaps: &[(&str, &[&str])] = &[
        ("fixed", &["free"]),
        ("free", &["fixed"]),
        ("linear", &["hertzian"]),
        ("hertzian", &["linear"]),
        ("auto", &["dop853", "rkn6-contact"]),
        ("rk4", &["rk4-contact", "verlet"]),
    ];
    if let Some((_, others)) = swaps.iter().find(|(from, _)| *from == text) {
        return others.iter().map(|s| s.to_string()).collect();
    }
    // A quantity with a unit: scale its number.
    let (number, unit) = text.split_once(' ').expect("a quantity with a unit");
    let x: f64 = number.parse().unwrap();
    vec![format!("{} {unit}", x * 1.1), format!("{} {unit}", x * 0.9)]
}

/// The documented key a leaf path sets: `defect[1].kappa.k1` sets `defect.kappa`.
fn without_indices(path: &str) -> String {
    let mut out = String::new();
    let mut skipping = false;
    for c in path.chars() {
        match c {
            '[' => skipping = true,
            ']' => skipping = false,
            _ if !skipping => out.push(c),
            _ => {}
        }
    }
    out
}

#[test]
fn every_leaf_of_every_maximal_scene_changes_the_key() {
    let mut ignored = Vec::new();
    // A leaf that cannot change in one scene (a striker's free left end) must in another.
    let (mut changed, mut fixed) = (BTreeSet::new(), BTreeSet::new());
    for text in maximal_scenes() {
        let base = key_of(&text).unwrap_or_else(|e| panic!("a maximal scene fails: {e}"));
        let root: toml::Value = toml::from_str(&text).unwrap();
        let mut paths = Vec::new();
        leaves("", &root, &mut paths);
        for path in paths {
            let tried = alternatives(get_mut(&mut root.clone(), &path));
            let loaded = tried.into_iter().find_map(|other| {
                let mut scene = root.clone();
                *get_mut(&mut scene, &path) = other;
                key_of(&toml::to_string(&scene).unwrap()).ok()
            });
            match loaded {
                None => {
                    fixed.insert(without_indices(&path));
                }
                Some(key) if key == base => ignored.push(path),
                Some(_) => {
                    changed.insert(without_indices(&path));
                }
            }
        }
    }
    assert!(ignored.is_empty(), "the key ignores {ignored:?}");
    let never: Vec<_> = fixed.difference(&changed).collect();
    assert!(never.is_empty(), "no scene could change {never:?}");
}

/// The keys docs/scene.md's table documents, as `section.key` without indices.
fn documented_keys() -> BTreeSet<String> {
    let docs =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/scene.md"))
            .unwrap();
    let table = docs
        .split("| key | default | meaning |")
        .nth(1)
        .expect("docs/scene.md's key table");
    let mut keys = BTreeSet::new();
    for row in table.lines().skip(2).take_while(|l| l.starts_with('|')) {
        let first = row.split('|').nth(1).unwrap();
        let mut last_full = String::new();
        for name in first.split('`').skip(1).step_by(2) {
            let full = match name.strip_prefix('.') {
                // `.right` beside `chain.boundary.left`: the sibling key.
                Some(sibling) => format!("{}.{sibling}", last_full.rsplit_once('.').unwrap().0),
                None => name.to_string(),
            };
            keys.insert(without_indices(&full));
            last_full = full;
        }
    }
    keys
}

#[test]
fn the_maximal_scenes_use_every_documented_key() {
    let mut used = Vec::new();
    for text in maximal_scenes() {
        let root: toml::Value = toml::from_str(&text).unwrap();
        let mut paths = Vec::new();
        leaves("", &root, &mut paths);
        used.extend(paths.iter().map(|p| without_indices(p)));
    }
    let documented = documented_keys();
    assert!(
        documented.len() > 40,
        "the table was not read: {documented:?}"
    );
    let missing: Vec<&String> = documented
        .iter()
        .filter(|key| {
            !used
                .iter()
                .any(|u| u == *key || u.starts_with(&format!("{key}.")))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "documented keys no maximal scene uses: {missing:?}"
    );
}

/// (A tolerance written out is not a spelling of the default: it also bounds a fixed step's
/// energy drift, see `Accuracy::tolerance_explicit`.)
#[test]
fn spellings_of_one_scene_hash_alike() {
    let alike = [
        (
            "[chain]\nn = 10\n[impulse]\nsite = -5\n",
            "[chain]\nsites = [-10, 10]\nboundary = \"fixed\"\nexponent = 1.5\n[impulse]\nsite = -5\n",
        ),
        (
            "[chain]\nn = 10\nboundary = \"free\"\n[impulse]\nsite = -5\n",
            "[chain]\nn = 10\nboundary = { left = \"free\", right = \"free\" }\n[impulse]\nsite = -5\n",
        ),
        (
            "[[defect]]\nsite = 0\neps = 2.0\n",
            "[[defect]]\nsite = 0\neps = 2.0\nkappa = 1.0\np = 1\n[impulse]\nsite = -25\nvelocity = 1.0\n[fractions]\nregion = [-1, 1]\n",
        ),
        (
            "[[defect]]\nsite = 0\neps = 2.0\n",
            "[[defect]]\nsite = 0\neps = 2.0\n[run]\nt_end = 150.0\nmethod = \"auto\"\nsample_every = 1.0\n",
        ),
        (
            "[[defect]]\nsite = 0\neps = 2.0\n",
            "[[defect]]\nsite = 0\neps = 2.0\n[damping]\ncontact = 0.0\nground = 0.0\n",
        ),
        (
            "[[defect]]\nsite = 0\neps = 2.0\n",
            "[[defect]]\nsite = 0\neps = 2.0\n[[segment]]\nsites = [-3, 3]\nmass = 1.0\ncontact = 1.0\n",
        ),
    ];
    for (short, long) in alike {
        assert_eq!(
            key_of(short).unwrap(),
            key_of(long).unwrap(),
            "{short}\nagainst\n{long}"
        );
    }
}

/// The keys the scene parser accepts (`woodpile-scene/src/raw.rs`), as `section.key` without
/// indices: each field of `SceneFile`, and of every raw struct a field holds, walked from the
/// file's text. A field of another type (a number, a list, a table read by hand) is a leaf.
fn parsed_keys() -> BTreeSet<String> {
    let raw = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../woodpile-scene/src/raw.rs"),
    )
    .unwrap();
    let mut structs: std::collections::BTreeMap<String, Vec<(String, String)>> = Default::default();
    let mut current: Option<String> = None;
    for line in raw.lines() {
        if let Some(rest) = line.strip_prefix("pub(crate) struct ") {
            current = rest.strip_suffix(" {").map(str::to_string);
        } else if line == "}" {
            current = None;
        } else if let (Some(name), Some(field)) = (&current, line.strip_prefix("    pub ")) {
            let (key, ty) = field.trim_end_matches(',').split_once(": ").unwrap();
            let inner = ty.trim_start_matches("Option<").trim_start_matches("Vec<");
            let inner = inner.trim_end_matches('>').to_string();
            structs
                .entry(name.clone())
                .or_default()
                .push((key.to_string(), inner));
        }
    }
    let mut keys = BTreeSet::new();
    let mut stack = vec![(String::new(), "SceneFile".to_string())];
    while let Some((prefix, name)) = stack.pop() {
        for (key, ty) in &structs[&name] {
            let path = format!("{prefix}{key}");
            match structs.contains_key(ty) {
                true => stack.push((format!("{path}."), ty.clone())),
                false => {
                    keys.insert(path);
                }
            }
        }
    }
    keys
}

#[test]
fn every_key_the_parser_accepts_is_documented() {
    let parsed = parsed_keys();
    assert!(
        parsed.len() > 40 && parsed.contains("damping.restitution.e"),
        "raw.rs was not read: {parsed:?}"
    );
    let documented = documented_keys();
    // A documented key names a leaf, or a table whose keys the table's row lists.
    let undocumented: Vec<&String> = parsed
        .iter()
        .filter(|key| {
            !documented.iter().any(|d| {
                d == *key || key.starts_with(&format!("{d}.")) || d.starts_with(&format!("{key}."))
            })
        })
        .collect();
    assert!(
        undocumented.is_empty(),
        "keys the parser accepts that docs/scene.md's table does not document: {undocumented:?}"
    );
}
