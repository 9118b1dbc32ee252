//! The drawing itself, generic over the backend so PNG and SVG are the same picture.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::colour::viridis;
use crate::{Figure, HeatPanel, LinePanel, Panel};

/// Height of the figure title strip in pixels.
pub(crate) const TITLE_HEIGHT: u32 = 36;
const FONT: &str = "sans-serif";
/// Line colours (matplotlib's tab10, which prints and projects well).
/// Its grey is left out: it is too close to [`MISSING`].
const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];
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

fn lines<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &LinePanel) -> Result<(), String> {
    let all = || p.series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) = range(all().map(|q| q.0));
    let (y0, y1) = range(all().map(|q| q.1));
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
    // One curve is named by the y label; a legend would only hide data.
    if p.series.len() > 1 {
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

/// Overlay line colours: red and white stand out on every viridis shade.
const OVERLAY_COLOURS: [RGBColor; 3] = [RGBColor(230, 30, 40), WHITE, RGBColor(255, 140, 0)];

fn heat<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, h: &HeatPanel) -> Result<(), String> {
    let width = area.dim_in_pixel().0;
    let (main, bar) = area.split_horizontally(width.saturating_sub(100));
    let (ex, ey) = (cell_edges(&h.xs), cell_edges(&h.ys));
    let (z0, z1) = {
        let (lo, hi) =
            h.z.iter()
                .flatten()
                .filter(|v| v.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), &v| {
                    (l.min(v), u.max(v))
                });
        if !lo.is_finite() {
            (0.0, 1.0)
        } else if hi > lo {
            (lo, hi)
        } else {
            (lo - 0.5, lo + 0.5)
        }
    };
    let scale = |v: f64| (v - z0) / (z1 - z0);
    let mut chart = ChartBuilder::on(&main)
        .caption(&h.title, (FONT, 16))
        .margin(10)
        .x_label_area_size(42)
        .y_label_area_size(58)
        .build_cartesian_2d(ex[0]..ex[ex.len() - 1], ey[0]..ey[ey.len() - 1])
        .map_err(text)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .x_desc(&h.x_label)
        .y_desc(&h.y_label)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(text)?;
    let nx = h.xs.len();
    let cells = (0..h.ys.len())
        .flat_map(|j| (0..nx).map(move |i| (i, j)))
        .map(|(i, j)| {
            let colour = match h.z.get(j * nx + i).copied().flatten() {
                Some(v) if v.is_finite() => viridis(scale(v)),
                _ => MISSING,
            };
            Rectangle::new([(ex[i], ey[j]), (ex[i + 1], ey[j + 1])], colour.filled())
        });
    chart.draw_series(cells).map_err(text)?;
    if let Some((x, y, label)) = &h.marker {
        chart
            .draw_series([EmptyElement::at((*x, *y))
                + Circle::new((0, 0), 6, ShapeStyle::from(&WHITE).stroke_width(2))
                + Text::new(
                    label.clone(),
                    (8, -16),
                    (FONT, 13).into_font().color(&WHITE),
                )])
            .map_err(text)?;
    }
    // Overlay lines, clamped to the map, in colours that read on viridis, with a legend.
    let (x_range, y_range) = (ex[0]..=ex[ex.len() - 1], ey[0]..=ey[ey.len() - 1]);
    for (k, overlay) in h.overlays.iter().enumerate() {
        let colour = OVERLAY_COLOURS[k % OVERLAY_COLOURS.len()];
        let points: Vec<(f64, f64)> = overlay
            .points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|&(x, y)| {
                (
                    x.clamp(*x_range.start(), *x_range.end()),
                    y.clamp(*y_range.start(), *y_range.end()),
                )
            })
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
    if !h.overlays.is_empty() {
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    }
    // Colour bar: the map's scale as a strip with its own labelled axis.
    let mut bar_chart = ChartBuilder::on(&bar)
        .margin_top(40)
        .margin_bottom(52)
        .margin_right(8)
        .right_y_label_area_size(62)
        .build_cartesian_2d(0.0..1.0, z0..z1)
        .map_err(text)?;
    bar_chart
        .configure_mesh()
        .disable_x_axis()
        .disable_x_mesh()
        .disable_y_mesh()
        .y_desc(&h.z_label)
        .label_style((FONT, 11))
        .axis_desc_style((FONT, 13))
        .draw()
        .map_err(text)?;
    let steps = 120;
    let strip = (0..steps).map(|k| {
        let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
        let (va, vb) = (z0 + a * (z1 - z0), z0 + b * (z1 - z0));
        Rectangle::new([(0.0, va), (1.0, vb)], viridis(0.5 * (a + b)).filled())
    });
    bar_chart.draw_series(strip).map_err(text)?;
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
}
