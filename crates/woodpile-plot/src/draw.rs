//! The drawing itself, generic over the backend so PNG and SVG are the same picture.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::colour::{diverging, viridis, CATEGORIES, PALETTE};
use crate::{Colours, Figure, HeatPanel, LinePanel, Mark, MarkAt, Panel};

/// Height of the figure title strip in pixels.
pub(crate) const TITLE_HEIGHT: u32 = 36;
const FONT: &str = "sans-serif";
const MISSING: RGBColor = RGBColor(190, 190, 190);

fn text<E: std::fmt::Debug>(e: E) -> String {
    format!("{e:?}")
}

/// The legend of every labelled series, framed on a translucent white box at `position`.
fn legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 12))
        .draw()
        .map_err(text)
}

pub(crate) fn figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(text)?;
    let (top, body) = root.split_vertically(TITLE_HEIGHT);
    // Shrink a long title to the width rather than cut it (DejaVu Sans averages ~0.55 em).
    let width = root.dim_in_pixel().0 as f64;
    let chars = fig.title.chars().count().max(1) as f64;
    let size = (width - 20.0) / (0.55 * chars);
    top.draw(&Text::new(
        fig.title.clone(),
        (10, 8),
        (FONT, size.clamp(10.0, 20.0)).into_font().color(&BLACK),
    ))
    .map_err(text)?;
    let columns = fig.columns.max(1);
    let rows = fig.panels.len().div_ceil(columns).max(1);
    let areas = body.split_evenly((rows, columns));
    for (panel, area) in fig.panels.iter().zip(areas.iter()) {
        match panel {
            Panel::Lines(p) => lines(area, p)?,
            Panel::Heat(h) => heat(area, h)?,
        }
    }
    Ok(())
}

/// The finite range of `values`, padded by 5%, or (0, 1).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1e-3)
    };
    (lo - pad, hi + pad)
}

/// A tick label: integers without a decimal point (`10`, not `10.0`), other values with at
/// most four significant decimals, and never `-0`.
pub fn tick(v: &f64) -> String {
    let v = if v.abs() < 1e-12 { 0.0 } else { *v };
    if (v - v.round()).abs() <= 1e-9 * v.abs().max(1.0) && v.abs() < 1e15 {
        return format!("{}", v.round() as i64);
    }
    let magnitude = v.abs().log10().floor();
    if !(-4.0..6.0).contains(&magnitude) {
        return format!("{v:.2e}");
    }
    let decimals = (3.0 - magnitude).clamp(0.0, 8.0) as usize;
    let text = format!("{v:.decimals$}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// Mark colours: dark grey and black read on white and on every map colour.
const MARK_COLOURS: [RGBColor; 2] = [RGBColor(60, 60, 60), BLACK];

/// Draws `marks` across the visible ranges, one legend entry per distinct label.
fn draw_marks<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    marks: &[Mark],
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Result<(), String> {
    let mut labels: Vec<&str> = Vec::new();
    for mark in marks {
        let k = match labels.iter().position(|l| *l == mark.label) {
            Some(k) => k,
            None => {
                labels.push(&mark.label);
                labels.len() - 1
            }
        };
        let colour = MARK_COLOURS[k % MARK_COLOURS.len()];
        let style = ShapeStyle::from(&colour).stroke_width(2);
        let points = match mark.at {
            MarkAt::X(x) => vec![(x, y0), (x, y1)],
            MarkAt::Y(y) => vec![(x0, y), (x1, y)],
        };
        let drawn = chart
            .draw_series(DashedLineSeries::new(points, 8, 5, style))
            .map_err(text)?;
        if first_of(marks, mark) {
            drawn
                .label(mark.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
        }
    }
    Ok(())
}

/// Whether `mark` is the first of `marks` with its label.
fn first_of(marks: &[Mark], mark: &Mark) -> bool {
    marks
        .iter()
        .find(|m| m.label == mark.label)
        .is_some_and(|m| std::ptr::eq(m, mark))
}

fn lines<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &LinePanel) -> Result<(), String> {
    let all = || p.series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) = p.view.x.unwrap_or_else(|| range(all().map(|q| q.0)));
    let (y0, y1) = p.view.y.unwrap_or_else(|| range(all().map(|q| q.1)));
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT, 16))
        .margin(10)
        .x_label_area_size(42)
        .y_label_area_size(58)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(text)?;
    chart
        .configure_mesh()
        .x_desc(&p.x_label)
        .y_desc(&p.y_label)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 14))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(text)?;
    for (k, series) in p.series.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let style = ShapeStyle::from(&colour).stroke_width(2);
        // A non-finite value (a failed point) breaks the line rather than bridging the gap.
        let segments: Vec<Vec<(f64, f64)>> = series
            .points
            .split(|q| !(q.0.is_finite() && q.1.is_finite()))
            .filter(|s| !s.is_empty())
            .map(|s| s.to_vec())
            .collect();
        let sparse = series.points.len() <= 40;
        for (i, segment) in segments.into_iter().enumerate() {
            if sparse {
                // Few points: mark each, so a reader sees where the data are.
                let dots = segment.iter().map(|&q| Circle::new(q, 3, colour.filled()));
                chart.draw_series(dots).map_err(text)?;
            }
            let drawn = chart
                .draw_series(LineSeries::new(segment, style))
                .map_err(text)?;
            if i == 0 {
                drawn
                    .label(series.label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
            }
        }
    }
    draw_marks(&mut chart, &p.marks, (x0, x1), (y0, y1))?;
    // One curve is named by the y label; a legend would only hide data.
    if p.series.len() > 1 || !p.marks.is_empty() {
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    }
    Ok(())
}

