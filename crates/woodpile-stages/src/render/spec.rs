//! A panel's keys, parsed once into named fields: what it draws ([`Plot`]), from which input,
//! under which filter, with which marks and visible ranges.

use polars::prelude::DataFrame;
use woodpile_plot::{
    hex_colour, markup, Colours, Dash, Mark, MarkAt, Marker, Scale, SeriesStyle, View,
};

use woodpile_pipeline::error::Result;
use woodpile_pipeline::fields::{Ends, Fields};
use woodpile_pipeline::table::Match;

use super::plotted::PlottedColumns;

/// One input table drawn as one or more panels.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelSpec {
    /// The stage whose table is drawn.
    pub input: String,
    /// A fixed title (may quote manifests); otherwise `panel_title`, `panel_label` or
    /// `panels = value`.
    pub title: Option<String>,
    /// `panel_title = "ε = {value}"`: each panel's title, `{value}` its `panels` value.
    pub panel_title: Option<String>,
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
        /// `series_style`: a curve's colour, dash, marker and legend text, by its name.
        styles: Vec<CurveStyle>,
        /// `mark_halving`: mark where each curve first falls to half its value at its
        /// smallest x.
        mark_halving: bool,
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
        z_range: ZRange,
    },
}

/// The look a `series_style` entry gives the curve it names.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveStyle {
    /// The curve's name: its y column, or its `series` label.
    pub name: String,
    /// Colour, dash, marker.
    pub style: SeriesStyle,
    /// The legend's text (markup), instead of the name.
    pub label: Option<String>,
}

/// The values a heat map's colours span.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ZRange {
    /// The data's own range (symmetric about zero for diverging colours).
    Full,
    /// Symmetric, to the 99th percentile of |z|: a few large values (the impact itself) do
    /// not wash out the rest. The default for diverging colours; the colour bar says so.
    Robust,
    /// `z_range = [lo, hi]`.
    Fixed(f64, f64),
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
    let view = parse_view(f)?;
    let marks = parse_marks(f)?;
    let lines = f.optional::<toml::Table>("lines")?;
    let heat = f.optional::<toml::Table>("heatmap")?;
    let (plot, panel_title) = match (lines, heat) {
        (Some(t), None) => parse_lines(f.nested("lines", t))?,
        (None, Some(t)) => parse_heatmap(f.nested("heatmap", t))?,
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
    if let Some(t) = &panel_title {
        markup(t).map_err(|reason| f.error("panel_title", reason))?;
    }
    Ok(PanelSpec {
        input,
        title,
        panel_title,
        panel_label,
        filter,
        marks,
        view,
        plot,
    })
}

/// A panel's ranges and scales; a log axis must start above zero.
fn parse_view(f: &mut Fields<'_>) -> Result<View> {
    let view = View {
        x: range_key(f, "x_range")?,
        y: range_key(f, "y_range")?,
        x_scale: scale_key(f, "x_scale")?,
        y_scale: scale_key(f, "y_scale")?,
    };
    for (key, scale, range) in [
        ("x_range", view.x_scale, view.x),
        ("y_range", view.y_scale, view.y),
    ] {
        if scale == Scale::Log && range.is_some_and(|(lo, _)| lo <= 0.0) {
            return Err(f.error(key, "a log axis starts above zero"));
        }
    }
    Ok(view)
}

/// A panel's `[lines]` table: the plot and the panel's title.
fn parse_lines(mut f: Fields<'_>) -> Result<(Plot, Option<String>)> {
    let panel_title = f.optional::<String>("panel_title")?;
    let styles = parse_series_styles(&mut f)?;
    let (x, panels, x_label, y_label) = shared_axes(&mut f)?;
    let plot = Plot::Lines {
        styles,
        x,
        y: f.required("y")?,
        panels,
        series: f.optional("series")?,
        series_label: f.optional("series_label")?,
        x_label,
        y_label,
        mark_halving: flag(&mut f, "mark_halving")?,
    };
    check_series(&plot, &f)?;
    f.finish()?;
    Ok((plot, panel_title))
}

/// A panel's `[heatmap]` table: the plot and the panel's title.
fn parse_heatmap(mut f: Fields<'_>) -> Result<(Plot, Option<String>)> {
    let panel_title = f.optional::<String>("panel_title")?;
    let mark_max = flag(&mut f, "mark_max")?;
    let overlays = parse_overlays(&mut f)?;
    let colours = parse_colours(&mut f)?;
    let z_range = parse_z_range(&mut f, &colours)?;
    let (x, panels, x_label, y_label) = shared_axes(&mut f)?;
    let plot = Plot::Heatmap {
        overlays,
        colours,
        z_range,
        x,
        y: f.required("y")?,
        z: f.required("z")?,
        panels,
        x_label,
        y_label,
        z_label: f.required("z_label")?,
        mark_max,
    };
    f.finish()?;
    Ok((plot, panel_title))
}

