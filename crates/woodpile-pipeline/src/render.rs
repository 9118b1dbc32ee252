//! `kind = "render"`: draw one input table as a figure (PNG and SVG under `figures/`), and keep
//! exactly the plotted numbers as the stage's parquet table.
//!
//! ```toml
//! kind = "render"
//! inputs = ["f4_fractions"]
//! title = "Fig. 4: energy fractions against the mass ratio"
//! columns = 2                     # panels per row
//! [lines]                         # or [heatmap]
//! x = "eps"
//! y = ["R", "T", "E_tr"]          # one curve each
//! panels = "L"                    # optional: one panel per value of this column
//! x_label = "ε"
//! y_label = "energy fraction at t = 150"
//! ```
//!
//! An optional `where = { column = value }` draws only the matching rows, and
//! `panel_label = "column"` titles each panel by that string column instead of `panel = value`. In `[lines]`,
//! `series = "column"` draws one curve of the single `y` per value of that column, named by
//! the string column `series_label` when given (work-precision charts: one curve per method).
//! `[heatmap]` takes `x`, `y`, `z` (a rectangular grid), `x_label`, `y_label`, `z_label`,
//! optionally `panels`, `mark_max = true` (circle and label the largest z), and
//! `overlay = [{ x = "column", label = "text" }, ...]`: a line over each panel through
//! (that column's value, y) for every row of the map, e.g. a stability bound against ε.

use std::path::{Path, PathBuf};

use polars::prelude::DataFrame;
use serde_json::json;
use woodpile_plot::{cell_edges, Figure, HeatPanel, LinePanel, Panel, Series};

use crate::error::{PipelineError, Result};
use crate::fields::Fields;
use crate::table::{f64_column, matching_rows, str_column, Columns};
use crate::Output;

/// A parsed render stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Render {
    /// Figure title.
    pub title: String,
    /// String column whose value titles each panel (instead of `column = value`).
    pub panel_label: Option<String>,
    /// Panels per row.
    pub columns: usize,
    /// Row filter: draw only rows where these columns equal these values.
    pub filter: Vec<(String, f64)>,
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
    },
}

impl Render {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Render> {
        let title: String = fields.required("title")?;
        let columns = fields.optional::<i64>("columns")?.unwrap_or(1);
        if !(1..=8).contains(&columns) {
            return Err(fields.error("columns", "expected 1 to 8 panels per row"));
        }
        let filter = fields.equality_filter("where")?;
        let panel_label = fields.optional::<String>("panel_label")?;
        let lines = fields.optional::<toml::Table>("lines")?;
        let heat = fields.optional::<toml::Table>("heatmap")?;
        let plot = match (lines, heat) {
            (Some(t), None) => {
                let mut f = fields.nested("lines", t);
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
                let mut f = fields.nested("heatmap", t);
                let mark_max = match f.take("mark_max") {
                    None => false,
                    Some(toml::Value::Boolean(b)) => b,
                    Some(_) => return Err(f.error("mark_max", "expected true or false")),
                };
                let overlays = parse_overlays(&mut f)?;
                let plot = Plot::Heatmap {
                    overlays,
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
                let others = fields.keys();
                let reason = if others.is_empty() {
                    "give exactly one of [lines] or [heatmap]".to_string()
                } else {
                    format!(
                        "give exactly one of [lines] or [heatmap] (unknown keys: {})",
                        others.join(", ")
                    )
                };
                return Err(fields.error("lines", reason));
            }
        };
        Ok(Render {
            title,
            panel_label,
            columns: columns as usize,
            filter,
            plot,
        })
    }

    /// The figure files of stage `name` under `figures`.
    pub fn files(figures: &Path, name: &str) -> [PathBuf; 2] {
        [
            figures.join(format!("{name}.png")),
            figures.join(format!("{name}.svg")),
        ]
    }

