//! `kind = "render"`: draw input tables as one figure (PNG and SVG under `figures/`), and keep
//! exactly the plotted numbers as the stage's parquet table.
//!
//! A figure is a title over panels laid out `columns` per row. The simple form draws one
//! input, with the plot keys at the top level:
//!
//! ```toml
//! kind = "render"
//! inputs = ["f4_fractions"]
//! title = "Fig. 4: energy fractions at t = {f4_fractions.params.at}"
//! columns = 2                     # panels per row
//! [lines]                         # or [heatmap]
//! x = "eps"
//! y = ["R", "T", "E_tr"]          # one curve each
//! panels = "L"                    # optional: one panel per value of this column
//! x_label = "ε"
//! y_label = "energy fraction"
//! ```
//!
//! The composite form lays out panels from several inputs, as the paper's multi-panel
//! figures do: `[[panel]]` tables, each with `input = "stage"` and the same keys as the simple
//! form (`where`, `panel_label`, `[panel.lines]` or `[panel.heatmap]`), plus an optional
//! fixed `title`.
//!
//! Keys of a panel (simple form: top level):
//! - `where = { column = value }` draws only the matching rows; `panel_label = "column"` titles
//!   each panel by that string column instead of `panel = value`.
//! - `x_range = [lo, hi]`, `y_range = [lo, hi]`: the visible ranges (a zoom).
//! - `mark = [{ x = 0.0, label = "defect" }, { y = 40.0, label = "switch-on" }]`: dashed lines
//!   at fixed positions, with a legend entry per label.
//! - `[lines]`: `x`, `y` (columns), `x_label`, `y_label`, optional `panels`; `series = "column"`
//!   draws one curve of the single `y` per value of that column, named by the string column
//!   `series_label` when given.
//! - `[heatmap]`: `x`, `y`, `z` (a rectangular grid), `x_label`, `y_label`, `z_label`, optional
//!   `panels`, `mark_max = true` (circle and label the largest z), `colours = "sequential"`
//!   (viridis, the default) or `"diverging"` (blue-white-red, white at zero: signed values), or
//!   `categories = ["meets", "misses", "unstable"]` (z = 0, 1, 2 ... as named colours in a
//!   legend), `z_range = [lo, hi]`, and `overlay = [{ x = "column", label = "text" }, ...]`: a
//!   line over each panel through (that column's value, y) for every row of the map.
//!
//! `same_colour_scale = true` gives every heat map of the figure one colour scale, the union of
//! their ranges, so that panels compare by colour (the paper's Fig. 9).
//!
//! Titles (the figure's and fixed panel titles) may quote an input's manifest:
//! `{stage.params.at}`, `{stage.summary.tolerance}` or `{stage.params.scene.defect.0.eps}` (a
//! number indexes an array) is replaced by that value, so a title follows the parameters it
//! states.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use polars::prelude::DataFrame;
use serde_json::{json, Value};
use woodpile_plot::{
    cell_edges, Colours, Figure, HeatPanel, LinePanel, Mark, MarkAt, Panel, Series, View,
};

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::manifest::Manifest;
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::{f64_column, matching_rows, str_column, Columns};
use woodpile_pipeline::Output;

/// A parsed render stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Render {
    /// Figure title, possibly quoting input manifests (`{stage.params.at}`).
    pub title: String,
    /// Panels per row.
    pub columns: usize,
    /// What to draw, in order.
    pub panels: Vec<PanelSpec>,
    /// One colour scale for every heat map of the figure.
    pub same_colour_scale: bool,
}

/// One input table drawn as one or more panels.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelSpec {
    /// The stage whose table is drawn.
    pub input: String,
    /// A fixed title (may quote manifests); otherwise `panels = value` or `panel_label`.
    pub title: Option<String>,
    /// String column whose value titles each panel (instead of `column = value`).
    pub panel_label: Option<String>,
    /// Row filter: draw only rows where these columns equal these values.
    pub filter: Vec<(String, f64)>,
    /// Dashed lines at fixed positions.
    pub marks: Vec<Mark>,
    /// Visible ranges.
    pub view: View,
    /// What to draw.
    pub plot: Plot,
}

