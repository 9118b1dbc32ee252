//! A panel's keys, parsed once into named fields: what it draws ([`Plot`]), from which input,
//! under which filter, with which marks and visible ranges.

use polars::prelude::DataFrame;
use woodpile_plot::{Colours, Mark, MarkAt, View};

use woodpile_pipeline::error::Result;
use woodpile_pipeline::fields::{Ends, Fields};
use woodpile_pipeline::table::Match;

use super::plotted::PlottedColumns;

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
    pub filter: Vec<(String, Match)>,
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

pub(super) fn flag(fields: &mut Fields<'_>, key: &str) -> Result<bool> {
    match fields.take(key) {
        None => Ok(false),
        Some(toml::Value::Boolean(b)) => Ok(b),
        Some(_) => Err(fields.error(key, "expected true or false")),
    }
}

pub(super) fn range_key(f: &mut Fields<'_>, key: &str) -> Result<Option<(f64, f64)>> {
    Ok(f.interval(key, Ends::Apart)?.map(|[lo, hi]| (lo, hi)))
}

/// The keys of one panel (at the top level in the simple form).
pub(super) fn parse_panel(
    f: &mut Fields<'_>,
    input: String,
    title: Option<String>,
) -> Result<PanelSpec> {
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
pub(super) fn parse_marks(f: &mut Fields<'_>) -> Result<Vec<Mark>> {
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
pub(super) fn parse_overlays(f: &mut Fields<'_>) -> Result<Vec<(String, String)>> {
    f.table_array("overlay", "{ x = \"column\", label = \"text\" }")?
        .into_iter()
        .map(|mut o| {
            let overlay = (o.required("x")?, o.required("label")?);
            o.finish()?;
            Ok(overlay)
        })
        .collect()
}

impl PanelSpec {
    /// Every column the spec names exists in `input`, or the error names the key, the input,
    /// the columns there are and the nearest one.
    pub(super) fn check_columns(&self, input: &DataFrame) -> std::result::Result<(), String> {
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
    pub(super) fn columns(&self) -> PlottedColumns {
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
}
