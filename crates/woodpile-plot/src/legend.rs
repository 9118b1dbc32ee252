//! Curves and legends in pixels: dashed polylines clipped to the axes, point markers, and a
//! legend box placed where it hides no data. Everything here takes absolute backend pixels
//! and draws on a [`Shift`] area, whose origin it subtracts.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::colour::{Dash, Marker};
use crate::style::{Corner, Style};

const FONT: &str = "sans-serif";

/// A rectangle in backend pixels: left, top, right, bottom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rect {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl Rect {
    pub(crate) fn contains_point(&self, (x, y): (f64, f64)) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }
}

/// What a legend entry shows beside its label.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Glyph {
    /// A stretch of curve, with its marker.
    Line {
        colour: RGBColor,
        dash: Dash,
        marker: Marker,
        width_pt: f64,
    },
    /// A filled square (a category).
    Swatch(RGBColor),
}

/// One line of a legend.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Entry {
    pub label: String,
    pub glyph: Glyph,
}

fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("{e:?}")
}

fn local<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, (x, y): (f64, f64)) -> (i32, i32) {
    let (bx, by) = area.get_base_pixel();
    (x.round() as i32 - bx, y.round() as i32 - by)
}

/// The part of segment a-b inside `clip` (Liang-Barsky), if any.
fn clipped(a: (f64, f64), b: (f64, f64), clip: &Rect) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - clip.x0),
        (dx, clip.x1 - a.0),
        (-dy, a.1 - clip.y0),
        (dy, clip.y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// Draws the polyline `points` (backend pixels) inside `clip` with `dash`, continuing the dash
/// pattern across vertices so dense curves still show their dashes.
pub(crate) fn polyline<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[(f64, f64)],
    clip: &Rect,
    (colour, dash, width_pt): (RGBColor, Dash, f64),
    style: &Style,
) -> Result<(), String> {
    let stroke = ShapeStyle::from(&colour).stroke_width(style.stroke(width_pt));
    let pattern: Vec<f64> = dash
        .pattern()
        .iter()
        .map(|&l| style.pt(l * width_pt.max(0.75)))
        .collect();
    let mut runs: Vec<Vec<(i32, i32)>> = vec![Vec::new()];
    let push = |runs: &mut Vec<Vec<(i32, i32)>>, p: (f64, f64)| {
        if let Some(run) = runs.last_mut() {
            run.push(local(area, p));
        }
    };
    // Where in the pattern the pen is: the piece (even: drawing, odd: a gap) and its length left.
    let (mut piece, mut left) = (0usize, pattern.first().copied().unwrap_or(f64::INFINITY));
    for w in points.windows(2) {
        let Some((a, b)) = clipped(w[0], w[1], clip) else {
            runs.push(Vec::new());
            continue;
        };
        if a != w[0] {
            runs.push(Vec::new());
        }
        let length = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let at = |s: f64| {
            let f = if length > 0.0 { s / length } else { 0.0 };
            (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1))
        };
        if piece % 2 == 0 {
            push(&mut runs, a);
        }
        let mut s = 0.0;
        while s + left < length {
            s += left;
            push(&mut runs, at(s));
            if piece % 2 == 0 {
                runs.push(Vec::new());
            }
            piece = (piece + 1) % pattern.len().max(1);
            left = pattern.get(piece).copied().unwrap_or(f64::INFINITY);
        }
        left -= length - s;
        if piece % 2 == 0 {
            push(&mut runs, b);
        }
        if b != w[1] {
            runs.push(Vec::new());
        }
    }
    for run in runs.into_iter().filter(|r| r.len() >= 2) {
        area.draw(&PathElement::new(run, stroke)).map_err(err)?;
    }
    Ok(())
}

/// Draws `marker` centred on `at` (backend pixels).
pub(crate) fn marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (f64, f64),
    marker: Marker,
    colour: RGBColor,
    style: &Style,
) -> Result<(), String> {
    let r = style.pt(2.2);
    let (x, y) = local(area, at);
    let ri = r.round() as i32;
    let fill = colour.filled();
    let outline = ShapeStyle::from(&colour).stroke_width(style.stroke(0.8));
    match marker {
        Marker::None => Ok(()),
        Marker::Circle => area.draw(&Circle::new((x, y), ri, fill)).map_err(err),
        Marker::Square => {
            let s = (0.85 * r).round() as i32;
            area.draw(&Rectangle::new([(x - s, y - s), (x + s, y + s)], fill))
                .map_err(err)
        }
        Marker::Triangle => {
            let h = r.round() as i32;
            area.draw(&Polygon::new(
                vec![(x, y - h), (x + h, y + h * 3 / 4), (x - h, y + h * 3 / 4)],
                fill,
            ))
            .map_err(err)
        }
        Marker::Diamond => area
            .draw(&Polygon::new(
                vec![(x, y - ri), (x + ri, y), (x, y + ri), (x - ri, y)],
                fill,
            ))
            .map_err(err),
        Marker::Cross => {
            area.draw(&PathElement::new(
                vec![(x - ri, y - ri), (x + ri, y + ri)],
                outline,
            ))
            .map_err(err)?;
            area.draw(&PathElement::new(
                vec![(x - ri, y + ri), (x + ri, y - ri)],
                outline,
            ))
            .map_err(err)
        }
    }
}

/// The legend's text style.
fn font(style: &Style) -> TextStyle<'static> {
    (FONT, style.font(1.0)).into_font().color(&BLACK)
}

/// Width and height of the legend box of `entries`, in pixels.
pub(crate) fn measure<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    style: &Style,
) -> (f64, f64) {
    let line = style.font(1.35);
    let widest = entries
        .iter()
        .map(|e| {
            area.estimate_text_size(&e.label, &font(style))
                .map_or(0, |s| s.0)
        })
        .max()
        .unwrap_or(0) as f64;
    let pad = style.pt(3.0);
    (
        widest + style.pt(16.0) + 2.0 * pad,
        entries.len() as f64 * line + 2.0 * pad,
    )
}