/// A heatmap's colours: `colours = "sequential"` (the default) or `"diverging"`, or named
/// `categories`.
fn parse_colours(f: &mut Fields<'_>) -> Result<Colours> {
    let categories = f.optional::<Vec<String>>("categories")?;
    match (f.optional::<String>("colours")?.as_deref(), categories) {
        (None | Some("sequential"), None) => Ok(Colours::Sequential),
        (Some("diverging"), None) => Ok(Colours::Diverging),
        (None, Some(names)) if !names.is_empty() => Ok(Colours::Categories(names)),
        (None, Some(_)) => Err(f.error("categories", "name at least one")),
        (Some(_), Some(_)) => Err(f.error("colours", "give `colours` or `categories`, not both")),
        (Some(other), None) => Err(f.error(
            "colours",
            format!("expected \"sequential\" or \"diverging\", got \"{other}\""),
        )),
    }
}

/// `x_scale = "linear" | "log"`.
/// The keys a line plot and a heat map share: the x column, the column that splits panels,
/// and the axis labels.
fn shared_axes(f: &mut Fields<'_>) -> Result<(String, Option<String>, String, String)> {
    Ok((
        f.required("x")?,
        f.optional("panels")?,
        f.required("x_label")?,
        f.required("y_label")?,
    ))
}

fn scale_key(f: &mut Fields<'_>, key: &str) -> Result<Scale> {
    f.choice(
        key,
        &[("linear", Scale::Linear), ("log", Scale::Log)],
        Some(Scale::Linear),
    )
}

/// `z_range = [lo, hi] | "robust" | "full"`; by default robust for diverging colours.
fn parse_z_range(f: &mut Fields<'_>, colours: &Colours) -> Result<ZRange> {
    match f.take("z_range") {
        None if *colours == Colours::Diverging => Ok(ZRange::Robust),
        None => Ok(ZRange::Full),
        Some(toml::Value::String(s)) if s == "robust" => Ok(ZRange::Robust),
        Some(toml::Value::String(s)) if s == "full" => Ok(ZRange::Full),
        Some(value) => {
            match <Vec<f64> as woodpile_pipeline::fields::FromToml>::from_toml(value).as_deref() {
                Some(&[lo, hi]) if lo < hi => Ok(ZRange::Fixed(lo, hi)),
                _ => Err(f.error(
                    "z_range",
                    "expected [lo, hi] with lo < hi, \"robust\" or \"full\"",
                )),
            }
        }
    }
}

/// A `[lines]` with `series` draws one y column, and `series_label` needs `series`.
fn check_series(plot: &Plot, f: &Fields<'_>) -> Result<()> {
    if let Plot::Lines {
        y,
        series,
        series_label,
        ..
    } = plot
    {
        if series.is_some() && y.len() != 1 {
            return Err(f.error("y", "with `series`, give exactly one y column"));
        }
        if series.is_none() && series_label.is_some() {
            return Err(f.error("series_label", "needs `series`"));
        }
    }
    Ok(())
}

/// `series_style = { E_tr = { colour = "#009e73", dash = "dashed", marker = "circle", label =
/// "E_{tr}" }, ... }` of a `[lines]`.
fn parse_series_styles(f: &mut Fields<'_>) -> Result<Vec<CurveStyle>> {
    let table = f
        .optional::<toml::Table>("series_style")?
        .unwrap_or_default();
    let outer = f.nested("series_style", table.clone());
    let mut styles = Vec::new();
    for (name, value) in table {
        let toml::Value::Table(t) = value else {
            return Err(outer.error(&name, "expected { colour, dash, marker, label }"));
        };
        let mut s = outer.nested(&name, t);
        let colour = named(&mut s, "colour", hex_colour, "\"#rrggbb\"")?;
        let dash = s.optional_choice("dash", &Dash::OPTIONS)?;
        let marker = s.optional_choice("marker", &Marker::OPTIONS)?;
        let label = s.optional::<String>("label")?;
        if let Some(l) = &label {
            markup(l).map_err(|reason| s.error("label", reason))?;
        }
        s.finish()?;
        styles.push(CurveStyle {
            name,
            style: SeriesStyle {
                colour,
                dash,
                marker,
            },
            label,
        });
    }
    Ok(styles)
}

/// The optional string `key` read by `parse`, or an error saying what it accepts.
fn named<T>(
    f: &mut Fields<'_>,
    key: &str,
    parse: fn(&str) -> Option<T>,
    expected: &str,
) -> Result<Option<T>> {
    match f.optional::<String>(key)? {
        None => Ok(None),
        Some(text) => parse(&text)
            .map(Some)
            .ok_or_else(|| f.error(key, format!("expected {expected}, got \"{text}\""))),
    }
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
