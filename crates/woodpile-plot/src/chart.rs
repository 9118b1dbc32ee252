//! A chart on a drawing area: plot-space axes ticked where the [`Scale`]s say, the mesh and
//! its labels, and the conversions from plot space to backend pixels.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::Scale;
use crate::legend::Rect;
use crate::style::Style;

/// The typeface of every label.
pub(crate) const FONT: &str = "sans-serif";

/// A chart whose axes tick where [`Scale::ticks`] says.
pub(crate) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<Ticked, Ticked>>;

/// A plot-space axis from `lo` to `hi` with its tick positions chosen in advance (plotters'
/// own would tick a log axis at log10 values).
#[derive(Debug, Clone)]
pub(crate) struct Ticked {
    lo: f64,
    hi: f64,
    major: Vec<f64>,
    minor: Vec<f64>,
}

impl Ticked {
    pub(crate) fn new(lo: f64, hi: f64, (major, minor): (Vec<f64>, Vec<f64>)) -> Ticked {
        Ticked {
            lo,
            hi,
            major,
            minor,
        }
    }
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let f = (value - self.lo) / (self.hi - self.lo);
        limit.0 + (f * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.major.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

pub(crate) fn text<E: std::fmt::Debug>(e: E) -> String {
    format!("{e:?}")
}

/// One axis of a chart: its visible range in plot space, and the scale that maps values there.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AxisSpan {
    /// The range's low end, in plot space.
    pub lo: f64,
    /// Its high end.
    pub hi: f64,
    /// How a value is placed on the axis and labelled.
    pub scale: Scale,
}

/// Builds a chart on `area` over the axes `x` and `y`, ticked by their scales, with its mesh
/// drawn.
pub(crate) fn chart<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    x: AxisSpan,
    y: AxisSpan,
    style: &Style,
    draw_mesh: Option<(&str, &str, bool)>,
) -> Result<Chart<'a, DB>, String> {
    let AxisSpan {
        lo: x0,
        hi: x1,
        scale: sx,
    } = x;
    let AxisSpan {
        lo: y0,
        hi: y1,
        scale: sy,
    } = y;
    let (w, h) = area.dim_in_pixel();
    let keep_minor = |(major, minor): (Vec<f64>, Vec<f64>)| {
        (major, if style.minor_grid { minor } else { Vec::new() })
    };
    let xticks = keep_minor(sx.ticks(x0, x1, ((w as f64 / style.pt(48.0)) as usize).clamp(3, 8)));
    let yticks = keep_minor(sy.ticks(y0, y1, ((h as f64 / style.pt(28.0)) as usize).clamp(3, 8)));
    let right = right_margin(area, &xticks.0, x, style);
    let mut chart = ChartBuilder::on(area)
        .margin(style.pt(4.0) as u32)
        .margin_right(right)
        .x_label_area_size(style.font(2.9) as u32)
        .y_label_area_size(style.font(4.4) as u32)
        .build_cartesian_2d(Ticked::new(x0, x1, xticks), Ticked::new(y0, y1, yticks))
        .map_err(text)?;
    if let Some((x_label, y_label, grid)) = draw_mesh {
        let xf = move |u: &f64| sx.label(*u);
        let yf = move |u: &f64| sy.label(*u);
        let mut mesh = chart.configure_mesh();
        mesh.x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&xf)
            .y_label_formatter(&yf)
            .label_style((FONT, style.font(1.0)))
            .axis_desc_style((FONT, style.font(1.0)))
            .set_all_tick_mark_size(style.pt(2.0) as u32)
            .axis_style(ShapeStyle::from(&BLACK).stroke_width(style.stroke(0.5)))
            .bold_line_style(RGBColor(226, 226, 226).stroke_width(style.stroke(0.3)))
            .light_line_style(RGBColor(244, 244, 244).stroke_width(style.stroke(0.25)));
        if !grid {
            mesh.disable_mesh();
        }
        mesh.draw().map_err(text)?;
    }
    Ok(chart)
}

/// The chart's right margin: the usual 4 pt, or, when the last x tick sits at the right end of
/// the axis, room for the half of its label (centred on the tick) that lies past it, so that
/// "100" is not cut to "10".
fn right_margin<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    ticks: &[f64],
    x: AxisSpan,
    style: &Style,
) -> u32 {
    let AxisSpan {
        lo: x0,
        hi: x1,
        scale: sx,
    } = x;
    let usual = style.pt(4.0);
    let Some(&last) = ticks.last() else {
        return usual as u32;
    };
    let (w, _) = area.dim_in_pixel();
    // How far short of the right end the tick is, in pixels (the plot is most of the area).
    let short = (x1 - last) / (x1 - x0) * (w as f64 - usual - style.font(4.4));
    let font = TextStyle::from((FONT, style.font(1.0)).into_font());
    let half = area
        .estimate_text_size(&sx.label(last), &font)
        .map_or(0.0, |(tw, _)| 0.5 * tw as f64);
    (half - short + style.pt(1.0)).max(usual) as u32
}

/// The plotting rectangle of `chart` in backend pixels.
pub(crate) fn plot_rect<DB: DrawingBackend, CT: CoordTranslate>(
    chart: &ChartContext<'_, DB, CT>,
) -> Rect {
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    Rect {
        x0: xr.start as f64,
        y0: yr.start as f64,
        x1: xr.end as f64,
        y1: yr.end as f64,
    }
}

/// `(x, y)` in plot space as backend pixels.
pub(crate) fn pixel<DB: DrawingBackend>(chart: &Chart<'_, DB>, (x, y): (f64, f64)) -> (f64, f64) {
    let (px, py) = chart.backend_coord(&(x, y));
    (px as f64, py as f64)
}

/// `text` broken at spaces into lines no wider than `width` pixels.
pub(crate) fn wrap<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    width: f64,
    font: &TextStyle<'_>,
) -> Vec<String> {
    let fits = |s: &str| {
        area.estimate_text_size(s, font)
            .map_or(true, |(w, _)| w as f64 <= width)
    };
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(line) if fits(&format!("{line} {word}")) => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}
