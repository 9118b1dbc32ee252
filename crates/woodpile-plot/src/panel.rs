//! What line panels ([`crate::draw`]) and heat maps ([`crate::heat`]) share: a panel's ranges
//! and the ranges a figure's panels share, marks and their legend entries, where an inside
//! legend goes, and curves in backend pixels. Both panel kinds use it; it uses neither.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::Scale;
use crate::chart::{pixel, plot_rect, Chart};
use crate::colour::{Dash, Marker};
use crate::legend::{self, Entry, Glyph, Rect};
use crate::style::{Corner, Legend, Style};
use crate::{Mark, MarkAt};

/// A panel's x and y ranges in plot space.
pub(crate) type Ranges = ((f64, f64), (f64, f64));
/// A polyline in backend pixels.
pub(crate) type Curve = Vec<(f64, f64)>;

/// Ranges every panel of a kind shares (plot space), when the style asks for it.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Shared {
    pub x: Option<(f64, f64)>,
    pub y: Option<(f64, f64)>,
}

impl Shared {
    /// A panel's own `ranges`, replaced by the shared ones on axes its view leaves free.
    pub(crate) fn apply(self, view: &crate::View, (x, y): Ranges) -> Ranges {
        (
            self.x.filter(|_| view.x.is_none()).unwrap_or(x),
            self.y.filter(|_| view.y.is_none()).unwrap_or(y),
        )
    }
}

/// The finite range of `values` padded by `pad` of its width, or (0, 1).
pub(crate) fn range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi > lo {
        (lo - pad * (hi - lo), hi + pad * (hi - lo))
    } else {
        let half = 0.5 * lo.abs().max(1e-3);
        (lo - half, hi + half)
    }
}

/// Mark colours: dark grey and black read on white and on every map colour.
const MARK_COLOURS: [RGBColor; 2] = [RGBColor(60, 60, 60), BLACK];

/// One legend entry per distinct mark label, in order of first appearance, each in its
/// lines' colour.
pub(crate) fn mark_entries(marks: &[Mark]) -> Vec<Entry> {
    let mut entries: Vec<Entry> = Vec::new();
    for mark in marks {
        if !entries.iter().any(|e| e.label == mark.label) {
            entries.push(Entry {
                label: mark.label.clone(),
                glyph: Glyph::Line {
                    colour: MARK_COLOURS[entries.len() % MARK_COLOURS.len()],
                    dash: Dash::Dashed,
                    marker: Marker::None,
                    width_pt: 0.9,
                },
            });
        }
    }
    entries
}

/// Draws `marks` across the plot (in plot space, scaled) in the colours of
/// [`mark_entries`]; returns their lines in backend pixels.
pub(crate) fn marks<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &Chart<'_, DB>,
    marks: &[Mark],
    (sx, sy): (Scale, Scale),
    style: &Style,
) -> Result<Vec<Curve>, String> {
    let rect = plot_rect(chart);
    let entries = mark_entries(marks);
    let mut drawn = Vec::new();
    for mark in marks {
        let Some(Glyph::Line { colour, .. }) = entries
            .iter()
            .find(|e| e.label == mark.label)
            .map(|e| e.glyph)
        else {
            continue;
        };
        let line = match mark.at {
            MarkAt::X(x) => {
                let px = pixel(chart, (sx.to_plot(x), 0.0)).0;
                vec![(px, rect.y0), (px, rect.y1)]
            }
            MarkAt::Y(y) => {
                let py = pixel(chart, (0.0, sy.to_plot(y))).1;
                vec![(rect.x0, py), (rect.x1, py)]
            }
        };
        legend::polyline(area, &line, &rect, (colour, Dash::Dashed, 0.9), style)?;
        drawn.push(line);
    }
    Ok(drawn)
}

/// Where the legend goes for `placement`: inside at a corner (or `None` when it must go
/// outside), choosing for `Best` the first place that hides none of `points`.
pub(crate) fn inside_place(
    placement: Legend,
    plot: &Rect,
    size: (f64, f64),
    points: &[(f64, f64)],
    style: &Style,
) -> Option<(f64, f64)> {
    match placement {
        Legend::Inside(corner) => Some(legend::inside(corner, plot, size, style)),
        Legend::Best => Corner::TRIED
            .iter()
            .map(|&c| legend::inside(c, plot, size, style))
            .find(|&at| legend::covered(points, at, size, style) == 0),
        _ => None,
    }
}

/// Each curve (plot space) as backend pixels; non-finite points stay non-finite.
pub(crate) fn pixel_curves<DB: DrawingBackend>(
    chart: &Chart<'_, DB>,
    curves: &[Vec<(f64, f64)>],
) -> Vec<Vec<(f64, f64)>> {
    curves
        .iter()
        .map(|c| {
            c.iter()
                .map(|&q| {
                    if q.0.is_finite() && q.1.is_finite() {
                        pixel(chart, q)
                    } else {
                        (f64::NAN, f64::NAN)
                    }
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_pad_only_where_asked() {
        assert_eq!(range([1.0, f64::NAN, 3.0].into_iter(), 0.05), (0.9, 3.1));
        assert_eq!(range([1.0, 3.0].into_iter(), 0.0), (1.0, 3.0));
    }
}