/// The plot types.
#[derive(Debug, Clone, PartialEq)]
pub enum Plot {
    /// Curves y(x).
    Lines {
        /// x column.
        x: String,
        /// y columns, one curve each.
        y: Vec<String>,
        /// Optional panel column.
        panels: Option<String>,
        /// Optional column splitting the single y into one curve per value.
        series: Option<String>,
        /// String column naming each curve of `series`.
        series_label: Option<String>,
        /// Axis labels.
        x_label: String,
        /// Axis labels.
        y_label: String,
    },
    /// z over an (x, y) grid.
    Heatmap {
        /// x column.
        x: String,
        /// y column.
        y: String,
        /// z column.
        z: String,
        /// Optional panel column.
        panels: Option<String>,
        /// Axis labels.
        x_label: String,
        /// Axis labels.
        y_label: String,
        /// Colour-bar label.
        z_label: String,
        /// Mark the maximum.
        mark_max: bool,
        /// Lines over the map: (x column, legend label).
        overlays: Vec<(String, String)>,
        /// How values become colours.
        colours: Colours,
        /// The value range the colours span.
        z_range: Option<(f64, f64)>,
    },
}

impl Render {
    /// Parses the render keys; `inputs` are the stage's inputs, which every panel and every
    /// quoted manifest must name.
    pub(crate) fn parse(fields: &mut Fields<'_>, inputs: &[String]) -> Result<Render> {
        let title: String = fields.required("title")?;
        let columns = fields.optional::<i64>("columns")?.unwrap_or(1);
        if !(1..=8).contains(&columns) {
            return Err(fields.error("columns", "expected 1 to 8 panels per row"));
        }
        let same_colour_scale = flag(fields, "same_colour_scale")?;
        check_quotes(&title, inputs).map_err(|reason| fields.error("title", reason))?;
        let panel_tables = fields.table_array("panel", "[[panel]]")?;
        let panels = match panel_tables.is_empty() {
            false => {
                let mut panels = Vec::with_capacity(panel_tables.len());
                for mut f in panel_tables {
                    let input: String = f.required("input")?;
                    if !inputs.contains(&input) {
                        return Err(f.error(
                            "input",
                            format!("`{input}` is not one of the stage's inputs {inputs:?}"),
                        ));
                    }
                    let title = f.optional::<String>("title")?;
                    if let Some(t) = &title {
                        check_quotes(t, inputs).map_err(|reason| f.error("title", reason))?;
                    }
                    let panel = parse_panel(&mut f, input, title)?;
                    f.finish()?;
                    panels.push(panel);
                }
                panels
            }
            true => {
                let [input] = inputs else {
                    return Err(fields.error(
                        "inputs",
                        "a render stage of several inputs draws them as [[panel]] tables, each naming its input",
                    ));
                };
                vec![parse_panel(fields, input.clone(), None)?]
            }
        };
        Ok(Render {
            title,
            columns: columns as usize,
            panels,
            same_colour_scale,
        })
    }

    /// The figure files of stage `name` under `figures`.
    pub fn files(figures: &Path, name: &str) -> [PathBuf; 2] {
        woodpile_pipeline::layout::figure_paths(figures, name)
    }