/// The top-left corner of a `size` box at `corner` inside `plot`, a little in from its edges.
pub(crate) fn inside(corner: Corner, plot: &Rect, (w, h): (f64, f64), style: &Style) -> (f64, f64) {
    let inset = style.pt(3.0);
    let left = plot.x0 + inset;
    let right = plot.x1 - inset - w;
    let centre_x = 0.5 * (plot.x0 + plot.x1 - w);
    let top = plot.y0 + inset;
    let bottom = plot.y1 - inset - h;
    let centre_y = 0.5 * (plot.y0 + plot.y1 - h);
    match corner {
        Corner::UpperLeft => (left, top),
        Corner::UpperCenter => (centre_x, top),
        Corner::UpperRight => (right, top),
        Corner::LowerLeft => (left, bottom),
        Corner::LowerCenter => (centre_x, bottom),
        Corner::LowerRight => (right, bottom),
        Corner::CenterLeft => (left, centre_y),
        Corner::CenterRight => (right, centre_y),
    }
}

/// How many of `points` lie under a `size` box at `at`, with a margin of a point around it.
pub(crate) fn covered(
    points: &[(f64, f64)],
    at: (f64, f64),
    (w, h): (f64, f64),
    style: &Style,
) -> usize {
    let m = style.pt(1.0);
    let rect = Rect {
        x0: at.0 - m,
        y0: at.1 - m,
        x1: at.0 + w + m,
        y1: at.1 + h + m,
    };
    points.iter().filter(|&&p| rect.contains_point(p)).count()
}

/// The curves as points every couple of pixels along them (backend pixels): what a legend box
/// must not hide.
pub(crate) fn dense(curves: &[Vec<(f64, f64)>], step: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for curve in curves {
        out.extend(curve.first().copied());
        for w in curve.windows(2) {
            let length = ((w[1].0 - w[0].0).powi(2) + (w[1].1 - w[0].1).powi(2)).sqrt();
            let n = (length / step).ceil().clamp(1.0, 10_000.0) as usize;
            out.extend((1..=n).map(|k| {
                let f = k as f64 / n as f64;
                (
                    w[0].0 + f * (w[1].0 - w[0].0),
                    w[0].1 + f * (w[1].1 - w[0].1),
                )
            }));
        }
    }
    out
}

/// Draws the legend box of `entries` with its top-left corner at `at` (backend pixels).
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    at: (f64, f64),
    style: &Style,
) -> Result<(), String> {
    let (w, h) = measure(area, entries, style);
    let (x, y) = local(area, at);
    area.draw(&Rectangle::new(
        [(x, y), (x + w.round() as i32, y + h.round() as i32)],
        WHITE.mix(0.9).filled(),
    ))
    .map_err(err)?;
    area.draw(&Rectangle::new(
        [(x, y), (x + w.round() as i32, y + h.round() as i32)],
        ShapeStyle::from(&RGBColor(150, 150, 150)).stroke_width(style.stroke(0.4)),
    ))
    .map_err(err)?;
    let pad = style.pt(3.0);
    let line = style.font(1.35);
    for (k, entry) in entries.iter().enumerate() {
        let mid = at.1 + pad + (k as f64 + 0.5) * line;
        let (x0, x1) = (at.0 + pad, at.0 + pad + style.pt(12.0));
        match entry.glyph {
            Glyph::Line {
                colour,
                dash,
                marker: m,
                width_pt,
            } => {
                let clip = Rect {
                    x0,
                    y0: mid - 1.0,
                    x1,
                    y1: mid + 1.0,
                };
                if colour == WHITE {
                    // A white line (over a map) shows in the white box as a black-edged one.
                    polyline(
                        area,
                        &[(x0, mid), (x1, mid)],
                        &clip,
                        (BLACK, Dash::Solid, width_pt + 1.0),
                        style,
                    )?;
                }
                polyline(
                    area,
                    &[(x0, mid), (x1, mid)],
                    &clip,
                    (colour, dash, width_pt),
                    style,
                )?;
                marker(area, (0.5 * (x0 + x1), mid), m, colour, style)?;
            }
            Glyph::Swatch(colour) => {
                let s = style.pt(3.0);
                let (a, b) = (
                    local(area, (x0, mid - s)),
                    local(area, (x0 + 2.0 * s, mid + s)),
                );
                area.draw(&Rectangle::new([a, b], colour.filled()))
                    .map_err(err)?;
            }
        }
        let (tx, ty) = local(area, (x1 + style.pt(3.0), mid - 0.5 * style.font(1.0)));
        area.draw(&Text::new(entry.label.clone(), (tx, ty), font(style)))
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_are_clipped_to_the_axes() {
        let clip = Rect {
            x0: 0.0,
            y0: 0.0,
            x1: 10.0,
            y1: 10.0,
        };
        assert_eq!(
            clipped((-5.0, 5.0), (5.0, 5.0), &clip),
            Some(((0.0, 5.0), (5.0, 5.0)))
        );
        assert_eq!(clipped((-5.0, -5.0), (-1.0, 20.0), &clip), None);
    }

    #[test]
    fn a_box_counts_the_curve_samples_it_hides() {
        let style = Style::default();
        let line = dense(&[vec![(0.0, 50.0), (100.0, 50.0)]], 2.0);
        assert_eq!(line.len(), 51);
        assert_eq!(covered(&line, (10.0, 0.0), (20.0, 20.0), &style), 0);
        assert!(covered(&line, (10.0, 40.0), (20.0, 20.0), &style) >= 10);
    }
}
