//! Heat-map panels: cells as one raster between their neighbours' midpoints (in plot space, so
//! geometric midpoints on a log axis), clipped at the outermost data; overlays and marks over
//! it; a colour bar or a category legend beside it.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::Scale;
use crate::chart::{chart, pixel, plot_rect, text, AxisSpan, Chart, Ticked, FONT};
use crate::colour::{diverging, viridis, Dash, Marker, CATEGORIES};
use crate::legend::{self, Entry, Glyph, Rect};
use crate::panel::{inside_place, mark_entries, marks, pixel_curves, Ranges, Shared};
use crate::style::{Corner, Legend, Style};
use crate::{Colours, HeatPanel};

const MISSING: RGBColor = RGBColor(190, 190, 190);

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

/// Cell edges as drawn: [`cell_edges`] with the outer two moved in to the first and last
/// centre, so the map (and its axis) ends at the data. A single centre keeps its unit cell.
fn drawn_edges(centres: &[f64]) -> Vec<f64> {
    let mut e = cell_edges(centres);
    if let ([first, ..], [.., last]) = (centres, centres) {
        if centres.len() > 1 {
            let n = e.len();
            (e[0], e[n - 1]) = (*first, *last);
        }
    }
    e
}

fn plot_space(centres: &[f64], scale: crate::Scale) -> Vec<f64> {
    centres.iter().map(|&c| scale.to_plot(c)).collect()
}

/// The map's ranges in plot space: its view, or its data.
pub(crate) fn ranges(h: &HeatPanel) -> Ranges {
    let (sx, sy) = (h.view.x_scale, h.view.y_scale);
    let ex = drawn_edges(&plot_space(&h.xs, sx));
    let ey = drawn_edges(&plot_space(&h.ys, sy));
    let x = h.view.x.map_or((ex[0], ex[ex.len() - 1]), |(a, b)| {
        (sx.to_plot(a), sx.to_plot(b))
    });
    let y = h.view.y.map_or((ey[0], ey[ey.len() - 1]), |(a, b)| {
        (sy.to_plot(a), sy.to_plot(b))
    });
    (x, y)
}

/// The colour of each value of a heat map, and the range its scale spans.
pub(crate) struct ColourScale<'a> {
    colours: &'a Colours,
    lo: f64,
    hi: f64,
}