    /// Draws the panels from `inputs` (stage name to its table and manifest) and returns the
    /// plotted numbers, one row per drawn point or cell.
    pub(crate) fn run(
        &self,
        stage: &str,
        inputs: &HashMap<String, (DataFrame, Manifest)>,
        figures: &Path,
    ) -> Result<Output> {
        let fail = |e: PipelineError| PipelineError::stage(stage, e.to_string());
        let quote = |text: &str| quoted(text, inputs).map_err(|r| PipelineError::stage(stage, r));
        let mut panels = Vec::new();
        let mut names = Vec::new();
        for spec in &self.panels {
            let (frame, _) = &inputs[&spec.input];
            spec.check_columns(frame)
                .map_err(|reason| PipelineError::stage(stage, reason))?;
            let title = spec.title.as_deref().map(quote).transpose()?;
            let drawn = spec.draw(frame, title).map_err(fail)?;
            names.extend(std::iter::repeat_n(spec.columns(), drawn.len()));
            panels.extend(drawn);
            if panels.len() > MAX_PANELS {
                return Err(PipelineError::stage(
                    stage,
                    format!("more than the {MAX_PANELS} panels a figure may have"),
                ));
            }
        }
        if self.same_colour_scale {
            share_colour_scale(&mut panels);
        }
        let figure = Figure {
            title: quote(&self.title)?,
            columns: self.columns,
            panel_size: match panels.first() {
                Some(Panel::Heat(_)) => (620, 500),
                _ => (560, 400),
            },
            panels,
        };
        let [png, svg] = Render::files(figures, stage);
        let drawing = |e: woodpile_plot::PlotError| PipelineError::stage(stage, e.to_string());
        woodpile_pipeline::atomic::write(&png, &figure.png().map_err(drawing)?)?;
        woodpile_pipeline::atomic::write(&svg, figure.svg().map_err(drawing)?.as_bytes())?;
        Ok(Output {
            failures: Vec::new(),
            frame: plotted(&figure.panels, &names).into_frame()?,
            summary: json!({
                "figures": [format!("{stage}.png"), format!("{stage}.svg")],
                "panels": figure.panels.len(),
                "title": figure.title,
            }),
        })
    }
}

fn flag(fields: &mut Fields<'_>, key: &str) -> Result<bool> {
    match fields.take(key) {
        None => Ok(false),
        Some(toml::Value::Boolean(b)) => Ok(b),
        Some(_) => Err(fields.error(key, "expected true or false")),
    }
}

fn range_key(f: &mut Fields<'_>, key: &str) -> Result<Option<(f64, f64)>> {
    match f.optional::<Vec<f64>>(key)?.as_deref() {
        None => Ok(None),
        Some(&[lo, hi]) if lo < hi && lo.is_finite() && hi.is_finite() => Ok(Some((lo, hi))),
        Some(_) => Err(f.error(key, "expected [lo, hi] with lo < hi")),
    }
}

/// The keys of one panel (at the top level in the simple form).
fn parse_panel(f: &mut Fields<'_>, input: String, title: Option<String>) -> Result<PanelSpec> {
    let filter = f.equality_filter("where")?;
    let panel_label = f.optional::<String>("panel_label")?;
    let view = View {
        x: range_key(f, "x_range")?,
        y: range_key(f, "y_range")?,
    };
    let marks = parse_marks(f)?;
    let lines = f.optional::<toml::Table>("lines")?;
    let heat = f.optional::<toml::Table>("heatmap")?;
    let plot = match (lines, heat) {
        (Some(t), None) => {
            let mut f = f.nested("lines", t);
            let plot = Plot::Lines {
                x: f.required("x")?,
                y: f.required("y")?,
                panels: f.optional("panels")?,
                series: f.optional("series")?,
                series_label: f.optional("series_label")?,
                x_label: f.required("x_label")?,
                y_label: f.required("y_label")?,
            };
            if let Plot::Lines {
                y,
                series,
                series_label,
                ..
            } = &plot
            {
                if series.is_some() && y.len() != 1 {
                    return Err(f.error("y", "with `series`, give exactly one y column"));
                }
                if series.is_none() && series_label.is_some() {
                    return Err(f.error("series_label", "needs `series`"));
                }
            }
            f.finish()?;
            plot
        }
        (None, Some(t)) => {
            let mut f = f.nested("heatmap", t);
            let mark_max = flag(&mut f, "mark_max")?;
            let overlays = parse_overlays(&mut f)?;
            let categories = f.optional::<Vec<String>>("categories")?;
            let colours = match (f.optional::<String>("colours")?.as_deref(), categories) {
                (None | Some("sequential"), None) => Colours::Sequential,
                (Some("diverging"), None) => Colours::Diverging,
                (None, Some(names)) if !names.is_empty() => Colours::Categories(names),
                (None, Some(_)) => return Err(f.error("categories", "name at least one")),
                (Some(_), Some(_)) => {
                    return Err(f.error("colours", "give `colours` or `categories`, not both"))
                }
                (Some(other), None) => {
                    return Err(f.error(
                        "colours",
                        format!("expected \"sequential\" or \"diverging\", got \"{other}\""),
                    ))
                }
            };
            let plot = Plot::Heatmap {
                overlays,
                colours,
                z_range: range_key(&mut f, "z_range")?,
                x: f.required("x")?,
                y: f.required("y")?,
                z: f.required("z")?,
                panels: f.optional("panels")?,
                x_label: f.required("x_label")?,
                y_label: f.required("y_label")?,
                z_label: f.required("z_label")?,
                mark_max,
            };
            f.finish()?;
            plot
        }
        _ => {
            let others = f.keys();
            let reason = if others.is_empty() {
                "give exactly one of [lines] or [heatmap]".to_string()
            } else {
                format!(
                    "give exactly one of [lines] or [heatmap] (unknown keys: {})",
                    others.join(", ")
                )
            };
            return Err(f.error("lines", reason));
        }
    };
    Ok(PanelSpec {
        input,
        title,
        panel_label,
        filter,
        marks,
        view,
        plot,
    })
}

