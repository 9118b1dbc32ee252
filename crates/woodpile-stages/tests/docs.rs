//! `docs/stage-kinds.md` is generated from the module documentation of every stage kind
//! (`crates/woodpile-stages/src/<kind>.rs`, or `<kind>/mod.rs`, the one place each kind's keys
//! are described), so the reference a user reads cannot drift from the code. This test fails when it is out of date;
//! `UPDATE_DOCS=1 cargo test -p woodpile-stages --test docs` (or `make docs`) rewrites it.
#![allow(clippy::unwrap_used)]

use std::path::Path;
use woodpile_stages::KINDS;

fn module_doc(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .take_while(|l| l.starts_with("//!"))
        .map(|l| {
            l.strip_prefix("//! ")
                .unwrap_or(l.strip_prefix("//!").unwrap_or(l))
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn generated() -> String {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = String::from(
        "# Stage kinds\n\n<!-- Generated from the module documentation of each kind \
         (crates/woodpile-stages/src/<kind>.rs) by `make docs`; do not edit by hand. -->\n\n\
         Every stage file takes the common keys below; the rest belong to its kind. Unknown keys \
         are errors that name the file and the key.\n\n",
    );
    out.push_str(&module_doc(
        &src.join("../../woodpile-pipeline/src/stage.rs"),
    ));
    out.push('\n');
    for kind in woodpile_stages::names() {
        out.push_str(&format!("\n## `{kind}`\n\n"));
        let file = src.join(format!("{kind}.rs"));
        let file = match file.exists() {
            true => file,
            false => src.join(kind).join("mod.rs"),
        };
        out.push_str(&module_doc(&file));
        out.push('\n');
    }
    out
}

#[test]
fn the_stage_kind_reference_is_generated_from_the_code() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/stage-kinds.md");
    assert_generated(&path, &generated(), "docs/stage-kinds.md is out of date");
}

/// Asserts that the file at `path` holds `expected`, after writing it there when `UPDATE_DOCS`
/// is set (`make docs`); `stale` says what is wrong when it does not.
fn assert_generated(path: &Path, expected: &str, stale: &str) {
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(path, expected).unwrap();
    }
    let current = std::fs::read_to_string(path).unwrap_or_default();
    assert!(current == expected, "{stale}: run `make docs`");
}

/// The accuracy each README figure was computed to: for every stage upstream of the figure that
/// simulates (sweeps, space-time maps, varied optima, the design search), the tolerance and the largest error
/// estimate its manifest in `results/` records. `None` for a figure with no such stage.
fn accuracy_caption(
    pipeline: &woodpile_pipeline::Pipeline,
    results: &Path,
    figure: &str,
) -> Option<String> {
    use woodpile_pipeline::table;
    let mut seen = std::collections::BTreeSet::new();
    let mut stack = vec![figure.to_string()];
    while let Some(name) = stack.pop() {
        if seen.insert(name.clone()) {
            stack.extend(pipeline.stage(&name).unwrap().inputs.iter().cloned());
        }
    }
    let parts: Vec<String> = seen
        .iter()
        .filter_map(|name| {
            let manifest = table::read_manifest(&results.join(format!("{name}.parquet")))
                .unwrap()
                .unwrap_or_else(|| panic!("results/{name}.parquet has no manifest"));
            let number = |key: &str| manifest.summary.get(key).and_then(|v| v.as_f64());
            match manifest.kind.as_str() {
                "sweep" | "spacetime" | "vary" => Some(format!(
                    "`{name}` at tolerance {:e}, largest error estimate {:.1e}",
                    number("tolerance")?,
                    number("max_error_estimate")?
                )),
                "design" => Some(format!(
                    "`{name}` best design verified at tolerance {:e}, error estimate {:.1e}",
                    number("verify_tolerance")?,
                    number("best_error_estimate")?
                )),
                _ => None,
            }
        })
        .collect();
    (!parts.is_empty()).then(|| format!("*Accuracy: {}.*", parts.join("; ")))
}

/// The README's figure captions end with the accuracy of what they draw, read from the
/// manifests of `results/` (so a caption cannot keep a number the results no longer have).
/// `UPDATE_DOCS=1` (`make docs`) rewrites them.
#[test]
fn readme_captions_state_the_accuracy_of_the_committed_results() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let pipeline = woodpile_pipeline::Pipeline::load(&root.join("pipeline"), KINDS).unwrap();
    let readme_path = root.join("README.md");
    let readme = std::fs::read_to_string(&readme_path).unwrap();
    let mut expected = String::new();
    for line in readme.lines() {
        let figure = line
            .strip_prefix("| ![")
            .and_then(|rest| rest.split("(figures/").nth(1))
            .and_then(|rest| rest.split(".png)").next());
        let rewritten =
            match figure.and_then(|f| accuracy_caption(&pipeline, &root.join("results"), f)) {
                Some(caption) => {
                    let body = line.trim_end().strip_suffix('|').unwrap().trim_end();
                    let body = body.split(" *Accuracy:").next().unwrap();
                    format!("{body} {caption} |")
                }
                None => line.to_string(),
            };
        expected.push_str(&rewritten);
        expected.push('\n');
    }
    assert_generated(
        &readme_path,
        &expected,
        "README.md's figure captions do not state the accuracy of results/",
    );
}