/// Cell edges around increasing centres: midpoints inside, half a spacing beyond the ends.
pub fn cell_edges(centres: &[f64]) -> Vec<f64> {
    match centres {
        [] => vec![0.0, 1.0],
        [c] => vec![c - 0.5, c + 0.5],
        _ => {
            let n = centres.len();
            let mut e = Vec::with_capacity(n + 1);
            e.push(centres[0] - 0.5 * (centres[1] - centres[0]));
            e.extend(centres.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            e.push(centres[n - 1] + 0.5 * (centres[n - 1] - centres[n - 2]));
            e
        }
    }
}

/// The colour of each value of a heat map, and the range its scale spans.
struct Scale<'a> {
    colours: &'a Colours,
    lo: f64,
    hi: f64,
}

impl Scale<'_> {
    fn of(h: &HeatPanel) -> Scale<'_> {
        let (lo, hi) = h.z_range.unwrap_or_else(|| {
            let (lo, hi) = h.value_range();
            match (&h.colours, lo.is_finite()) {
                (_, false) => (0.0, 1.0),
                (Colours::Diverging, true) => {
                    let m = lo.abs().max(hi.abs()).max(f64::MIN_POSITIVE);
                    (-m, m)
                }
                (_, true) if hi > lo => (lo, hi),
                (_, true) => (lo - 0.5, lo + 0.5),
            }
        });
        Scale {
            colours: &h.colours,
            lo,
            hi,
        }
    }

    fn colour(&self, v: Option<f64>) -> RGBColor {
        let Some(v) = v.filter(|v| v.is_finite()) else {
            return MISSING;
        };
        let t = (v - self.lo) / (self.hi - self.lo);
        match self.colours {
            Colours::Sequential => viridis(t),
            Colours::Diverging => diverging(t),
            Colours::Categories(_) => {
                let k = v.round();
                if k >= 0.0 && (k as usize) < CATEGORIES.len() {
                    CATEGORIES[k as usize]
                } else {
                    MISSING
                }
            }
        }
    }
}

/// The heat map's cells as an RGB raster of `(w, h)` pixels covering the visible ranges: one
/// image instead of a rectangle per cell, so a fine space-time map stays small in SVG.
fn raster(
    h: &HeatPanel,
    scale: &Scale<'_>,
    (w, hgt): (u32, u32),
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Vec<u8> {
    let (ex, ey) = (cell_edges(&h.xs), cell_edges(&h.ys));
    let cell = |edges: &[f64], v: f64| -> Option<usize> {
        let k = edges.partition_point(|&e| e <= v);
        (k >= 1 && k < edges.len()).then(|| k - 1)
    };
    let columns: Vec<Option<usize>> = (0..w)
        .map(|px| cell(&ex, x0 + (px as f64 + 0.5) / w as f64 * (x1 - x0)))
        .collect();
    let mut buf = Vec::with_capacity((w * hgt * 3) as usize);
    for py in 0..hgt {
        // Pixel rows run top down; y runs bottom up.
        let row = cell(&ey, y1 - (py as f64 + 0.5) / hgt as f64 * (y1 - y0));
        for column in &columns {
            let colour = match (column, row) {
                (Some(i), Some(j)) => scale.colour(h.z.get(j * h.xs.len() + i).copied().flatten()),
                _ => WHITE,
            };
            buf.extend_from_slice(&[colour.0, colour.1, colour.2]);
        }
    }
    buf
}

fn heat<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, h: &HeatPanel) -> Result<(), String> {
    let width = area.dim_in_pixel().0;
    let (main, bar) = area.split_horizontally(width.saturating_sub(112));
    let (ex, ey) = (cell_edges(&h.xs), cell_edges(&h.ys));
    let scale = Scale::of(h);
    let (x0, x1) = h.view.x.unwrap_or((ex[0], ex[ex.len() - 1]));
    let (y0, y1) = h.view.y.unwrap_or((ey[0], ey[ey.len() - 1]));
    let mut chart = ChartBuilder::on(&main)
        .caption(&h.title, (FONT, 16))
        .margin(10)
        .x_label_area_size(42)
        .y_label_area_size(58)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(text)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .x_desc(&h.x_label)
        .y_desc(&h.y_label)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(text)?;
    let size = chart.plotting_area().dim_in_pixel();
    if size.0 > 0 && size.1 > 0 {
        let pixels = raster(h, &scale, size, (x0, x1), (y0, y1));
        let image = BitMapElement::with_owned_buffer((x0, y1), size, pixels)
            .ok_or("heat-map raster of the wrong size")?;
        chart.draw_series([image]).map_err(text)?;
    }
    if let Some((x, y, label)) = &h.marker {
        // The label goes above the circle, or below it near the top edge (the title's place).
        let offset = if *y > y1 - 0.12 * (y1 - y0) {
            (8, 4)
        } else {
            (8, -16)
        };
        chart
            .draw_series([EmptyElement::at((*x, *y))
                + Circle::new((0, 0), 6, ShapeStyle::from(&WHITE).stroke_width(2))
                + Text::new(label.clone(), offset, (FONT, 13).into_font().color(&WHITE))])
            .map_err(text)?;
    }
    // Overlay lines, clamped to the view, in colours that read on every map, with a legend.
    let overlay_colours = match h.colours {
        Colours::Sequential => OVERLAY_COLOURS,
        Colours::Diverging | Colours::Categories(_) => OVERLAY_COLOURS_ON_COLOUR,
    };
    for (k, overlay) in h.overlays.iter().enumerate() {
        let colour = overlay_colours[k % overlay_colours.len()];
        let points: Vec<(f64, f64)> = overlay
            .points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|&(x, y)| (x.clamp(x0, x1), y.clamp(y0, y1)))
            .collect();
        chart
            .draw_series(LineSeries::new(
                points,
                ShapeStyle::from(&colour).stroke_width(3),
            ))
            .map_err(text)?
            .label(overlay.label.clone())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(3)));
    }
    draw_marks(&mut chart, &h.marks, (x0, x1), (y0, y1))?;
    if !h.overlays.is_empty() || !h.marks.is_empty() {
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    }
    match &h.colours {
        Colours::Categories(names) => category_legend(&bar, names),
        _ => colour_bar(&bar, h, &scale),
    }
}