/// `mark = [{ x = value, label = "text" } | { y = value, label = "text" }, ...]`.
fn parse_marks(f: &mut Fields<'_>) -> Result<Vec<Mark>> {
    f.table_array("mark", "{ x or y, label }")?
        .into_iter()
        .map(|mut m| {
            let at = match (m.optional::<f64>("x")?, m.optional::<f64>("y")?) {
                (Some(x), None) => MarkAt::X(x),
                (None, Some(y)) => MarkAt::Y(y),
                _ => return Err(m.error("x", "give exactly one of x or y")),
            };
            let mark = Mark {
                at,
                label: m.required("label")?,
            };
            m.finish()?;
            Ok(mark)
        })
        .collect()
}

/// `overlay = [{ x = "column", label = "text" }, ...]` of a `[heatmap]`.
fn parse_overlays(f: &mut Fields<'_>) -> Result<Vec<(String, String)>> {
    f.table_array("overlay", "{ x = \"column\", label = \"text\" }")?
        .into_iter()
        .map(|mut o| {
            let overlay = (o.required("x")?, o.required("label")?);
            o.finish()?;
            Ok(overlay)
        })
        .collect()
}

/// The `{stage.path}` quotes of `text`, each naming one of `inputs`.
fn check_quotes(text: &str, inputs: &[String]) -> std::result::Result<(), String> {
    for quote in quotes(text) {
        let stage = quote.split('.').next().unwrap_or_default();
        if !inputs.iter().any(|i| i == stage) {
            return Err(format!(
                "`{{{quote}}}` quotes `{stage}`, which is not one of the inputs {inputs:?}"
            ));
        }
    }
    Ok(())
}

fn quotes(text: &str) -> impl Iterator<Item = &str> {
    text.split('{')
        .skip(1)
        .filter_map(|part| part.split_once('}').map(|(q, _)| q))
}

/// Most panels one figure may have: more are unreadable, and each costs memory to draw.
const MAX_PANELS: usize = 64;

/// Longest text a title or label may expand to: far more than any figure shows.
const MAX_EXPANDED_CHARS: usize = 100_000;

