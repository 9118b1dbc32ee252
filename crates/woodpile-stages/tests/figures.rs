//! The kinds behind the figures: render (single and composite), fit, the product
//! approximation, space-time fields, and a fit that fails without stopping the run.
#![allow(clippy::unwrap_used)]

mod common;

use common::{
    load_error, load_error_after_reduce, single_defect_sweep_to, sweep_file, Counter, Project,
    FIGURE, REDUCE, SWEEP,
};
use woodpile_pipeline::run::{run, RunOptions};
use woodpile_pipeline::status::State;
use woodpile_pipeline::{table, PipelineError};

#[test]
fn render_stages_draw_figures_and_keep_the_plotted_numbers() {
    let figure = FIGURE
        .replace("TITLE", "test figure")
        .replace("[lines]", "[lines]\npanels = \"L\"");
    let heat = r#"
kind = "render"
inputs = ["at_end"]
title = "test map"
[heatmap]
x = "eps"
y = "L"
z = "E_tr"
x_label = "eps"
y_label = "L"
z_label = "E_tr"
mark_max = true
"#;
    let p = Project::new(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        ("figure", &figure),
        ("map", heat),
    ]);
    p.counted(&[]);
    let figures = p.figures();
    for name in ["figure.png", "figure.svg", "map.png", "map.svg"] {
        assert!(figures.join(name).exists(), "{name}");
    }
    // The table holds exactly the plotted numbers: a row per curve point, per panel.
    let plotted = table::read(&p.output("figure")).unwrap();
    let names: Vec<String> = plotted
        .get_column_names()
        .iter()
        .map(|n| n.to_string())
        .collect();
    // Each number under the name of the column it was drawn from.
    assert_eq!(names, ["panel", "series", "eps", "R", "E_tr"]);
    let reduced = table::read(&p.output("at_end")).unwrap();
    assert_eq!(
        plotted.height(),
        2 * reduced.height(),
        "R and E_tr of every row"
    );
    let (x, y) = (
        table::f64_column(&plotted, "eps").unwrap(),
        table::f64_column(&plotted, "E_tr").unwrap(),
    );
    let series = table::str_column(&plotted, "series").unwrap();
    let (eps, e_tr) = (
        table::f64_column(&reduced, "eps").unwrap(),
        table::f64_column(&reduced, "E_tr").unwrap(),
    );
    let drawn: Vec<(Option<f64>, Option<f64>)> = (0..plotted.height())
        .filter(|&r| series[r].as_deref() == Some("E_tr"))
        .map(|r| (x[r], y[r]))
        .collect();
    for pair in eps.iter().zip(&e_tr) {
        assert!(drawn.contains(&(*pair.0, *pair.1)), "{pair:?} not drawn");
    }
    // A deleted figure makes its stage stale, and only that stage re-runs.
    std::fs::remove_file(figures.join("map.svg")).unwrap();
    assert!(matches!(p.state("map"), State::Stale(why) if why[0].contains("map.svg")));
    assert_eq!(
        *p.counted(&[]).started.lock().unwrap(),
        vec!["map".to_string()]
    );
    let e = load_error_after_reduce("f", &figure.replace("[lines]", "[bars]"));
    assert!(e.contains("f.toml") && e.contains("bars"), "{e}");
}

