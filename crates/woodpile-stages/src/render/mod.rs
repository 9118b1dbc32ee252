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
//! - `where = { column = value }` (numbers or strings) draws only the matching rows;
//!   `panel_label = "column"` titles each panel by that string column instead of
//!   `panel = value`.
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
//! their ranges, so that panels compare by colour (the paper's Fig. 9), and draws its colour
//! bar (or category legend) once, beside the panels.
//!
//! An axis label may end with its unit in parentheses, `x_label = "t (µs)"`. When the input
//! says its columns' units (a sweep or spacetime stage with `units = "SI"`, a spectrum stage's
//! `frequency`), the column is drawn in that unit; a label naming a unit the column is not in
//! (µs on the model's scaled time) is refused.
//!
//! Titles (the figure's and fixed panel titles) may quote an input's manifest:
//! `{stage.params.at}`, `{stage.summary.tolerance}` or `{stage.params.scene.defect.0.eps}` (a
//! number indexes an array) is replaced by that value, so a title follows the parameters it
//! states.
//!
//! Axes and panels:
//! - `x_scale = "log"`, `y_scale = "log"` (panel keys, beside `x_range`): a log axis, for lines
//!   and heat maps; values at or below zero are not drawn. A heat map's cells meet halfway
//!   between their neighbours (geometric midpoints on a log axis) and the map, and its axis,
//!   end at the outermost data.
//! - `panel_title = "ε = {value}"` (in `[lines]` or `[heatmap]`): each panel's title, `{value}`
//!   its `panels` value.
//! - `series_style = { E_tr = { colour = "#009e73", dash = "dashed", marker = "circle", label =
//!   "E_{tr}" } }` (in `[lines]`): a curve's look by its name. Unset curves take the next of a
//!   colour-blind-safe palette (Okabe-Ito), a dash (solid, dashed, dotted, dash-dot) and a
//!   marker (circle, square, triangle, diamond, cross), so every figure reads in greyscale.
//! - `mark_halving = true` (in `[lines]`): a dashed vertical line where each curve first falls
//!   to half its first value in the table's order (its lossless end, say), interpolated between
//!   the samples around the crossing (in log x on positive x), labelled "`<curve>` halves".
//! - `z_range = "robust"` (the default of diverging maps: symmetric, to the 99th percentile of
//!   |z|, said in the colour bar's label), `"full"` (the data's range) or `[lo, hi]`.
//!
//! Text: every title and label may use a small markup, drawn as Unicode in PNG and SVG:
//! `E_{tr}` (a subscript group), `u'_n` (a prime and a one-letter subscript), `10^{-3}`,
//! `\varepsilon_1`, `\kappa`. A one-character `_x` or `^x` applies only when it ends a word, so
//! column names such as `E_tr` pass as typed. `labels = { E_tr = "E_{tr}" }` writes a name (a
//! curve's column, a colour bar's label, any whole label) as a label; the stage's table keeps
//! the names.
//!
//! `[style]`: the printed figure.
//! - `width_mm` (default 86 for one panel, 178 for more: a journal's column and page),
//!   `height_mm` or `aspect` (a panel's height over its width: 0.72 for lines, 0.8 for maps),
//!   `dpi` of the PNG (300), `font_pt` (8: ticks, axis labels and legends; titles 1.1 to 1.2
//!   times it). The SVG states its size in mm and the PNG its DPI, so LaTeX, Inkscape and
//!   layout programs place them at that size with text at `font_pt`.
//! - `legend = "best"` (the inside place that covers no curve, else outside on the right; on a
//!   heat map, under it), `"upper left"`, `"upper center"`, `"upper right"`, `"lower left"`,
//!   `"lower center"`, `"lower right"`, `"center left"`, `"center right"`, `"outside right"`,
//!   `"below"` or `"none"`. The manifest's `legend_covers_points` counts, per panel, the curve
//!   samples under the legend box: zero unless a stage forces a place.
//! - `panel_letters = true`: (a), (b), (c) in each panel's top-left corner.
//! - `share_x = true`, `share_y = true`: one range on that axis across the panels of a kind.
//! - `minor_grid = true`: a light grid between the ticks (off by default).
//!
//! Project-wide values go in `pipeline/defaults.toml` as `[render.style]` and
//! `[render.labels]`; a stage's keys override them. Before and after, for Fig. 4:
//!
//! ```toml
//! # before: 1,120 x 820 px, 9.7-px ticks (under 2 pt at print size), legend over T
//! columns = 2
//! [lines]
//! x = "eps"
//! y = ["R", "T", "E_tr"]
//!
//! # after: 178 mm at 300 DPI, 8-pt text, legend where no curve is, eps on a log axis,
//! # E_tr drawn as E with a subscript "tr" (labels in defaults.toml), panels (a) to (d)
//! columns = 2
//! x_scale = "log"
//! [lines]
//! x = "eps"
//! y = ["R", "T", "E_tr"]
//! ```

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use polars::prelude::DataFrame;
use serde_json::json;
use woodpile_plot::{Figure, Panel};

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{wrong_inputs, Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::manifest::Manifest;
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::Output;

mod display;
mod draw;
mod plotted;
mod spec;
mod style;
mod title;
mod units;

pub use spec::{CurveStyle, PanelSpec, Plot, ZRange};
pub use style::{Labels, StyleSpec};

use plotted::plotted;
use spec::{flag, parse_panel};
use title::{check_quotes, quoted};

/// Most panels one figure may have: more are unreadable, and each costs memory to draw.
const MAX_PANELS: usize = 64;

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
    /// Printed size, type, legends and panel conventions (`[style]`).
    pub style: StyleSpec,
    /// How names are written in the figure (`labels`).
    pub labels: Labels,
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
        let style = StyleSpec::parse(fields)?;
        let labels = Labels::parse(fields)?;
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
        for panel in &panels {
            let (key, texts) = match &panel.plot {
                Plot::Lines {
                    x_label, y_label, ..
                } => ("lines", vec![("x_label", x_label), ("y_label", y_label)]),
                Plot::Heatmap {
                    x_label,
                    y_label,
                    z_label,
                    ..
                } => (
                    "heatmap",
                    vec![
                        ("x_label", x_label),
                        ("y_label", y_label),
                        ("z_label", z_label),
                    ],
                ),
            };
            for (name, text) in texts {
                labels
                    .show(text)
                    .map_err(|reason| fields.error(&format!("{key}.{name}"), reason))?;
            }
        }
        Ok(Render {
            title,
            columns: columns as usize,
            panels,
            same_colour_scale,
            style,
            labels,
        })
    }

    /// The figure files of stage `name` under `figures`.
    pub fn files(figures: &Path, name: &str) -> [PathBuf; 2] {
        woodpile_files::layout::figure_paths(figures, name)
    }

    /// Draws the panels from `inputs` (stage name to its table and manifest) and returns the
    /// plotted numbers, one row per drawn point or cell.
    pub(crate) fn compute(
        &self,
        ctx: &Context<'_>,
        inputs: &HashMap<String, (DataFrame, Manifest)>,
    ) -> Result<Output> {
        let stage = ctx.name();
        let fail = |e: PipelineError| PipelineError::stage(stage, e.to_string());
        let quote = |text: &str| quoted(text, inputs).map_err(|r| PipelineError::stage(stage, r));
        let mut panels = Vec::new();
        let mut names = Vec::new();
        let mut specs: Vec<&PanelSpec> = Vec::new();
        for spec in &self.panels {
            let (frame, manifest) = &inputs[&spec.input];
            spec.check_columns(frame)
                .map_err(|reason| PipelineError::stage(stage, reason))?;
            let frame = units::in_label_units(spec, frame, manifest)
                .map_err(|reason| PipelineError::stage(stage, reason))?;
            let title = spec.title.as_deref().map(quote).transpose()?;
            let drawn = spec.draw(&frame, title).map_err(fail)?;
            names.extend(std::iter::repeat_n(spec.columns(), drawn.len()));
            specs.extend(std::iter::repeat_n(spec, drawn.len()));
            panels.extend(drawn);
            if panels.len() > MAX_PANELS {
                return Err(PipelineError::stage(
                    stage,
                    format!("more than the {MAX_PANELS} panels a figure may have"),
                ));
            }
        }
        display::robust_ranges(&mut panels, &specs);
        if self.same_colour_scale {
            share_colour_scale(&mut panels);
        }
        // The table keeps the names; the drawing shows the labels.
        let frame = plotted(&panels, &names).into_frame()?;
        for (panel, spec) in panels.iter_mut().zip(&specs) {
            display::show(panel, spec, &self.labels).map_err(|r| PipelineError::stage(stage, r))?;
        }
        let maps = matches!(panels.first(), Some(Panel::Heat(_)));
        let figure = Figure {
            title: self
                .labels
                .show(&quote(&self.title)?)
                .map_err(|r| PipelineError::stage(stage, r))?,
            columns: self.columns,
            style: self.style.resolve(panels.len(), self.columns, maps),
            shared_colour_bar: self.same_colour_scale,
            panels,
        };
        let [png, svg] = Render::files(ctx.figures, stage);
        let drawing = |e: woodpile_plot::PlotError| PipelineError::stage(stage, e.to_string());
        let drawn = figure.draw().map_err(drawing)?;
        ctx.write_file(&png, &drawn.png)?;
        ctx.write_file(&svg, drawn.svg.as_bytes())?;
        Ok(Output::table(
            frame,
            json!({
                "figures": [format!("{stage}.png"), format!("{stage}.svg")],
                "panels": figure.panels.len(),
                "title": figure.title,
                "size_mm": [figure.style.width_mm, figure.style.height_mm],
                "dpi": figure.style.dpi,
                "font_pt": figure.style.font_pt,
                "legend_covers_points": drawn.legend_covers,
            }),
        ))
    }
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

impl Kind for Render {
    fn check_inputs(&self, stage: &Stage, inputs: &Inputs<'_>) -> KindCheck {
        if stage.inputs.is_empty() {
            return wrong_inputs("a render stage reads one or more tables");
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
        self.compute(ctx, &inputs)
    }

    fn files(&self, stage: &str, _: &Path, figures: &Path) -> Vec<PathBuf> {
        Render::files(figures, stage).to_vec()
    }
}
