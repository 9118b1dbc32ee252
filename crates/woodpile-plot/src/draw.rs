//! The figure and its line panels, generic over the backend so PNG and SVG are one picture.
//! Heat maps are [`crate::heat`]'s, what both share [`crate::panel`]'s; curves, markers and
//! legends in pixels [`crate::legend`]'s.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart::{chart, plot_rect, text, wrap, AxisSpan, FONT};
use crate::legend::{self, Entry, Glyph, Rect};
use crate::panel::{inside_place, mark_entries, marks, pixel_curves, range, Ranges, Shared};
use crate::style::{Corner, Legend, Style};
use crate::{Figure, LinePanel, Panel};

/// Draws `fig` on `root`; returns, per panel, how many plotted points its legend covers.
pub(crate) fn figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
) -> Result<Vec<usize>, String> {
    let style = &fig.style;
    root.fill(&WHITE).map_err(text)?;
    let body = figure_title(root, &fig.title, style)?;
    let heat_maps: Vec<_> = fig.panels.iter().filter_map(Panel::as_heat).collect();
    let shared_bar = fig.shared_colour_bar && !heat_maps.is_empty();
    let (body, bar) = if shared_bar {
        let bar_width = match heat_maps.first().map(|h| &h.colours) {
            Some(crate::Colours::Categories(names)) => {
                legend::measure(root, &crate::heat::category_entries(names), style).0
                    + style.pt(6.0)
            }
            _ => style.mm(17.0),
        }
        .round() as u32;
        let (body, bar) = body.split_horizontally(body.dim_in_pixel().0.saturating_sub(bar_width));
        (body, Some(bar))
    } else {
        (body, None)
    };
    let columns = fig.columns.clamp(1, fig.panels.len().max(1));
    let rows = fig.panels.len().div_ceil(columns).max(1);
    let areas = body.split_evenly((rows, columns));
    let shared_lines = shared_ranges(fig, |p| match p {
        Panel::Lines(l) => Some(line_ranges(l)),
        Panel::Heat(_) => None,
    });
    let shared_heat = shared_ranges(fig, |p| p.as_heat().map(crate::heat::ranges));
    let (title_lines, strip_lines, letters) = panel_titles(fig, &areas, style);
    let mut covered = Vec::with_capacity(fig.panels.len());
    for (k, (panel, area)) in fig.panels.iter().zip(areas.iter()).enumerate() {
        let letter = letters.then(|| format!("({})", char::from(b'a' + (k % 26) as u8)));
        let plot_area = panel_title(
            area,
            (&title_lines[k], strip_lines),
            letter.as_deref(),
            style,
        )?;
        covered.push(match panel {
            Panel::Lines(p) => lines_panel(&plot_area, p, style, shared_lines)?,
            Panel::Heat(h) => crate::heat::panel(&plot_area, h, style, shared_heat, !shared_bar)?,
        });
    }
    if let (Some(bar), Some(first)) = (bar, heat_maps.first()) {
        let strip_top = (style.font(1.1) * 1.6).round() as u32;
        let (_, bar) = bar.split_vertically(strip_top);
        match &first.colours {
            crate::Colours::Categories(names) => crate::heat::category_legend(&bar, names, style)?,
            _ => crate::heat::colour_bar(&bar, first, style)?,
        }
    }
    Ok(covered)
}

/// Draws the figure's title, wrapped, in a strip at the top of `root`; returns the area below.
fn figure_title<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    style: &Style,
) -> Result<DrawingArea<DB, Shift>, String> {
    let width = root.dim_in_pixel().0 as f64;
    let title_font = (FONT, style.font(1.2)).into_font().color(&BLACK);
    let lines = wrap(root, title, width - style.pt(8.0), &title_font);
    let strip = (lines.len() as f64 * style.font(1.2) * 1.3 + style.pt(4.0)).round() as u32;
    let (top, body) = root.split_vertically(strip);
    for (k, line) in lines.iter().enumerate() {
        let y = style.pt(2.0) + k as f64 * style.font(1.2) * 1.3;
        top.draw(&Text::new(
            line.clone(),
            (style.pt(4.0) as i32, y as i32),
            title_font.clone(),
        ))
        .map_err(text)?;
    }
    Ok(body)
}

/// Each panel's title wrapped to its area, the lines every panel's title strip holds (as
/// many as the longest title needs, so the panels of a row stay aligned), and whether the
/// panels are lettered (one panel is the figure: no letter, and no strip for a title it does
/// not have).
fn panel_titles<DB: DrawingBackend>(
    fig: &Figure,
    areas: &[DrawingArea<DB, Shift>],
    style: &Style,
) -> (Vec<Vec<String>>, usize, bool) {
    let title_font = (FONT, style.font(1.1)).into_font().color(&BLACK);
    let title_lines: Vec<Vec<String>> = fig
        .panels
        .iter()
        .zip(areas.iter())
        .map(|(p, a)| {
            wrap(
                a,
                p.title(),
                a.dim_in_pixel().0 as f64 - style.pt(24.0),
                &title_font,
            )
        })
        .collect();
    let letters = style.panel_letters && fig.panels.len() > 1;
    let has_title = |lines: &Vec<String>| lines.iter().any(|l| !l.is_empty());
    let strip_lines = title_lines
        .iter()
        .filter(|l| has_title(l))
        .map(Vec::len)
        .max()
        .unwrap_or(usize::from(letters));
    (title_lines, strip_lines, letters)
}

