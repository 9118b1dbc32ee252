//! Figures a journal accepts: printed size and type from `[style]`, legends that hide no
//! curve, log axes on non-uniform grids, and labels written as physics; checked on a small
//! study of our own and on every committed figure.
#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;

use common::{load_error, Project, REDUCE, SWEEP};
use woodpile_pipeline::table;
use woodpile_stages::KINDS;

/// The common sweep on a non-uniform grid, eps in {0.1, 0.2, 0.5, 1, 2, 5, 10}.
fn log_sweep() -> String {
    SWEEP.replace(
        "eps = { from = 0.5, to = 1.5, step = 0.5 }",
        "eps = [0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0]",
    )
}

/// The manifest summary of stage `name`'s table at `path`.
fn summary(path: &Path) -> serde_json::Value {
    table::read_manifest(path).unwrap().unwrap().summary
}

#[test]
fn a_study_on_a_log_grid_draws_with_the_documented_keys() {
    let lines = r##"
kind = "render"
inputs = ["at_end"]
title = "fractions against \\varepsilon"
x_scale = "log"
labels = { E_tr = "E_{tr}" }
style = { font_pt = 7, legend = "best" }
[lines]
x = "eps"
y = ["R", "T", "E_tr"]
panels = "L"
panel_title = "L = {value}"
x_label = "\\varepsilon = m/M"
y_label = "energy fraction"
series_style = { T = { colour = "#000000", dash = "dotted", marker = "none", label = "T (transmitted)" } }
"##;
    let map = r#"
kind = "render"
inputs = ["at_end"]
title = "E_{tr} over (\\varepsilon, L)"
x_scale = "log"
[heatmap]
x = "eps"
y = "L"
z = "E_tr"
x_label = "\\varepsilon"
y_label = "L"
z_label = "E_{tr}"
"#;
    let sweep = log_sweep();
    let p = Project::new(&[
        ("sweep", &sweep),
        ("at_end", REDUCE),
        ("lines", lines),
        ("map", map),
    ]);
    p.counted(&[]);
    let svg = std::fs::read_to_string(p.figures().join("lines.svg")).unwrap();
    assert!(
        svg.contains(r#"width="178.0mm""#),
        "two panels print at page width"
    );
    assert!(svg.contains("Eₜᵣ") && svg.contains("ε = m/M") && svg.contains("T (transmitted)"));
    assert!(
        svg.contains(">L = 0<") || svg.contains("L = 0"),
        "panel titles from panel_title"
    );
    let single = std::fs::read_to_string(p.figures().join("map.svg")).unwrap();
    assert!(
        single.contains(r#"width="86.0mm""#),
        "one panel prints at column width"
    );
    let drawn = summary(&p.output("lines"));
    assert_eq!(drawn["font_pt"], 7.0);
    assert_eq!(drawn["legend_covers_points"], serde_json::json!([0, 0]));
    // The table keeps the names, not the labels.
    let plotted = table::read(&p.output("lines")).unwrap();
    let series = table::str_column(&plotted, "series").unwrap();
    assert!(series.iter().any(|s| s.as_deref() == Some("E_tr")));
    // A wrong key is named, with what it accepts.
    for (good, bad, says) in [
        ("legend = \"best\"", "legend = \"top\"", "legend"),
        ("font_pt = 7", "font_pt = 1", "font_pt"),
        ("x_scale = \"log\"", "x_scale = \"ln\"", "x_scale"),
        ("dash = \"dotted\"", "dash = \"wavy\"", "dash"),
        (
            "x_label = \"\\\\varepsilon = m/M\"",
            "x_label = \"E_{q}\"",
            "no subscript form",
        ),
    ] {
        let stages = [
            ("sweep", sweep.as_str()),
            ("at_end", REDUCE),
            ("lines", &lines.replace(good, bad)),
        ];
        let e = load_error(&stages);
        assert!(e.contains("lines.toml") && e.contains(says), "{e}");
    }
}

/// Every committed figure prints at a journal's column or page width with text of at least
/// 7 pt, states its size in its SVG, and has no legend over a curve.
#[test]
fn committed_figures_print_at_journal_size_with_no_legend_over_a_curve() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let pipeline = woodpile_pipeline::Pipeline::load(&root.join("pipeline"), KINDS).unwrap();
    let mut checked = 0;
    for stage in pipeline.stages().iter().filter(|s| s.kind == "render") {
        let name = &stage.name;
        let drawn = summary(&root.join("results").join(format!("{name}.parquet")));
        let width = drawn["size_mm"][0].as_f64().unwrap();
        assert!(width == 86.0 || width == 178.0, "{name}: {width} mm wide");
        assert!(drawn["font_pt"].as_f64().unwrap() >= 7.0, "{name}");
        let covers = drawn["legend_covers_points"].as_array().unwrap();
        assert!(
            covers.iter().all(|c| c == 0),
            "{name}: a legend covers {covers:?}"
        );
        let svg =
            std::fs::read_to_string(root.join("figures").join(format!("{name}.svg"))).unwrap();
        assert!(svg.contains(&format!("width=\"{width:.1}mm\"")), "{name}");
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} figures");
}