impl ColourScale<'_> {
    pub(crate) fn of(h: &HeatPanel) -> ColourScale<'_> {
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
        ColourScale {
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

/// The heat map's cells as an RGB raster of `(w, h)` pixels covering the visible ranges (plot
/// space): one image instead of a rectangle per cell, so a fine space-time map stays small in
/// SVG.
fn raster(
    h: &HeatPanel,
    scale: &ColourScale<'_>,
    (w, hgt): (u32, u32),
    [x, y]: [AxisSpan; 2],
) -> Vec<u8> {
    let (x0, x1, y0, y1) = (x.lo, x.hi, y.lo, y.hi);
    let ex = drawn_edges(&plot_space(&h.xs, h.view.x_scale));
    let ey = drawn_edges(&plot_space(&h.ys, h.view.y_scale));
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

/// Overlay line colours: red and white stand out on every viridis shade.
const OVERLAY_COLOURS: [RGBColor; 3] = [RGBColor(213, 94, 0), WHITE, RGBColor(230, 159, 0)];
/// Overlay line colours on red-blue maps and category colours (whose red would hide red).
const OVERLAY_COLOURS_ON_COLOUR: [RGBColor; 3] = [BLACK, WHITE, RGBColor(204, 121, 167)];

/// Draws a heat-map panel, with its own colour bar when `own_bar`; returns how many overlay or
/// mark points its legend covers.
pub(crate) fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    h: &HeatPanel,
    style: &Style,
    shared: Shared,
    own_bar: bool,
) -> Result<usize, String> {
    let (sx, sy) = (h.view.x_scale, h.view.y_scale);
    let (main, bar, below) = panel_areas(area, h, style, own_bar);
    let ((x0, x1), (y0, y1)) = shared.apply(&h.view, ranges(h));
    let scale = ColourScale::of(h);
    let x = AxisSpan {
        lo: x0,
        hi: x1,
        scale: sx,
    };
    let y = AxisSpan {
        lo: y0,
        hi: y1,
        scale: sy,
    };
    let chart = chart(&main, x, y, style, Some((&h.x_label, &h.y_label, false)))?;
    let size = chart.plotting_area().dim_in_pixel();
    if size.0 > 0 && size.1 > 0 {
        let pixels = raster(h, &scale, size, [x, y]);
        let image = BitMapElement::with_owned_buffer((x0, y1), size, pixels)
            .ok_or("heat-map raster of the wrong size")?;
        chart.plotting_area().draw(&image).map_err(text)?;
    }
    let rect = plot_rect(&chart);
    if let Some(marker) = &h.marker {
        draw_marker(area, &chart, &rect, marker, (sx, sy), style)?;
    }
    let curves: Vec<Vec<(f64, f64)>> = h
        .overlays
        .iter()
        .map(|o| {
            o.points
                .iter()
                .map(|&(x, y)| (sx.to_plot(x).clamp(x0, x1), sy.to_plot(y).clamp(y0, y1)))
                .collect()
        })
        .collect();
    let lines = pixel_curves(&chart, &curves);
    let mut entries = draw_overlays(area, h, &lines, &rect, style)?;
    let mark_lines = marks(area, &chart, &h.marks, (sx, sy), style)?;
    entries.extend(mark_entries(&h.marks));
    if let Some(bar) = bar {
        match &h.colours {
            Colours::Categories(names) => category_legend(&bar, names, style)?,
            _ => colour_bar(&bar, h, style)?,
        }
    }
    if entries.is_empty() || style.legend == Legend::None {
        return Ok(0);
    }
    let all: Vec<Vec<(f64, f64)>> = lines.into_iter().chain(mark_lines).collect();
    let dense = legend::dense(&all, 2.0);
    let size = legend::measure(area, &entries, style);
    let at = match &below {
        Some(b) => {
            let (bx, by) = b.get_base_pixel();
            (
                bx as f64 + 0.5 * (b.dim_in_pixel().0 as f64 - size.0),
                by as f64 + style.pt(2.0),
            )
        }
        None => inside_place(style.legend, &rect, size, &dense, style)
            .unwrap_or_else(|| legend::inside(Corner::UpperLeft, &rect, size, style)),
    };
    legend::draw(area, &entries, at, style)?;
    Ok(legend::covered(&dense, at, size, style))
}

/// A heat panel's areas: the map, its own colour bar (when it has one) on the right, and a
/// strip under the map for the overlay and mark legends (the map has no free corner).
#[allow(clippy::type_complexity)]
fn panel_areas<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    h: &HeatPanel,
    style: &Style,
    own_bar: bool,
) -> (
    DrawingArea<DB, Shift>,
    Option<DrawingArea<DB, Shift>>,
    Option<DrawingArea<DB, Shift>>,
) {
    let width = area.dim_in_pixel().0;
    let bar_width = match &h.colours {
        Colours::Categories(names) => {
            legend::measure(area, &category_entries(names), style).0 + style.pt(6.0)
        }
        _ => style.mm(17.0),
    };
    let (main, bar) = if own_bar {
        let (m, b) = area.split_horizontally(width.saturating_sub(bar_width as u32));
        (m, Some(b))
    } else {
        (area.clone(), None)
    };
    let entry_count = h.overlays.len() + mark_entries(&h.marks).len();
    if entry_count > 0 && style.legend != Legend::None && !matches!(style.legend, Legend::Inside(_))
    {
        let rows = entry_count as f64 * style.font(1.35) + style.pt(8.0);
        let (m, b) = main.split_vertically((main.dim_in_pixel().1 as f64 - rows).max(1.0) as u32);
        (m, bar, Some(b))
    } else {
        (main, bar, None)
    }
}

/// The map's marked point (the maximum): a white circle and its label, above the circle, or
/// below it near the top edge.
fn draw_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &Chart<'_, DB>,
    rect: &Rect,
    (x, y, label): &(f64, f64, String),
    (sx, sy): (Scale, Scale),
    style: &Style,
) -> Result<(), String> {
    let at = pixel(chart, (sx.to_plot(*x), sy.to_plot(*y)));
    let r = style.pt(3.0);
    let (bx, by) = area.get_base_pixel();
    let (cx, cy) = (at.0 as i32 - bx, at.1 as i32 - by);
    area.draw(&Circle::new(
        (cx, cy),
        r as i32,
        ShapeStyle::from(&WHITE).stroke_width(style.stroke(0.8)),
    ))
    .map_err(text)?;
    let font = (FONT, style.font(1.0)).into_font().color(&WHITE);
    let dy = if at.1 - rect.y0 < 3.0 * style.font(1.0) {
        r as i32
    } else {
        -(r as i32) - style.font(1.0) as i32
    };
    area.draw(&Text::new(label.clone(), (cx + r as i32, cy + dy), font))
        .map_err(text)
}

/// Each overlay curve at its pixel `lines`, in the overlay colours that read on the map's
/// colours; their legend entries.
fn draw_overlays<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    h: &HeatPanel,
    lines: &[Vec<(f64, f64)>],
    rect: &Rect,
    style: &Style,
) -> Result<Vec<Entry>, String> {
    let overlay_colours = match h.colours {
        Colours::Sequential => OVERLAY_COLOURS,
        Colours::Diverging | Colours::Categories(_) => OVERLAY_COLOURS_ON_COLOUR,
    };
    let mut entries = Vec::new();
    for (k, (overlay, line)) in h.overlays.iter().zip(lines).enumerate() {
        let colour = overlay_colours[k % overlay_colours.len()];
        for segment in line.split(|q| !(q.0.is_finite() && q.1.is_finite())) {
            legend::polyline(area, segment, rect, (colour, Dash::Solid, 1.5), style)?;
        }
        entries.push(Entry {
            label: overlay.label.clone(),
            glyph: Glyph::Line {
                colour,
                dash: Dash::Solid,
                marker: Marker::None,
                width_pt: 1.5,
            },
        });
    }
    Ok(entries)
}

