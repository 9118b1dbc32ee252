//! `make bench`: woodpile's RK4 and its other methods on the standard scene, timed in the same
//! run as the C and numba RK4 baselines of `baseline/`, with the ratios. Prints a Markdown table
//! (the README's) and one JSON line per row on stderr.
//!
//! Then the paper-level comparison ([`woodpile_bench::paper`]): a seeded sample of the F4, F7
//! coarse and F7 fine sweeps' scenes, woodpile at the pipeline's settings against the numba
//! script at RK4 dt = 0.01, one thread each.
//!
//! Then, with `--sweeps`, the paper's five sweeps whole against the same script on every core
//! ([`woodpile_bench::sweeps`]), and with `--whole-paper` the whole pipeline from a cold cache
//! against the script's sweeps: the ratios the speed targets are stated in.
//!
//! ```text
//! woodpile-bench [--c PATH_TO_C_BINARY] [--numba PATH_TO_SCRIPT] [--numba-scenes PATH]
//!                [--repeats N] [--paper SCENES_PER_SWEEP] [--seed SEED]
//!                [--sweeps [--sweep-points N]] [--whole-paper]
//! ```
//!
//! Accuracy is |ΔE_tr| against a reference (Yoshida-6 at dt = 2.5e-4, whose own error is about
//! 1e-11: it agrees with RK4 at dt = 5e-4 to that). Wall time is the best of `repeats` runs.
#![allow(clippy::print_stdout)]

use std::process::Command;
use std::time::Instant;

use serde_json::Value;
use woodpile_bench::{fixed, paper, run, standard_scene, sweeps};
use woodpile_sim::integrate::{Method, MethodChoice, Plan};
use woodpile_sim::simulation::{run_with_plan, Scenario};
use woodpile_sim::testing::{fixed_dt, tolerance};

struct Row {
    implementation: String,
    setting: String,
    error: f64,
    ms: f64,
}

fn best_ms(repeats: usize, mut f: impl FnMut() -> f64) -> (f64, f64) {
    let mut best = f64::INFINITY;
    let mut value = f64::NAN;
    for _ in 0..repeats {
        let t0 = Instant::now();
        value = f();
        best = best.min(t0.elapsed().as_secs_f64() * 1e3);
    }
    (best, value)
}

fn trapped(scene: &Scenario) -> f64 {
    run(scene).map_or(f64::NAN, |o| o.fractions.trapped)
}

fn full_chain(scene: &Scenario, method: Method, dt: f64) -> f64 {
    Plan::choose(&scene.model, MethodChoice::Named(method), fixed_dt(dt))
        .and_then(|plan| run_with_plan(scene, &plan, &mut (), false))
        .map_or(f64::NAN, |o| o.fractions.trapped)
}