/// Draws a panel's title lines (and letter) over it, in a strip of `strip_lines` lines; returns
/// the area left for the plot.
fn panel_title<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (lines, strip_lines): (&[String], usize),
    letter: Option<&str>,
    style: &Style,
) -> Result<DrawingArea<DB, Shift>, String> {
    let line = style.font(1.1) * 1.25;
    if strip_lines == 0 {
        return Ok(area.clone());
    }
    let height = (strip_lines as f64 * line + style.font(1.1) * 0.4).round() as u32;
    let (top, rest) = area.split_vertically(height);
    let font = (FONT, style.font(1.1)).into_font().color(&BLACK);
    let width = top.dim_in_pixel().0 as i32;
    let bold = (FONT, style.font(1.1), FontStyle::Bold)
        .into_font()
        .color(&BLACK);
    // A centred title moves right of the panel's letter rather than run into it.
    let letter_end = letter.map_or(0, |l| {
        top.estimate_text_size(l, &bold).map_or(0, |s| s.0) as i32 + style.pt(6.0) as i32
    });
    for (k, title) in lines.iter().enumerate() {
        let text_width = top.estimate_text_size(title, &font).map_or(0, |s| s.0) as i32;
        let y = (style.pt(2.0) + k as f64 * line) as i32;
        let x = ((width - text_width) / 2).max(letter_end);
        top.draw(&Text::new(title.clone(), (x, y), font.clone()))
            .map_err(text)?;
    }
    if let Some(letter) = letter {
        top.draw(&Text::new(
            letter.to_string(),
            (style.pt(3.0) as i32, style.pt(2.0) as i32),
            bold,
        ))
        .map_err(text)?;
    }
    Ok(rest)
}

/// The union of every panel's ranges, on the axes the style shares.
fn shared_ranges(fig: &Figure, ranges: impl Fn(&Panel) -> Option<Ranges>) -> Shared {
    let all: Vec<_> = fig.panels.iter().filter_map(ranges).collect();
    let union = |pick: fn(&Ranges) -> (f64, f64)| {
        all.iter()
            .map(pick)
            .filter(|(l, h)| l.is_finite() && h.is_finite())
            .fold(None, |acc: Option<(f64, f64)>, (l, h)| {
                Some(acc.map_or((l, h), |(a, b)| (a.min(l), b.max(h))))
            })
    };
    Shared {
        x: if fig.style.share_x {
            union(|r| r.0)
        } else {
            None
        },
        y: if fig.style.share_y {
            union(|r| r.1)
        } else {
            None
        },
    }
}

/// A line panel's own ranges in plot space: x at the data, y padded by 5%.
fn line_ranges(p: &LinePanel) -> Ranges {
    let (sx, sy) = (p.view.x_scale, p.view.y_scale);
    let all = || p.series.iter().flat_map(|s| s.points.iter());
    let x = p
        .view
        .x
        .map(|(a, b)| (sx.to_plot(a), sx.to_plot(b)))
        .unwrap_or_else(|| range(all().map(|q| sx.to_plot(q.0)), 0.0));
    let y = p
        .view
        .y
        .map(|(a, b)| (sy.to_plot(a), sy.to_plot(b)))
        .unwrap_or_else(|| range(all().map(|q| sy.to_plot(q.1)), 0.05));
    (x, y)
}