/// Overlay line colours: red and white stand out on every viridis shade.
const OVERLAY_COLOURS: [RGBColor; 3] = [RGBColor(230, 30, 40), WHITE, RGBColor(255, 140, 0)];
/// Overlay line colours on red-blue maps and category colours (whose red would hide red).
const OVERLAY_COLOURS_ON_COLOUR: [RGBColor; 3] = [BLACK, WHITE, RGBColor(148, 103, 189)];

/// The map's scale as a strip with its own labelled axis.
fn colour_bar<DB: DrawingBackend>(
    bar: &DrawingArea<DB, Shift>,
    h: &HeatPanel,
    scale: &Scale<'_>,
) -> Result<(), String> {
    let (z0, z1) = (scale.lo, scale.hi);
    let mut bar_chart = ChartBuilder::on(bar)
        .margin_top(40)
        .margin_bottom(52)
        .margin_right(22)
        .right_y_label_area_size(60)
        .build_cartesian_2d(0.0..1.0, z0..z1)
        .map_err(text)?;
    bar_chart
        .configure_mesh()
        .disable_x_axis()
        .disable_x_mesh()
        .disable_y_mesh()
        .y_desc(&h.z_label)
        .y_label_formatter(&tick)
        .label_style((FONT, 11))
        .axis_desc_style((FONT, 13))
        .draw()
        .map_err(text)?;
    let steps = 120;
    let strip = (0..steps).map(|k| {
        let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
        let (va, vb) = (z0 + a * (z1 - z0), z0 + b * (z1 - z0));
        let mid = z0 + 0.5 * (a + b) * (z1 - z0);
        Rectangle::new([(0.0, va), (1.0, vb)], scale.colour(Some(mid)).filled())
    });
    bar_chart.draw_series(strip).map_err(text)?;
    Ok(())
}

/// A legend of named categories in place of a colour bar: a swatch and a name each.
fn category_legend<DB: DrawingBackend>(
    bar: &DrawingArea<DB, Shift>,
    names: &[String],
) -> Result<(), String> {
    for (k, name) in names.iter().enumerate() {
        let y = 50 + 24 * k as i32;
        let colour = CATEGORIES[k % CATEGORIES.len()];
        bar.draw(&Rectangle::new([(6, y), (20, y + 14)], colour.filled()))
            .map_err(text)?;
        bar.draw(&Text::new(
            name.clone(),
            (26, y),
            (FONT, 12).into_font().color(&BLACK),
        ))
        .map_err(text)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_surround_the_centres() {
        assert_eq!(cell_edges(&[1.0, 2.0, 4.0]), vec![0.5, 1.5, 3.0, 5.0]);
        assert_eq!(cell_edges(&[3.0]), vec![2.5, 3.5]);
        assert_eq!(range([1.0, f64::NAN, 3.0].into_iter()), (0.9, 3.1));
    }

    #[test]
    fn ticks_print_integers_as_integers_and_never_minus_zero() {
        assert_eq!(tick(&10.0), "10");
        assert_eq!(tick(&-0.0), "0");
        assert_eq!(tick(&-1e-17), "0");
        assert_eq!(tick(&0.25), "0.25");
        assert_eq!(tick(&(0.1 + 0.2)), "0.3");
        assert_eq!(tick(&-2.5), "-2.5");
        assert_eq!(tick(&1.5e-7), "1.50e-7");
    }
}