#[test]
fn fit_stages_fit_the_forms_and_report_the_papers_coefficients_on_our_data() {
    let fit = r#"
kind = "fit"
inputs = ["at_end"]
x = "eps"
where = { L = 1 }
[[model]]
name = "R"
y = "R"
form = "tanh"
start = [0.5, 0.5, 0.0]
paper = [0.5491, 0.0830, 0.0760]
"#;
    let wide = SWEEP.replace(
        "eps = { from = 0.5, to = 1.5, step = 0.5 }",
        "eps = { from = 0.5, to = 4.0, step = 0.5 }",
    );
    let p = Project::new(&[("sweep", &wide), ("at_end", REDUCE), ("fit", fit)]);
    p.counted(&[]);
    let out = table::read(&p.output("fit")).unwrap();
    let col = |c: &str| table::f64_column(&out, c).unwrap()[0].unwrap();
    assert_eq!(col("n"), 8.0, "only the L = 1 rows");
    // The fitted curve reproduces the data it was fitted to: recompute its residual here.
    let data = table::read(&p.output("at_end")).unwrap();
    let (l, eps, r) = (
        table::f64_column(&data, "L").unwrap(),
        table::f64_column(&data, "eps").unwrap(),
        table::f64_column(&data, "R").unwrap(),
    );
    let (a, b, c) = (col("A"), col("B"), col("C"));
    let (mut ssr, mut norm) = (0.0, 0.0);
    for i in (0..l.len()).filter(|&i| l[i] == Some(1.0)) {
        ssr += (a * (b * eps[i].unwrap()).tanh() + c - r[i].unwrap()).powi(2);
        norm += r[i].unwrap().powi(2);
    }
    assert!((col("relative_error") - (ssr / norm).sqrt()).abs() < 1e-12);
    assert!(
        col("relative_error") <= col("paper_relative_error"),
        "LM beats any other coefficients"
    );
    assert!(col("se_A") > 0.0);
    let e = load_error_after_reduce("fit", &fit.replace("\"tanh\"", "\"cubic\""));
    assert!(e.contains("model[0].form") && e.contains("cubic"), "{e}");
}

#[test]
fn the_product_approximation_evaluates_the_fitted_forms() {
    let single = single_defect_sweep_to(4.0);
    let fits = r#"
kind = "fit"
x = "eps"
inputs = ["single_at_end"]
model = [
  { name = "T1", y = "T", form = "power", start = [0.5, -0.3, 0.2] },
  { name = "R", y = "R", form = "tanh", start = [0.5, 0.5, 0.0] },
]
"#;
    let pair = &sweep_file(
        "eps1 = [1.0, 2.0]\neps2 = [1.0, 2.0]",
        12,
        (12.0, 0.02, 2.0),
        &[(0, "$eps1"), (3, "$eps2")],
    );
    let approx = r#"
kind = "approximate"
inputs = ["fits", "pair_at_end"]
transmission = "T1"
reflection = "R"
axes = ["eps1", "eps2"]
numerics = "E_tr"
"#;
    let p = Project::new(&[
        ("single", &single),
        ("single_at_end", &REDUCE.replace("\"sweep\"", "\"single\"")),
        ("fits", fits),
        ("pair", pair),
        ("pair_at_end", &REDUCE.replace("\"sweep\"", "\"pair\"")),
        ("approx", approx),
    ]);
    p.counted(&[]);
    let f = table::read(&p.output("fits")).unwrap();
    let coef = |c: &str, row: usize| table::f64_column(&f, c).unwrap()[row].unwrap();
    let t1 = |x: f64| coef("A", 0) * x.powf(coef("B", 0)) + coef("C", 0);
    let r = |x: f64| coef("A", 1) * (coef("B", 1) * x).tanh() + coef("C", 1);
    let out = table::read(&p.output("approx")).unwrap();
    let col = |c: &str| table::f64_column(&out, c).unwrap();
    let (e1, e2, values, diag) = (col("eps1"), col("eps2"), col("approx"), col("on_diagonal"));
    assert_eq!(values.len(), 4);
    for i in 0..4 {
        let (a, b) = (e1[i].unwrap(), e2[i].unwrap());
        assert!((values[i].unwrap() - t1(a) * r(b) * r(a) * r(b)).abs() < 1e-14);
        assert_eq!(diag[i], Some(if a == b { 1.0 } else { 0.0 }));
    }
    assert!(
        col("approx_paper").iter().all(Option::is_none),
        "no paper coefficients given"
    );
    let manifest = table::read_manifest(&p.output("approx")).unwrap().unwrap();
    assert!(manifest.summary["relative_error"].as_f64().unwrap() > 0.0);
    let swapped = approx.replace("[\"fits\", \"pair_at_end\"]", "[\"pair_at_end\", \"fits\"]");
    let e = load_error(&[
        ("single", &single),
        ("single_at_end", &REDUCE.replace("\"sweep\"", "\"single\"")),
        ("fits", fits),
        ("pair", pair),
        ("pair_at_end", &REDUCE.replace("\"sweep\"", "\"pair\"")),
        ("approx", &swapped),
    ]);
    assert!(
        e.contains("approx.toml") && e.contains("expected [a fit stage, a reduce stage]"),
        "{e}"
    );
}