/// Runs a baseline command that prints one JSON line with `E_tr` and `ms`.
fn baseline(program: &str, args: &[&str]) -> Result<(f64, f64, String), String> {
    let out = Command::new(program)
        .args(args)
        .output()
        .map_err(|e| format!("{program}: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{program} failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().last().unwrap_or_default();
    let v: Value = serde_json::from_str(line).map_err(|e| format!("{program}: {e}: {line}"))?;
    let get = |k: &str| {
        v.get(k)
            .and_then(Value::as_f64)
            .ok_or(format!("{program}: no `{k}`"))
    };
    let name = v
        .get("implementation")
        .and_then(Value::as_str)
        .unwrap_or(program)
        .to_string();
    Ok((get("E_tr")?, get("ms")?, name))
}

fn main() {
    woodpile_scene::cpu::apply_environment();
    let args: Vec<String> = std::env::args().collect();
    let option = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let repeats: usize = option("--repeats")
        .and_then(|r| r.parse().ok())
        .unwrap_or(10);

    let reference = trapped(&fixed(Method::Yoshida6, 2.5e-4));
    let check = trapped(&fixed(Method::Rk4, 5e-4));
    println!(
        "standard scene (N = 100, eps = 10, t = 150): reference E_tr = {reference:.12} \
         (yoshida6, dt = 2.5e-4; |ref - rk4(dt = 5e-4)| = {:.1e}); best of {repeats} runs\n",
        (reference - check).abs()
    );
    let mut rows = our_rows(repeats, reference);
    let reference_ms = baseline_rows(
        (option("--c"), option("--numba")),
        repeats,
        reference,
        &mut rows,
    );
    print_rows(&rows, &reference_ms);

    // 34 scenes of each of three sweeps: a sample of 102, drawn afresh each day unless a seed
    // is given, so that no sample is the one the code was tuned on.
    let per_sweep: usize = option("--paper").and_then(|n| n.parse().ok()).unwrap_or(34);
    let seed: u64 = option("--seed")
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(todays_seed);
    if per_sweep > 0 {
        paper_level(per_sweep, seed, option("--numba-scenes").as_deref());
    }
    if args.iter().any(|a| a == "--sweeps") {
        let points = match option("--sweep-points").map(|n| n.parse::<usize>()) {
            None => None,
            Some(Ok(n)) if n > 0 => Some(n),
            Some(_) => {
                eprintln!("--sweep-points takes a whole number above 0");
                std::process::exit(2);
            }
        };
        let whole = args.iter().any(|a| a == "--whole-paper");
        if whole && points.is_some() {
            eprintln!("note: --whole-paper is not run with --sweep-points (a quick look)");
        }
        paper_sweeps(option("--numba-scenes").as_deref(), points, whole);
    }
}

/// woodpile's rows on the standard scene: each method at its steps, `auto`, and the full
/// chain without the active window; `reference` is the converged E_tr.
fn our_rows(repeats: usize, reference: f64) -> Vec<Row> {
    let mut rows = Vec::new();
    let mut ours = |setting: &str, ms_value: (f64, f64)| {
        rows.push(Row {
            implementation: "woodpile".into(),
            setting: setting.into(),
            error: (ms_value.1 - reference).abs(),
            ms: ms_value.0,
        });
    };
    for (method, dt) in [
        (Method::Rk4, 0.01),
        (Method::Rk4, 0.02),
        (Method::Rk4Contact, 0.05),
        (Method::Rk4Contact, 0.06),
        (Method::Rk4Contact, 0.075),
        (Method::Rkn4Contact, 0.05),
        (Method::Rkn4Contact, 0.06),
        (Method::Rkn4Contact, 0.1),
        (Method::Yoshida4, 0.01),
        (Method::Yoshida6, 0.02),
        (Method::Verlet, 0.005),
    ] {
        let scene = fixed(method, dt);
        ours(
            &format!("{} dt = {dt}", method.name()),
            best_ms(repeats, || trapped(&scene)),
        );
    }
    let scene = fixed(Method::Rkn6Contact, 0.1);
    ours(
        "rkn6-contact dt = 0.1",
        best_ms(repeats, || trapped(&scene)),
    );
    let auto = standard_scene(MethodChoice::Auto, tolerance(1e-7));
    ours("auto, tolerance 1e-7", best_ms(repeats, || trapped(&auto)));
    let scene = fixed(Method::Rk4, 0.01);
    ours(
        "rk4 dt = 0.01, full chain (no active window)",
        best_ms(repeats, || full_chain(&scene, Method::Rk4, 0.01)),
    );
    rows
}

/// The C and numba baselines given (`--c`, `--numba`), each run in this run, as rows; their
/// names and times, which every row is divided by.
fn baseline_rows(
    (c_binary, numba_script): (Option<String>, Option<String>),
    repeats: usize,
    reference: f64,
    rows: &mut Vec<Row>,
) -> Vec<(String, f64)> {
    let mut baselines = Vec::new();
    let repeats_text = repeats.to_string();
    if let Some(c) = &c_binary {
        baselines.push(baseline(c, &["0.01", &repeats_text]));
    }
    if let Some(script) = &numba_script {
        baselines.push(baseline("python3", &[script, "0.01", &repeats_text]));
    }
    let mut reference_ms: Vec<(String, f64)> = Vec::new();
    for b in baselines {
        match b {
            Ok((e_tr, ms, name)) => {
                reference_ms.push((name.clone(), ms));
                rows.push(Row {
                    implementation: name,
                    setting: "rk4 dt = 0.01, full chain".into(),
                    error: (e_tr - reference).abs(),
                    ms,
                });
            }
            Err(e) => eprintln!("baseline skipped: {e}"),
        }
    }
    reference_ms
}

/// The rows as a Markdown table on stdout (a ratio column per baseline) and as JSON lines on
/// stderr.
fn print_rows(rows: &[Row], reference_ms: &[(String, f64)]) {
    let mut header = "| implementation | setting | abs error E_tr | wall ms |".to_string();
    let mut rule = "|---|---|---|---|".to_string();
    for (name, _) in reference_ms {
        header.push_str(&format!(" time / {name} |"));
        rule.push_str("---|");
    }
    println!("{header}\n{rule}");
    for r in rows {
        let mut line = format!(
            "| {} | {} | {:.1e} | {:.2} |",
            r.implementation, r.setting, r.error, r.ms
        );
        for (_, ms) in reference_ms {
            line.push_str(&format!(" {:.2} |", r.ms / ms));
        }
        println!("{line}");
        eprintln!(
            "{}",
            serde_json::json!({"implementation": r.implementation, "setting": r.setting,
                "abs_error_E_tr": r.error, "ms": r.ms})
        );
    }
}

/// The paper-level comparison, printed as a table.
/// Today's date as a seed, `YYYYMMDD` (UTC): a new paper sample every day.
fn todays_seed() -> u64 {
    let days = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() / 86_400);
    let (year, month, day) = civil_from_days(days as i64);
    (year as u64) * 10_000 + month * 100 + day
}

/// The Gregorian date of `days` since 1970-01-01 (Howard Hinnant's `civil_from_days`).
fn civil_from_days(days: i64) -> (i64, u64, u64) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097) as u64;
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe as i64 + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