/// The map's colour scale as a strip with its own labelled axis, its label written level
/// above it so that it reads at print size.
pub(crate) fn colour_bar<DB: DrawingBackend>(
    bar: &DrawingArea<DB, Shift>,
    h: &HeatPanel,
    style: &Style,
) -> Result<(), String> {
    let scale = ColourScale::of(h);
    let (z0, z1) = (scale.lo, scale.hi);
    let font = (FONT, style.font(1.0)).into_font().color(&BLACK);
    let width = bar.dim_in_pixel().0 as f64 - style.pt(2.0);
    let lines = crate::chart::wrap(bar, &h.z_label, width, &font);
    let line = style.font(1.0) * 1.25;
    let (top, rest) = bar.split_vertically((lines.len() as f64 * line + style.pt(4.0)) as u32);
    for (k, text) in lines.into_iter().enumerate() {
        top.draw(&Text::new(
            text,
            (
                style.pt(2.0) as i32,
                (style.pt(2.0) + k as f64 * line) as i32,
            ),
            font.clone(),
        ))
        .map_err(crate::chart::text)?;
    }
    let (major, _) = crate::Scale::Linear.ticks(z0, z1, 6);
    let mut bar_chart = ChartBuilder::on(&rest)
        .margin_top(style.pt(2.0) as u32)
        .margin_bottom(style.font(2.9) as u32)
        .margin_left(style.pt(2.0) as u32)
        .right_y_label_area_size(style.font(3.6) as u32)
        .build_cartesian_2d(0.0..1.0, Ticked::new(z0, z1, (major, Vec::new())))
        .map_err(text)?;
    bar_chart
        .configure_mesh()
        .disable_x_axis()
        .disable_mesh()
        .y_label_formatter(&crate::axis::tick)
        .label_style((FONT, style.font(1.0)))
        .set_all_tick_mark_size(style.pt(2.0) as u32)
        .draw()
        .map_err(text)?;
    let steps = 200;
    let strip = (0..steps).map(|k| {
        let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
        let (va, vb) = (z0 + a * (z1 - z0), z0 + b * (z1 - z0));
        Rectangle::new(
            [(0.0, va), (1.0, vb)],
            scale.colour(Some(z0 + 0.5 * (a + b) * (z1 - z0))).filled(),
        )
    });
    bar_chart.draw_series(strip).map_err(text)?;
    Ok(())
}

pub(crate) fn category_entries(names: &[String]) -> Vec<Entry> {
    names
        .iter()
        .enumerate()
        .map(|(k, name)| Entry {
            label: name.clone(),
            glyph: Glyph::Swatch(CATEGORIES[k % CATEGORIES.len()]),
        })
        .collect()
}

/// A legend of named categories in place of a colour bar: a swatch and a name each.
pub(crate) fn category_legend<DB: DrawingBackend>(
    bar: &DrawingArea<DB, Shift>,
    names: &[String],
    style: &Style,
) -> Result<(), String> {
    let entries = category_entries(names);
    let (bx, by) = bar.get_base_pixel();
    legend::draw(
        bar,
        &entries,
        (bx as f64 + style.pt(2.0), by as f64 + style.font(3.0)),
        style,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_surround_the_centres_and_drawn_ones_stop_at_the_data() {
        assert_eq!(cell_edges(&[1.0, 2.0, 4.0]), vec![0.5, 1.5, 3.0, 5.0]);
        assert_eq!(cell_edges(&[3.0]), vec![2.5, 3.5]);
        assert_eq!(drawn_edges(&[1.0, 2.0, 4.0]), vec![1.0, 1.5, 3.0, 4.0]);
        assert_eq!(drawn_edges(&[3.0]), vec![2.5, 3.5]);
    }

    #[test]
    fn on_a_log_axis_cells_meet_at_geometric_midpoints() {
        let xs = [0.1, 1.0, 10.0];
        let edges = drawn_edges(&plot_space(&xs, crate::Scale::Log));
        let back: Vec<f64> = edges
            .iter()
            .map(|&u| crate::Scale::Log.from_plot(u))
            .collect();
        assert!((back[1] - (0.1f64 * 1.0).sqrt()).abs() < 1e-12);
        assert!((back[2] - 10f64.sqrt()).abs() < 1e-12);
        assert!((back[3] - 10.0).abs() < 1e-12);
    }
}