/// `text` with every `{stage.path}` replaced by that value of the stage's manifest, in one
/// pass over `text`: inserted values are never expanded again (a quoted value cannot inject
/// quotes, and the order of the quotes does not matter), each distinct quote is looked up
/// once, and the result is at most [`MAX_EXPANDED_CHARS`] long.
fn quoted(
    text: &str,
    inputs: &HashMap<String, (DataFrame, Manifest)>,
) -> std::result::Result<String, String> {
    let mut manifests: HashMap<&str, Value> = HashMap::new();
    let mut values: HashMap<&str, String> = HashMap::new();
    let mut out = String::new();
    let mut rest = text;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        // A quote runs to the next `}` with no `{` before it; anything else is literal.
        let Some(close) = after
            .find(['{', '}'])
            .filter(|&i| after.as_bytes()[i] == b'}')
        else {
            out.push('{');
            rest = after;
            continue;
        };
        let quote = &after[..close];
        if !values.contains_key(quote) {
            let shown = quote_value(quote, inputs, &mut manifests)?;
            values.insert(quote, shown);
        }
        out.push_str(&values[quote]);
        if out.len() > MAX_EXPANDED_CHARS {
            return Err(format!(
                "the text expands to more than {MAX_EXPANDED_CHARS} characters; quote less"
            ));
        }
        rest = &after[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The shown value of one quote `stage.path`.
fn quote_value<'a>(
    quote: &'a str,
    inputs: &HashMap<String, (DataFrame, Manifest)>,
    manifests: &mut HashMap<&'a str, Value>,
) -> std::result::Result<String, String> {
    let (stage, path) = quote.split_once('.').unwrap_or((quote, ""));
    if !manifests.contains_key(stage) {
        let manifest = inputs
            .get(stage)
            .map(|(_, m)| serde_json::to_value(m).unwrap_or(Value::Null))
            .ok_or_else(|| format!("`{{{quote}}}`: no input `{stage}`"))?;
        manifests.insert(stage, manifest);
    }
    // Dotted keys; a number indexes an array (`params.scene.defect.0.eps`).
    let value = path
        .split('.')
        .filter(|k| !k.is_empty())
        .try_fold(&manifests[stage], |v, k| match (v, k.parse::<usize>()) {
            (Value::Array(items), Ok(i)) => items.get(i),
            _ => v.get(k),
        })
        .ok_or_else(|| format!("`{{{quote}}}`: the manifest of `{stage}` has no `{path}`"))?;
    Ok(match value {
        Value::Number(n) => n
            .as_f64()
            .map_or(n.to_string(), |x| woodpile_plot::tick(&x)),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    })
}

/// Gives every heat map the union of their colour ranges.
fn share_colour_scale(panels: &mut [Panel]) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for panel in panels.iter() {
        if let Panel::Heat(h) = panel {
            let (l, u) = h.z_range.unwrap_or_else(|| h.value_range());
            (lo, hi) = (lo.min(l), hi.max(u));
        }
    }
    if lo < hi {
        for panel in panels.iter_mut() {
            if let Panel::Heat(h) = panel {
                h.z_range = Some((lo, hi));
            }
        }
    }
}

/// The source columns a panel plots: x, the y of each curve (by curve label; `None`: the
/// panel's single y), and for heat maps y and z.
#[derive(Clone)]
struct PlottedColumns {
    x: String,
    y: Option<String>,
    z: Option<String>,
    overlays: Vec<(String, String)>,
}

/// The plotted numbers of `panels`: one row per curve point or heat-map cell, with the panel's
/// index and the curve's (or the colour bar's) label, each number under the name of the column
/// it was drawn from, so a diff can give a column (a wall time, say) its own tolerance.
fn plotted(panels: &[Panel], names: &[PlottedColumns]) -> Columns {
    /// A drawn point: its panel, its curve's label, and its numbers by source column.
    type Plotted = (usize, String, Vec<(String, Option<f64>)>);
    let mut order: Vec<String> = Vec::new();
    let mut rows: Vec<Plotted> = Vec::new();
    let mut push = |p: usize, label: &str, cells: Vec<(String, Option<f64>)>| {
        for (name, _) in &cells {
            if !order.contains(name) {
                order.push(name.clone());
            }
        }
        rows.push((p, label.to_string(), cells));
    };
    for (p, (drawn, cols)) in panels.iter().zip(names).enumerate() {
        match drawn {
            Panel::Lines(l) => {
                for s in &l.series {
                    let y = cols.y.clone().unwrap_or_else(|| s.label.clone());
                    for &(x, v) in &s.points {
                        push(
                            p,
                            &s.label,
                            vec![(cols.x.clone(), Some(x)), (y.clone(), Some(v))],
                        );
                    }
                }
            }
            Panel::Heat(h) => {
                let (y, z) = (
                    cols.y.clone().unwrap_or_default(),
                    cols.z.clone().unwrap_or_default(),
                );
                for (j, &yv) in h.ys.iter().enumerate() {
                    for (i, &xv) in h.xs.iter().enumerate() {
                        let cells = vec![
                            (cols.x.clone(), Some(xv)),
                            (y.clone(), Some(yv)),
                            (z.clone(), h.z[j * h.xs.len() + i]),
                        ];
                        push(p, &h.z_label, cells);
                    }
                }
                for (s, (column, _)) in h.overlays.iter().zip(&cols.overlays) {
                    for &(xv, yv) in &s.points {
                        push(
                            p,
                            &s.label,
                            vec![(column.clone(), Some(xv)), (y.clone(), Some(yv))],
                        );
                    }
                }
            }
        }
    }
    let mut columns = Columns::new();
    columns
        .i64("panel", rows.iter().map(|r| Some(r.0 as i64)).collect())
        .str("series", rows.iter().map(|r| Some(r.1.clone())).collect());
    for name in &order {
        let values = rows
            .iter()
            .map(|r| r.2.iter().find(|(n, _)| n == name).and_then(|(_, v)| *v))
            .collect();
        columns.f64(name, values);
    }
    columns
}