fn paper_level(per_sweep: usize, seed: u64, numba_script: Option<&str>) {
    let scenes = match paper::paper_sample("pipeline", per_sweep, seed) {
        Ok(scenes) => scenes,
        Err(e) => {
            eprintln!("paper-level comparison skipped: {e}");
            return;
        }
    };
    let c = paper::compare(&scenes, numba_script);
    println!(
        "\npaper-level sample: {} scenes ({per_sweep} each of F4, F7 coarse, F7 fine; seed {seed}, \
         --seed to repeat it), one thread each, the first pass and the best of {}; errors = \
         largest of R, T, E_tr against rk4-contact at dt = 0.001\n",
        c.scenes,
        paper::REPEATS
    );
    println!("| implementation | worst error | first pass ms (sum) | best pass ms (sum) | first / numba's first | best / numba's best |");
    println!("|---|---|---|---|---|---|");
    let numba = c.numba.as_ref().ok().map(|n| (n.first_ms, n.ms));
    let mut sides: Vec<&paper::Side> = c.woodpile.iter().collect();
    if let Ok(n) = &c.numba {
        sides.push(n);
    }
    for side in sides {
        let ratio = |ours: f64, theirs: Option<f64>| {
            theirs.map_or("–".to_string(), |n| format!("{:.3}", ours / n))
        };
        println!(
            "| {} | {:.1e} | {:.1} | {:.1} | {} | {} |",
            side.name,
            side.worst_error,
            side.first_ms,
            side.ms,
            ratio(side.first_ms, numba.map(|n| n.0)),
            ratio(side.ms, numba.map(|n| n.1)),
        );
    }
    if let Err(e) = &c.numba {
        eprintln!("numba side skipped: {e}");
    }
}

/// The paper's sweeps against the numba script, and the whole paper when asked, as tables.
fn paper_sweeps(numba_script: Option<&str>, max_points: Option<usize>, whole_paper: bool) {
    let pipeline = std::path::Path::new("pipeline");
    let scratch = sweeps::Scratch::new();
    let timings = match sweeps::time_sweeps(pipeline, numba_script, max_points, &scratch) {
        Ok(timings) => timings,
        Err(e) => return eprintln!("sweep comparison skipped: {e}"),
    };
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let how = match max_points {
        None => "each sweep stage run whole into an empty results tree".to_string(),
        Some(n) => format!("at most {n} points of each grid, woodpile's simulate alone"),
    };
    println!(
        "\nthe paper's sweeps, {how}; numba RK4 dt = 0.01 on the full chain in {cores} \
         processes; both on {cores} cores, in this run\n"
    );
    println!("| sweep | points | woodpile s | numba s | numba / woodpile | numba's largest difference from woodpile |");
    println!("|---|---|---|---|---|---|");
    let (mut ours, mut theirs) = (0.0, Some(0.0));
    for t in &timings {
        let numba = t.numba_s.as_ref().ok().copied();
        let differs = match (t.numba_worst, t.numba_failed) {
            (None, 0) => "–".to_string(),
            (None, failed) => format!("none finite ({failed} not finite)"),
            (Some(d), 0) => format!("{d:.1e}"),
            (Some(d), failed) => format!("{d:.1e} ({failed} not finite)"),
        };
        println!(
            "| {} | {} | {:.1} | {} | {} | {differs} |",
            t.label,
            t.points,
            t.woodpile_s,
            numba.map_or("–".into(), |n| format!("{n:.1}")),
            numba.map_or("–".into(), |n| format!("{:.2}x", n / t.woodpile_s)),
        );
        ours += t.woodpile_s;
        theirs = theirs.zip(numba).map(|(a, b)| a + b);
        if let Err(e) = &t.numba_s {
            eprintln!("{}: numba side skipped: {e}", t.label);
        }
    }
    let ratio = |n: Option<f64>, w: f64| n.map_or("–".into(), |n| format!("{:.2}x", n / w));
    let shown = theirs.map_or("–".into(), |n| format!("{n:.1}"));
    println!(
        "| all five | {} | {ours:.1} | {shown} | {} | |",
        timings.iter().map(|t| t.points).sum::<usize>(),
        ratio(theirs, ours)
    );
    if whole_paper && max_points.is_none() {
        match sweeps::time_whole_paper(pipeline, &scratch) {
            Ok(s) => println!(
                "\nthe whole paper (every stage and figure, cold): {s:.1} s; \
                 the numba sweeps alone / the whole paper = {}",
                ratio(theirs, s)
            ),
            Err(e) => eprintln!("whole-paper run failed: {e}"),
        }
    }
}