fn lines_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &LinePanel,
    style: &Style,
    shared: Shared,
) -> Result<usize, String> {
    let (sx, sy) = (p.view.x_scale, p.view.y_scale);
    let ((mut x0, mut x1), (y0, y1)) = shared.apply(&p.view, line_ranges(p));
    if x1 <= x0 || x0.is_nan() || x1.is_nan() {
        (x0, x1) = (x0 - 0.5, x0 + 0.5);
    }
    let (xs, ys) = (
        AxisSpan {
            lo: x0,
            hi: x1,
            scale: sx,
        },
        AxisSpan {
            lo: y0,
            hi: y1,
            scale: sy,
        },
    );
    let curves: Vec<Vec<(f64, f64)>> = p
        .series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .map(|&(x, y)| (sx.to_plot(x), sy.to_plot(y)))
                .collect()
        })
        .collect();
    let entries = line_entries(p);
    let size = legend::measure(area, &entries, style);
    let placement = line_legend_placement(area, p, [xs, ys], &curves, size, style)?;
    let gap = style.pt(4.0);
    let (main, side) = match placement {
        Legend::OutsideRight => {
            let w = area.dim_in_pixel().0 as f64 - size.0 - 2.0 * gap;
            let (main, side) = area.split_horizontally(w.max(1.0) as u32);
            (main, Some(side))
        }
        Legend::Below => {
            let h = area.dim_in_pixel().1 as f64 - size.1 - gap;
            let (main, side) = area.split_vertically(h.max(1.0) as u32);
            (main, Some(side))
        }
        _ => (area.clone(), None),
    };
    let chart = chart(&main, xs, ys, style, Some((&p.x_label, &p.y_label, true)))?;
    let rect = plot_rect(&chart);
    let points = pixel_curves(&chart, &curves);
    draw_lines(area, p, &points, &rect, style)?;
    let mark_lines = marks(area, &chart, &p.marks, (sx, sy), style)?;
    let all: Vec<Vec<(f64, f64)>> = points.into_iter().chain(mark_lines).collect();
    let dense = legend::dense(&all, 2.0);
    let at = match (placement, &side) {
        (Legend::None, _) => return Ok(0),
        (Legend::OutsideRight, Some(side)) => {
            let (bx, by) = side.get_base_pixel();
            (
                bx as f64 + gap,
                by as f64 + rect.y0 - main.get_base_pixel().1 as f64,
            )
        }
        (Legend::Below, Some(side)) => {
            let (bx, by) = side.get_base_pixel();
            (
                bx as f64 + 0.5 * (side.dim_in_pixel().0 as f64 - size.0),
                by as f64,
            )
        }
        _ => inside_place(placement, &rect, size, &dense, style)
            .unwrap_or_else(|| legend::inside(Corner::UpperRight, &rect, size, style)),
    };
    legend::draw(area, &entries, at, style)?;
    Ok(legend::covered(&dense, at, size, style))
}

/// The legend's entries of a line panel: a line per curve, then each mark whose label no
/// curve has (a mark labelled like a curve shares its entry).
fn line_entries(p: &LinePanel) -> Vec<Entry> {
    let mut entries: Vec<Entry> = p
        .series
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let (colour, dash, marker) = s.style.resolve(k);
            Entry {
                label: s.label.clone(),
                glyph: Glyph::Line {
                    colour,
                    dash,
                    marker,
                    width_pt: 1.2,
                },
            }
        })
        .collect();
    entries.extend(
        mark_entries(&p.marks)
            .into_iter()
            .filter(|m| !p.series.iter().any(|s| s.label == m.label)),
    );
    entries
}

/// Where a line panel's legend goes: none for one curve without marks (the y label names
/// it), and `Best` moves outside on the right when no corner of a trial chart is free.
fn line_legend_placement<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &LinePanel,
    [xs, ys]: [AxisSpan; 2],
    curves: &[Vec<(f64, f64)>],
    size: (f64, f64),
    style: &Style,
) -> Result<Legend, String> {
    let wants_legend = (p.series.len() > 1 || !p.marks.is_empty()) && style.legend != Legend::None;
    if !wants_legend {
        return Ok(Legend::None);
    }
    if style.legend != Legend::Best {
        return Ok(style.legend);
    }
    // Where the legend goes decides the chart's area, so place it on a trial chart first.
    let trial = chart(area, xs, ys, style, None)?;
    let points = pixel_curves(&trial, curves);
    let free = inside_place(
        Legend::Best,
        &plot_rect(&trial),
        size,
        &legend::dense(&points, 2.0),
        style,
    );
    Ok(match free {
        Some(_) => Legend::Best,
        None => Legend::OutsideRight,
    })
}

/// Each curve of `p` at its pixel `points`, broken at non-finite values, with its markers.
fn draw_lines<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &LinePanel,
    points: &[Vec<(f64, f64)>],
    rect: &Rect,
    style: &Style,
) -> Result<(), String> {
    for (k, (series, line)) in p.series.iter().zip(points).enumerate() {
        let (colour, dash, marker) = series.style.resolve(k);
        // A non-finite value (a failed point, or <= 0 on a log axis) breaks the line.
        for segment in line.split(|q| !(q.0.is_finite() && q.1.is_finite())) {
            legend::polyline(area, segment, rect, (colour, dash, 1.2), style)?;
        }
        // Every point when there are few; otherwise about eight per curve, evenly spaced
        // across the plot's width (whatever the axis scale), staggered so that curves
        // sharing an x do not stack their markers.
        let spacing = (rect.x1 - rect.x0) / 8.0;
        let mut next = rect.x0 + spacing * (k as f64 / p.series.len().max(1) as f64);
        for &q in line {
            if !(q.0.is_finite() && q.1.is_finite() && rect.contains_point(q)) {
                continue;
            }
            if line.len() <= 40 || q.0 >= next {
                legend::marker(area, q, marker, colour, style)?;
                next = q.0 + spacing;
            }
        }
    }
    Ok(())
}