impl PanelSpec {
    /// Every column the spec names exists in `input`, or the error names the key, the input,
    /// the columns there are and the nearest one.
    fn check_columns(&self, input: &DataFrame) -> std::result::Result<(), String> {
        let mut named: Vec<(String, &String)> = Vec::new();
        match &self.plot {
            Plot::Lines {
                x,
                y,
                panels,
                series,
                series_label,
                ..
            } => {
                named.push(("lines.x".into(), x));
                named.extend(y.iter().map(|c| ("lines.y".to_string(), c)));
                named.extend(panels.iter().map(|c| ("lines.panels".to_string(), c)));
                named.extend(series.iter().map(|c| ("lines.series".to_string(), c)));
                named.extend(
                    series_label
                        .iter()
                        .map(|c| ("lines.series_label".to_string(), c)),
                );
            }
            Plot::Heatmap {
                x,
                y,
                z,
                panels,
                overlays,
                ..
            } => {
                named.push(("heatmap.x".into(), x));
                named.push(("heatmap.y".into(), y));
                named.push(("heatmap.z".into(), z));
                named.extend(panels.iter().map(|c| ("heatmap.panels".to_string(), c)));
                named.extend(
                    overlays
                        .iter()
                        .map(|(c, _)| ("heatmap.overlay".to_string(), c)),
                );
            }
        }
        named.extend(self.filter.iter().map(|(c, _)| ("where".to_string(), c)));
        named.extend(
            self.panel_label
                .iter()
                .map(|c| ("panel_label".to_string(), c)),
        );
        for (key, column) in named {
            if input.column(column).is_err() {
                return Err(format!(
                    "key `{key}`: input `{}`: {}",
                    self.input,
                    woodpile_pipeline::table::missing_column(input, column)
                ));
            }
        }
        Ok(())
    }

    /// The source columns this spec plots.
    fn columns(&self) -> PlottedColumns {
        match &self.plot {
            Plot::Lines { x, y, series, .. } => PlottedColumns {
                x: x.clone(),
                // Curves named by their y column carry it as label; a `series` split has one y.
                y: series.as_ref().and(y.first().cloned()),
                z: None,
                overlays: Vec::new(),
            },
            Plot::Heatmap {
                x, y, z, overlays, ..
            } => PlottedColumns {
                x: x.clone(),
                y: Some(y.clone()),
                z: Some(z.clone()),
                overlays: overlays.clone(),
            },
        }
    }