#[test]
fn spacetime_stages_record_velocities_on_the_requested_sites() {
    let field = r#"
kind = "spacetime"
[axes]
L = [0, 1]
[scene]
chain = { n = 12 }
impulse = { site = -6, velocity = 1.0 }
run = { t_end = 12.0, method = "rk4", dt = 0.02, sample_every = 2.0 }
[[scene.defect]]
site = 0
through = "$L"
eps = 2.0
[field]
sites = [-8, 8]
"#;
    let p = Project::new(&[("field", field)]);
    p.counted(&[]);
    let out = table::read(&p.output("field")).unwrap();
    assert_eq!(out.height(), 2 * 7 * 17, "points x samples x sites");
    let (t, site, v) = (
        table::f64_column(&out, "t").unwrap(),
        table::f64_column(&out, "site").unwrap(),
        table::f64_column(&out, "velocity").unwrap(),
    );
    for i in 0..out.height() {
        let s = site[i].unwrap();
        assert!((-8.0..=8.0).contains(&s));
        if t[i] == Some(0.0) {
            assert_eq!(v[i].unwrap(), if s == -6.0 { 1.0 } else { 0.0 });
        }
    }
    let e = load_error(&[(
        "field",
        &field.replace("sites = [-8, 8]", "sites = [-80, 8]"),
    )]);
    assert!(e.contains("field.sites"), "{e}");
}

/// A composite figure draws panels from several inputs, with marks, a diverging map and a
/// title that quotes an input's parameters; a quote of a stage that is not an input, or an
/// unknown panel input, is refused at load.
#[test]
fn composite_figures_draw_several_inputs_and_quote_their_parameters() {
    let composite = r#"
kind = "render"
inputs = ["sweep", "at_end"]
title = "read out at t = {at_end.params.at}, tolerance {sweep.summary.tolerance}"
columns = 2
same_colour_scale = true

[[panel]]
input = "at_end"
title = "fractions at L = 0"
where = { L = 0 }
mark = [{ x = 1.0, label = "eps = 1" }]
[panel.lines]
x = "eps"
y = ["R", "T", "E_tr"]
x_label = "eps"
y_label = "fraction"

[[panel]]
input = "sweep"
where = { L = 1 }
[panel.heatmap]
x = "t"
y = "eps"
z = "E_tr"
colours = "diverging"
x_label = "t"
y_label = "eps"
z_label = "E_tr"
"#;
    let p = Project::new(&[("sweep", SWEEP), ("at_end", REDUCE), ("both", composite)]);
    p.counted(&[]);
    let manifest = table::read_manifest(&p.output("both")).unwrap().unwrap();
    assert_eq!(
        manifest.summary["title"],
        "read out at t = 12, tolerance 0.00000001"
            .replace("0.00000001", &woodpile_plot::tick(&1e-8))
            .as_str()
    );
    assert_eq!(manifest.summary["panels"], 2);
    let svg = std::fs::read_to_string(p.figures().join("both.svg")).unwrap();
    assert!(svg.contains("read out at t = 12") && svg.contains("eps = 1"));
    // The read-out time is in the title: changing it re-renders with the new value.
    p.write("at_end", &REDUCE.replace("at = 12.0", "at = 10.0"));
    p.counted(&[]);
    let manifest = table::read_manifest(&p.output("both")).unwrap().unwrap();
    assert!(manifest.summary["title"]
        .as_str()
        .unwrap()
        .starts_with("read out at t = 10,"));

    // Each edit of the composite, and what its load error must name.
    let refused: [(&str, &str, &[&str]); 3] = [
        (
            "{at_end.params.at}",
            "{other.params.at}",
            &["both.toml", "`title`", "other"],
        ),
        (
            "input = \"sweep\"",
            "input = \"nope\"",
            &["panel[1].input", "nope"],
        ),
        (
            "[[panel]]\ninput = \"sweep\"",
            "[wrong]\ninput = \"sweep\"",
            &["both.toml"],
        ),
    ];
    for (from, to, named) in refused {
        let edited = composite.replace(from, to);
        let e = load_error_after_reduce("both", &edited);
        assert!(named.iter().all(|n| e.contains(n)), "{from} -> {to}: {e}");
    }
}

