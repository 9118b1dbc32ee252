//! A point's canonical JSON, which its [`Key`](woodpile_files::key::Key) hashes. Two
//! descriptions that mean the same thing must hash the same, so scenes are hashed in their
//! *resolved* form ([`scene_json`]): a sweep that spells out a default and one that omits it
//! share their cached points.

use serde_json::{json, Map, Value};
use woodpile_scene::Scene;
use woodpile_sim::contact::{LawOf, LawParts};
use woodpile_sim::energy::RegionParts;
use woodpile_sim::integrate::{Accuracy, MethodChoice};
use woodpile_sim::model::ModelParts;
use woodpile_sim::simulation::Scenario;
use woodpile_sim::{Boundary, Coupling, Damping, End, Resonator};

/// The resolved scene as canonical JSON: everything that determines the simulated numbers and
/// nothing else (no file names, no spelling of defaults).
///
/// Every type on the way is taken apart with no `..` (the model's through
/// [`woodpile_sim::model::parts`]), so a field added anywhere in a resolved scene fails to
/// compile here until it is hashed or named as not changing a number. The chain's later keys
/// join the JSON only when a scene declares them, so that every earlier scene keeps its key
/// (and its cached point); `tests/key_coverage.rs` changes every documented key in turn.
pub fn scene_json(scene: &Scene) -> Value {
    let Scene {
        scenario,
        // The paper numbering and the SI scales only name and convert what the run computes.
        first_site: _,
        last_site: _,
        region_paper: _,
        physical: _,
    } = scene;
    let Scenario {
        model,
        impulse_site,
        impulse_velocity,
        t_end,
        region,
        method,
        accuracy,
        sample_every,
    } = scenario;
    let ModelParts {
        n_sites,
        boundary,
        resonators,
        site_masses,
        contacts,
        damping,
    } = model.parts();
    let RegionParts { lo, hi, striker } = region.parts();
    let Accuracy {
        tolerance,
        tolerance_explicit,
        dt,
    } = accuracy;
    let unit_masses = site_masses.is_none_or(|m| m.iter().all(|&m| m == 1.0));
    let mut canonical = json!({
        "sites": n_sites,
        "boundary": boundary_json(boundary),
        "masses": if unit_masses { Value::Null } else { json!(site_masses) },
        "resonators": resonators.iter().map(resonator_json).collect::<Vec<_>>(),
        "impulse": {"site": impulse_site, "velocity": impulse_velocity},
        "t_end": t_end,
        "region": [lo, hi],
        "method": method_name(*method),
        "tolerance": tolerance,
        "tolerance_explicit": tolerance_explicit,
        "dt": dt,
        "sample_every": sample_every,
    });
    if let Some(law) = contacts_json(contacts) {
        canonical["contacts"] = law;
    }
    if striker {
        canonical["striker"] = json!(true);
    }
    if let Some(damping) = damping {
        canonical["damping"] = damping_json(damping);
    }
    canonical
}

fn method_name(method: MethodChoice) -> &'static str {
    match method {
        MethodChoice::Auto => "auto",
        MethodChoice::Named(m) => m.name(),
    }
}

fn resonator_json(resonator: &Resonator) -> Value {
    let Resonator {
        site,
        eps,
        coupling,
        p,
    } = resonator;
    let kappa = match *coupling {
        Coupling::Constant(k) => json!(k),
        Coupling::Ramp { k1, k2, t0, tau } => json!({"k1": k1, "k2": k2, "t0": t0, "tau": tau}),
    };
    json!({"site": site, "eps": eps, "kappa": kappa, "p": p})
}

fn boundary_json(boundary: Boundary) -> Value {
    let end = |end: End| match end {
        End::Fixed => json!("fixed"),
        End::Free => json!("free"),
        End::Soft { spring, damping } => json!({"spring": spring, "damping": damping}),
    };
    match boundary {
        Boundary::Fixed => json!("fixed"),
        Boundary::Free => json!("free"),
        Boundary::Ends { left, right } => json!({"left": end(left), "right": end(right)}),
    }
}

/// The key's `contacts`: nothing for the paper's law (whose chain keeps the paper's key), the
/// experiment's parts, or a law only the library names by its name and numbers.
fn contacts_json(contacts: LawOf<'_>) -> Option<Value> {
    match contacts {
        LawOf::Paper => None,
        LawOf::Experiment(law) => Some(law_json(law)),
        LawOf::Named { name, numbers } => {
            let mut law = Map::new();
            law.insert("law".into(), json!(name));
            for (key, values) in numbers {
                law.insert(key.into(), json!(values));
            }
            Some(Value::Object(law))
        }
    }
}

fn law_json(law: LawParts<'_>) -> Value {
    let LawParts {
        coefficients,
        exponent,
        precompression,
        gravity,
    } = law;
    let mut contacts = json!({
        "coefficients": coefficients,
        "exponent": exponent,
        "precompression": precompression,
    });
    // Gravity joined the key after the contacts did: a chain without it keeps its key.
    if gravity > 0.0 {
        contacts["gravity"] = json!(gravity);
    }
    contacts
}

fn damping_json(damping: &Damping) -> Value {
    let Damping {
        contact,
        law,
        ground,
        resonator,
        contacts,
    } = damping;
    let mut damping = json!({
        "contact": contact,
        "law": law.name(),
        "ground": ground,
        "resonators": resonator,
    });
    // Per-contact dashpots joined the key after the rest: a chain without them keeps its key.
    if let Some(each) = contacts {
        damping["contacts"] = json!(each);
    }
    damping
}

#[cfg(test)]
mod tests {
    use super::*;
    use woodpile_files::key::Key;

    #[test]
    fn a_named_law_is_keyed_by_its_name_and_every_number() {
        use woodpile_sim::contact::ChainLaw;
        let key = |stiffness: f64, gap: f64| {
            let law = woodpile_sim::contact::LinearGap::new(vec![stiffness; 3], vec![gap; 3]);
            let law = ChainLaw::from(law.unwrap());
            Key::of(&contacts_json(law.describe()).unwrap())
        };
        assert_eq!(key(1.0, 0.1), key(1.0, 0.1));
        assert_ne!(key(1.0, 0.1), key(1.0, 0.2));
        assert_ne!(key(1.0, 0.1), key(2.0, 0.1));
        let paper = ChainLaw::default();
        assert_eq!(contacts_json(paper.describe()), None);
    }

    #[test]
    fn scenes_that_mean_the_same_hash_the_same() {
        let path = std::path::Path::new("t.toml");
        let explicit = woodpile_scene::parse(
            "[chain]\nn = 100\nboundary = \"fixed\"\n[[defect]]\nsite = 0\neps = 10.0\n",
            path,
        )
        .unwrap();
        let implicit = woodpile_scene::parse("[[defect]]\nsite = 0\neps = 10.0\n", path).unwrap();
        let other = woodpile_scene::parse("[[defect]]\nsite = 0\neps = 10.5\n", path).unwrap();
        assert_eq!(
            Key::of(&scene_json(&explicit)),
            Key::of(&scene_json(&implicit))
        );
        assert_ne!(
            Key::of(&scene_json(&explicit)),
            Key::of(&scene_json(&other))
        );
    }
}