    /// Draws `input` and returns the plotted numbers.
    pub(crate) fn run(&self, stage: &str, input: &DataFrame, figures: &Path) -> Result<Output> {
        let fail = |e: PipelineError| PipelineError::stage(stage, e.to_string());
        let all = |name: &str| f64_column(input, name).map_err(fail);
        let keep = matching_rows(input, &self.filter)
            .map_err(|e| PipelineError::stage(stage, e.to_string()))?;
        let column = |name: &str| -> Result<Vec<Option<f64>>> {
            let values = all(name)?;
            Ok(keep.iter().map(|&r| values[r]).collect())
        };
        // An optional string column (curve or panel names), on the kept rows.
        let text_column = |name: Option<&String>| -> Result<Option<Vec<Option<String>>>> {
            let Some(name) = name else { return Ok(None) };
            let values = str_column(input, name).map_err(fail)?;
            Ok(Some(keep.iter().map(|&r| values[r].clone()).collect()))
        };
        let (panel_name, mut used): (Option<&String>, Vec<&String>) = match &self.plot {
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
            let labelled = panel_labels.as_ref().and_then(|labels| {
                (0..height)
                    .find(|&r| panel_values[r] == Some(key))
                    .and_then(|r| labels[r].clone())
            });
            labelled.unwrap_or_else(|| {
                panel_name
                    .map(|p| format!("{p} = {key}"))
                    .unwrap_or_default()
            })
        };
        let panels: Vec<Panel> = keys
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
                }),
                Plot::Lines {
                    x_label,
                    y_label,
                    series: Some(series),
                    ..
                } => {
                    // data = [x, y, series]; curves in order of first appearance.
                    let rows = rows_of(key);
                    let mut curves: Vec<(f64, Vec<usize>)> = Vec::new();
                    for r in rows {
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
                                    .unwrap_or_else(|| format!("{series} = {id}")),
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
                    })
                }
                Plot::Heatmap {
                    x_label,
                    y_label,
                    z_label,
                    mark_max,
                    overlays,
                    ..
                } => {
                    let rows = rows_of(key);
                    let labels: Vec<&str> = overlays.iter().map(|(_, l)| l.as_str()).collect();
                    heat_panel(
                        &data,
                        &rows,
                        (title_of(key), [x_label, y_label, z_label]),
                        *mark_max,
                        &labels,
                    )
                }
            })
            .collect();
        let figure = Figure {
            title: self.title.clone(),
            panels,
            columns: self.columns,
            panel_size: match self.plot {
                Plot::Lines { .. } => (560, 400),
                Plot::Heatmap { .. } => (620, 500),
            },
        };
        let [png, svg] = Render::files(figures, stage);
        let drawing = |e: woodpile_plot::PlotError| PipelineError::stage(stage, e.to_string());
        crate::atomic::write(&png, &figure.png().map_err(drawing)?)?;
        crate::atomic::write(&svg, figure.svg().map_err(drawing)?.as_bytes())?;
        // The stage's table: exactly the plotted columns.
        if let Some(p) = panel_name {
            used.insert(0, p);
        }
        let mut columns = Columns::new();
        for name in used {
            columns.f64(name, column(name)?);
        }
        Ok(Output {
            frame: columns.into_frame()?,
            summary: json!({"figures": [format!("{stage}.png"), format!("{stage}.svg")], "panels": keys.len()}),
        })
    }
}

/// `overlay = [{ x = "column", label = "text" }, ...]` of a `[heatmap]`.
fn parse_overlays(f: &mut Fields<'_>) -> Result<Vec<(String, String)>> {
    let Some(value) = f.take("overlay") else {
        return Ok(Vec::new());
    };
    let toml::Value::Array(items) = value else {
        return Err(f.error("overlay", "expected an array of { x, label } tables"));
    };
    items
        .into_iter()
        .enumerate()
        .map(|(i, item)| {
            let key = format!("overlay[{i}]");
            let toml::Value::Table(table) = item else {
                return Err(f.error(
                    &key,
                    "expected a table { x = \"column\", label = \"text\" }",
                ));
            };
            let mut o = f.nested(&key, table);
            let overlay = (o.required("x")?, o.required("label")?);
            o.finish()?;
            Ok(overlay)
        })
        .collect()
}

/// One heat-map panel from `data` = [x, y, z, overlay columns...] on `rows`.
fn heat_panel(
    data: &[Vec<Option<f64>>],
    rows: &[usize],
    (title, [x_label, y_label, z_label]): (String, [&String; 3]),
    mark_max: bool,
    overlay_labels: &[&str],
) -> Panel {
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
    let overlays = overlay_labels
        .iter()
        .enumerate()
        .map(|(k, label)| {
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
                label: (*label).to_string(),
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
            .filter(|_| mark_max)
            .map(|(x, y, v)| (x, y, format!("max {v:.4}"))),
    })
}