/// A fit that cannot converge is a row with its reason; the stages after it still run, the
/// report shows the failure, and the run ends with an error naming it.
#[test]
fn a_failed_fit_is_a_row_the_run_goes_on_and_ends_naming_it() {
    let fits = r#"
kind = "fit"
x = "eps"
inputs = ["at_end"]
model = [
  { name = "good", y = "E_tr", form = "tanh", start = [0.1, 1.0, 0.0] },
  { name = "hopeless", y = "E_tr", form = "power", start = [1.0, 1.0, 0.0], x_range = [100.0, 200.0] },
]
"#;
    let report = r#"
kind = "report"
inputs = ["fits"]
markdown = "REPORT.md"
title = "Fits"
[[quote]]
figure = "X"
quantity = "A of the good fit"
paper = 0.1
agree = 1.0
as_run = "tanh"
ours = { stage = "fits", column = "A", where = { model = "good" } }
[[quote.convention]]
name = "the hopeless fit"
source = { stage = "fits", column = "A", where = { model = "hopeless" } }
"#;
    let p = Project::new(&[
        ("sweep", SWEEP),
        ("at_end", REDUCE),
        ("fits", fits),
        ("report", report),
    ]);
    let options = RunOptions {
        results: p.results().clone(),
        figures: p.figures(),
        ..Default::default()
    };
    let e = run(&p.load(), &options, &Counter::default()).unwrap_err();
    let PipelineError::Failed { failures } = &e else {
        panic!("{e}")
    };
    assert!(
        failures[0].contains("`fits`") && failures[0].contains("hopeless"),
        "{e}"
    );
    let table = table::read(&p.output("fits")).unwrap();
    let failure = table::str_column(&table, "failure").unwrap();
    let a = table::f64_column(&table, "A").unwrap();
    assert_eq!(failure[0], None);
    assert!(a[0].is_some());
    assert!(failure[1].as_deref().unwrap().contains("at least 4 points"));
    assert_eq!(a[1], None);
    let markdown =
        std::fs::read_to_string(p.results().parent().unwrap().join("REPORT.md")).unwrap();
    assert!(
        markdown.contains("**failed**") && markdown.contains("at least 4 points"),
        "{markdown}"
    );
}

/// A spacetime stage over a physical scene may write SI columns (`units = "SI"`); a figure
/// then draws `t` in the unit its label names, and a figure that labels the scaled columns of
/// the same stage in µs is refused.
#[test]
fn axes_are_drawn_in_the_units_the_table_has() {
    let field = |units: &str| {
        format!(
            r#"
kind = "spacetime"
{units}
[scene]
chain = {{ sites = [-10, 9], boundary = "free" }}
physical = {{ contact = 2.5e9, mass = 1e-3, velocity = 1.0 }}
impulse = {{ site = -10 }}
run = {{ t_end = 10.0, method = "rk4", dt = 0.01, sample_every = 1.0 }}
[field]
sites = [-10, 9]
"#
        )
    };
    let figure = r#"
kind = "render"
inputs = ["field"]
title = "rods"
[heatmap]
x = "t"
y = "site"
z = "velocity"
x_label = "t (µs)"
y_label = "rod"
z_label = "velocity (mm/s)"
"#;
    let p = Project::new(&[("field", &field("units = \"SI\"")), ("figure", figure)]);
    p.counted(&[]);
    let field_table = table::read(&p.output("field")).unwrap();
    let t = table::f64_column(&field_table, "t").unwrap();
    let last = t.iter().flatten().fold(0.0_f64, |a, &b| a.max(b));
    // 10 units of L/V seconds: tens of microseconds for these rods.
    assert!(last > 1e-6 && last < 1e-3, "{last}");
    let plotted = table::read(&p.output("figure")).unwrap();
    let x = table::f64_column(&plotted, "t").unwrap();
    let drawn = x.iter().flatten().fold(0.0_f64, |a, &b| a.max(b));
    assert!(
        (drawn - last * 1e6).abs() < 1e-9 * drawn,
        "{drawn} µs against {last} s"
    );
    let p = Project::new(&[("field", &field("")), ("figure", figure)]);
    let e = p.run(&[]).unwrap_err().to_string();
    assert!(e.contains("names µs") && e.contains("scaled units"), "{e}");
    let e = load_error(&[(
        "field",
        &field("units = \"SI\"").replace("physical = ", "# "),
    )]);
    assert!(e.contains("units"), "{e}");
}