    /// The panels this spec draws from `input`: one, or one per value of `panels`.
    fn draw(&self, input: &DataFrame, title: Option<String>) -> Result<Vec<Panel>> {
        let keep = matching_rows(input, &self.filter)?;
        let column = |name: &str| -> Result<Vec<Option<f64>>> {
            let values = f64_column(input, name)?;
            Ok(keep.iter().map(|&r| values[r]).collect())
        };
        // An optional string column (curve or panel names), on the kept rows.
        let text_column = |name: Option<&String>| -> Result<Option<Vec<Option<String>>>> {
            let Some(name) = name else { return Ok(None) };
            let values = str_column(input, name)?;
            Ok(Some(keep.iter().map(|&r| values[r].clone()).collect()))
        };
        let (panel_name, used): (Option<&String>, Vec<&String>) = match &self.plot {
            Plot::Lines {
                x,
                y,
                panels,
                series,
                ..
            } => (
                panels.as_ref(),
                std::iter::once(x).chain(y).chain(series).collect(),
            ),
            Plot::Heatmap {
                x,
                y,
                z,
                panels,
                overlays,
                ..
            } => (
                panels.as_ref(),
                [x, y, z]
                    .into_iter()
                    .chain(overlays.iter().map(|(column, _)| column))
                    .collect(),
            ),
        };
        let panel_values = match panel_name {
            Some(p) => column(p)?,
            None => vec![Some(0.0); keep.len()],
        };
        let mut keys: Vec<f64> = panel_values.iter().flatten().copied().collect();
        keys.sort_by(f64::total_cmp);
        keys.dedup();
        if keys.len() > MAX_PANELS {
            return Err(PipelineError::stage(
                "render",
                format!(
                    "`panels = \"{}\"` makes {} panels, more than the {MAX_PANELS} a figure may have; filter the rows with `where` or choose another column",
                    panel_name.map_or("", |p| p.as_str()),
                    keys.len()
                ),
            ));
        }
        let data: Vec<Vec<Option<f64>>> = used.iter().map(|c| column(c)).collect::<Result<_>>()?;
        let labels = match &self.plot {
            Plot::Lines { series_label, .. } => text_column(series_label.as_ref())?,
            Plot::Heatmap { .. } => None,
        };
        let panel_values = &panel_values;
        let height = keep.len();
        let rows_of = move |key: f64| -> Vec<usize> {
            (0..height)
                .filter(|&r| panel_values[r] == Some(key))
                .collect()
        };
        let panel_labels = text_column(self.panel_label.as_ref())?;
        let title_of = |key: f64| {
            if let Some(t) = &title {
                return t.clone();
            }
            let labelled = panel_labels.as_ref().and_then(|labels| {
                (0..height)
                    .find(|&r| panel_values[r] == Some(key))
                    .and_then(|r| labels[r].clone())
            });
            labelled.unwrap_or_else(|| {
                panel_name
                    .map(|p| format!("{p} = {}", woodpile_plot::tick(&key)))
                    .unwrap_or_default()
            })
        };
        let panels = keys
            .iter()
            .map(|&key| match &self.plot {
                Plot::Lines {
                    y,
                    x_label,
                    y_label,
                    series: None,
                    ..
                } => Panel::Lines(LinePanel {
                    title: title_of(key),
                    x_label: x_label.clone(),
                    y_label: y_label.clone(),
                    series: y
                        .iter()
                        .enumerate()
                        .map(|(k, name)| Series {
                            label: name.clone(),
                            points: rows_of(key)
                                .into_iter()
                                .map(|r| {
                                    (
                                        data[0][r].unwrap_or(f64::NAN),
                                        data[k + 1][r].unwrap_or(f64::NAN),
                                    )
                                })
                                .collect(),
                        })
                        .collect(),
                    marks: self.marks.clone(),
                    view: self.view,
                }),
                Plot::Lines {
                    x_label,
                    y_label,
                    series: Some(series),
                    ..
                } => {
                    // data = [x, y, series]; curves in order of first appearance.
                    let mut curves: Vec<(f64, Vec<usize>)> = Vec::new();
                    for r in rows_of(key) {
                        let Some(id) = data[2][r] else { continue };
                        match curves.iter_mut().find(|(v, _)| *v == id) {
                            Some((_, members)) => members.push(r),
                            None => curves.push((id, vec![r])),
                        }
                    }
                    Panel::Lines(LinePanel {
                        title: title_of(key),
                        x_label: x_label.clone(),
                        y_label: y_label.clone(),
                        series: curves
                            .into_iter()
                            .map(|(id, members)| Series {
                                label: labels
                                    .as_ref()
                                    .and_then(|l| l[members[0]].clone())
                                    .unwrap_or_else(|| {
                                        format!("{series} = {}", woodpile_plot::tick(&id))
                                    }),
                                points: members
                                    .iter()
                                    .map(|&r| {
                                        (
                                            data[0][r].unwrap_or(f64::NAN),
                                            data[1][r].unwrap_or(f64::NAN),
                                        )
                                    })
                                    .collect(),
                            })
                            .collect(),
                        marks: self.marks.clone(),
                        view: self.view,
                    })
                }
                Plot::Heatmap { .. } => self.heat_panel(&data, &rows_of(key), title_of(key)),
            })
            .collect();
        Ok(panels)
    }

