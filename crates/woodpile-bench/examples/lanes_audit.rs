//! The audit of the SIMD lanes' promise: every scene run four at a time in lanes
//! (`woodpile_sim::simulation::simulate_batch`) gives its scalar run's result bit for bit.
//! Random groups of four neighbouring points (`woodpile_sim::testing::lane_neighbours`:
//! the impulse's site two apart, one group in four with one lane's resonators a thousandth
//! lighter) around the `auto` audit's scenes, with `--chain` the experiment's chain's
//! (striker, precompression, alternating masses and contacts, any exponent), or with `--gap`
//! chains of gapped linear contacts (`woodpile_sim::testing::gap_audit_scene`), at the given
//! tolerances, each run by `simulate_batch` and by `simulate` alone. A group whose outcome or
//! samples differ in any bit is a `MISS`, and the exit status is 1.
//!
//! ```text
//! cargo run --release -p woodpile-bench --example lanes_audit [-- [--chain | --gap] GROUPS [SEED [TOLERANCES]]]
//! cargo run --release -p woodpile-bench --example lanes_audit -- 100 2026 1e-5,1e-6,1e-7,1e-8
//! ```
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use woodpile_bench::on_two_cores;
use woodpile_sim::integrate::lanes::shares_a_chain;
use woodpile_sim::integrate::{MethodChoice, Plan};
use woodpile_sim::simulation::{auto_first_step, Scenario};
use woodpile_sim::testing::{
    audit_scene, by_lanes_and_alone, chain_audit_scene, gap_audit_scene, lane_neighbours,
    tolerance, Lcg,
};
use woodpile_sim::Model;

/// What one group gave: whether it took lanes, and whether every scene matched.
struct Group {
    in_lanes: bool,
    identical: bool,
    line: String,
}

/// Whether `scenes` form a lane group: `auto`, one method and first step, one chain.
fn takes_lanes(scenes: &[Scenario]) -> bool {
    let first: Vec<_> = scenes
        .iter()
        .map(|s| {
            let plan = Plan::choose(&s.model, s.method, s.accuracy).ok()?;
            Some((plan.method, auto_first_step(s, &plan)))
        })
        .collect();
    let models: Vec<&Model> = scenes.iter().map(|s| &s.model).collect();
    let auto = scenes.iter().all(|s| s.method == MethodChoice::Auto);
    auto && first[0].is_some()
        && first.iter().all(|f| *f == first[0])
        && shares_a_chain(&models[..].try_into().unwrap())
}

/// Group `k`: its scenes by lanes and alone, compared.
fn audit(k: usize, scenes: &[Scenario]) -> Group {
    let runs = by_lanes_and_alone(scenes);
    let identical = runs.iter().all(|(lanes, alone)| lanes == alone);
    let in_lanes = takes_lanes(scenes);
    let outcome = match &runs[0].0 .0 {
        Ok(out) => format!("{} dt {:.4}", out.plan.method.name(), out.stats.max_step),
        Err(e) => format!("error: {e}"),
    };
    let verdict = if identical { "same" } else { "MISS" };
    let line = format!(
        "{k:>4} | lanes {in_lanes:<5} | tol {:.0e} | {outcome} | {verdict}",
        scenes[0].accuracy.tolerance
    );
    Group {
        in_lanes,
        identical,
        line,
    }
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let (draw, kind): (fn(&mut Lcg) -> Scenario, _) = match args.first().map(String::as_str) {
        Some("--chain") => (chain_audit_scene, "the experiment's chain"),
        Some("--gap") => (gap_audit_scene, "gapped linear contacts"),
        _ => (audit_scene, "audit scenes"),
    };
    if args.first().is_some_and(|a| a.starts_with("--")) {
        args.remove(0);
    }
    let groups: usize = args.first().map_or(40, |a| a.parse().unwrap());
    let seed: u64 = args.get(1).map_or(2026, |a| a.parse().unwrap());
    let tolerances: Vec<f64> = args.get(2).map_or(vec![1e-5, 1e-6], |a| {
        a.split(',').map(|t| t.parse().unwrap()).collect()
    });
    let mut rng = Lcg(seed);
    let cases: Vec<Vec<Scenario>> = (0..groups)
        .map(|k| {
            let base = draw(&mut rng);
            let base = Scenario {
                accuracy: tolerance(tolerances[k % tolerances.len()]),
                ..base
            };
            lane_neighbours(&base, k)
        })
        .collect();
    let indexed: Vec<(usize, &Vec<Scenario>)> = cases.iter().enumerate().collect();
    let results = on_two_cores(&indexed, |(k, scenes)| audit(*k, scenes));
    for r in &results {
        println!("{}", r.line);
    }
    let in_lanes = results.iter().filter(|r| r.in_lanes).count();
    let misses = results.iter().filter(|r| !r.identical).count();
    println!(
        "\n{groups} groups of four ({kind}, seed {seed}): {in_lanes} took lanes; {misses} differ from their scenes run alone"
    );
    if misses > 0 {
        std::process::exit(1);
    }
}
