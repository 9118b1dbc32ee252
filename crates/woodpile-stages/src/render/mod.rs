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
//! their ranges, so that panels compare by colour (the paper's Fig. 9).
//!
//! Titles (the figure's and fixed panel titles) may quote an input's manifest:
//! `{stage.params.at}`, `{stage.summary.tolerance}` or `{stage.params.scene.defect.0.eps}` (a
//! number indexes an array) is replaced by that value, so a title follows the parameters it
//! states.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use polars::prelude::DataFrame;
use serde_json::json;
use woodpile_plot::{Figure, Panel};

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::manifest::Manifest;
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::Output;

mod draw;
mod plotted;
mod spec;
mod title;

pub use spec::{PanelSpec, Plot};

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