    /// One heat-map panel from `data` = [x, y, z, overlay columns...] on `rows`.
    fn heat_panel(&self, data: &[Vec<Option<f64>>], rows: &[usize], title: String) -> Panel {
        let Plot::Heatmap {
            x_label,
            y_label,
            z_label,
            mark_max,
            overlays,
            colours,
            z_range,
            ..
        } = &self.plot
        else {
            unreachable!("heat_panel is called for heat maps only")
        };
        let unique = |k: usize| {
            let mut v: Vec<f64> = rows.iter().filter_map(|&r| data[k][r]).collect();
            v.sort_by(f64::total_cmp);
            v.dedup();
            v
        };
        let (xs, ys) = (unique(0), unique(1));
        let mut z = vec![None; xs.len() * ys.len()];
        let mut best: Option<(f64, f64, f64)> = None;
        for &r in rows {
            let (Some(x), Some(y)) = (data[0][r], data[1][r]) else {
                continue;
            };
            let i = xs.partition_point(|&v| v < x);
            let j = ys.partition_point(|&v| v < y);
            z[j * xs.len() + i] = data[2][r];
            if let Some(v) = data[2][r].filter(|v| v.is_finite()) {
                if best.is_none_or(|(_, _, b)| v > b) {
                    best = Some((x, y, v));
                }
            }
        }
        // Each overlay: its x on every row of the map, as a step line over the row's cell.
        let y_edges = cell_edges(&ys);
        let overlays = overlays
            .iter()
            .enumerate()
            .map(|(k, (_, label))| {
                let column = &data[3 + k];
                let points = ys
                    .iter()
                    .enumerate()
                    .filter_map(|(j, &y)| {
                        let x = rows
                            .iter()
                            .find(|&&r| data[1][r] == Some(y))
                            .and_then(|&r| column[r])?;
                        Some([(x, y_edges[j]), (x, y_edges[j + 1])])
                    })
                    .flatten()
                    .collect();
                Series {
                    label: label.clone(),
                    points,
                }
            })
            .collect();
        Panel::Heat(HeatPanel {
            title,
            x_label: x_label.clone(),
            y_label: y_label.clone(),
            z_label: z_label.clone(),
            overlays,
            xs,
            ys,
            z,
            marker: best
                .filter(|_| *mark_max)
                .map(|(x, y, v)| (x, y, format!("max {v:.4}"))),
            colours: colours.clone(),
            z_range: *z_range,
            marks: self.marks.clone(),
            view: self.view,
        })
    }
}

impl Kind for Render {
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck {
        if stage.inputs.is_empty() {
            return Err((
                "inputs".into(),
                "a render stage reads one or more tables".into(),
            ));
        }
        match stage
            .inputs
            .iter()
            .position(|i| inputs.get::<Render>(i).is_some())
        {
            Some(k) => Err((
                format!("inputs[{k}]"),
                format!("`{}` is a render stage: read a data table", stage.inputs[k]),
            )),
            None => Ok(()),
        }
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        let inputs = ctx
            .stage
            .inputs
            .iter()
            .map(|name| Ok((name.clone(), ctx.input_with_manifest(name)?)))
            .collect::<Result<_>>()?;
        self.run(ctx.name(), &inputs, ctx.figures)
    }

    fn files(&self, stage: &str, _: &Path, figures: &Path) -> Vec<PathBuf> {
        Render::files(figures, stage).to_vec()
    }
}
