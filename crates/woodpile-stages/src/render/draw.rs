//! A panel spec applied to its input table: the rows it keeps, read by role (x, the curves'
//! y, the series column; or x, y, z and overlays), then one `woodpile_plot::Panel` per value of
//! the `panels` column. The grid shaping of heat maps is `woodpile_plot::Grid`'s.

use polars::prelude::DataFrame;
use woodpile_plot::{Grid, HeatPanel, LinePanel, Mark, MarkAt, Panel, SeriesStyle, Trace};

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::table::{f64_column, matching_rows, str_column};

use super::spec::{PanelSpec, Plot, ZRange};
use super::MAX_PANELS;

/// A column's values on the kept rows.
type Values = Vec<Option<f64>>;

/// The kept rows of a line plot, by role.
struct LineData {
    x: Values,
    /// One per `y` column.
    y: Vec<Values>,
    /// The `series` column, when the single y is split into curves by it.
    series: Option<Values>,
    /// The `series_label` column: each curve's name.
    labels: Option<Vec<Option<String>>>,
}

/// The kept rows of a heat map, by role.
struct HeatData {
    x: Values,
    y: Values,
    z: Values,
    /// One per overlay, in order.
    overlays: Vec<Values>,
}

enum Data {
    Lines(LineData),
    Heat(HeatData),
}

/// `values` on `rows` only.
fn on(values: &[Option<f64>], rows: &[usize]) -> Values {
    rows.iter().map(|&r| values[r]).collect()
}

impl PanelSpec {
    /// The panels this spec draws from `input`: one, or one per value of `panels`.
    pub(super) fn draw(&self, input: &DataFrame, title: Option<String>) -> Result<Vec<Panel>> {
        let kept = Kept {
            input,
            rows: matching_rows(input, &self.filter)?,
        };
        let panel_name = match &self.plot {
            Plot::Lines { panels, .. } | Plot::Heatmap { panels, .. } => panels.as_ref(),
        };
        let panel_values = match panel_name {
            Some(p) => kept.column(p)?,
            None => vec![Some(0.0); kept.rows.len()],
        };
        let keys = panel_keys(&panel_values, panel_name)?;
        let data = self.data(&kept)?;
        let labels = kept.text_column(self.panel_label.as_ref())?;
        let panels = keys
            .iter()
            .map(|&key| {
                let rows: Vec<usize> = (0..kept.rows.len())
                    .filter(|&r| panel_values[r] == Some(key))
                    .collect();
                let title = match &title {
                    Some(t) => t.clone(),
                    None => self.panel_title_of(key, &rows, labels.as_deref(), panel_name),
                };
                match &data {
                    Data::Lines(d) => self.line_panel(d, &rows, title),
                    Data::Heat(d) => self.heat_panel(d, &rows, title),
                }
            })
            .collect();
        Ok(panels)
    }

    /// The columns the plot reads, on the kept rows.
    fn data(&self, kept: &Kept<'_>) -> Result<Data> {
        Ok(match &self.plot {
            Plot::Lines {
                x,
                y,
                series,
                series_label,
                ..
            } => Data::Lines(LineData {
                x: kept.column(x)?,
                y: y.iter().map(|c| kept.column(c)).collect::<Result<_>>()?,
                series: series.as_ref().map(|c| kept.column(c)).transpose()?,
                labels: kept.text_column(series_label.as_ref())?,
            }),
            Plot::Heatmap {
                x, y, z, overlays, ..
            } => Data::Heat(HeatData {
                x: kept.column(x)?,
                y: kept.column(y)?,
                z: kept.column(z)?,
                overlays: overlays
                    .iter()
                    .map(|(c, _)| kept.column(c))
                    .collect::<Result<_>>()?,
            }),
        })
    }

    /// The title of the panel of `key` (whose rows are `rows`): its `panel_label`, else its
    /// `panel_title` with `{value}`, else `column = value`.
    fn panel_title_of(
        &self,
        key: f64,
        rows: &[usize],
        labels: Option<&[Option<String>]>,
        panel_name: Option<&String>,
    ) -> String {
        let labelled = labels.and_then(|labels| rows.first().and_then(|&r| labels[r].clone()));
        let titled = self
            .panel_title
            .as_ref()
            .map(|t| t.replace("{value}", &woodpile_plot::tick(&key)));
        labelled.or(titled).unwrap_or_else(|| {
            panel_name
                .map(|p| format!("{p} = {}", woodpile_plot::tick(&key)))
                .unwrap_or_default()
        })
    }

    /// One line panel from `data` on `rows`: a curve per y column, or per value of the series
    /// column (in order of first appearance).
    fn line_panel(&self, data: &LineData, rows: &[usize], title: String) -> Panel {
        let Plot::Lines {
            y: y_names,
            x_label,
            y_label,
            series: series_name,
            styles,
            mark_halving,
            ..
        } = &self.plot
        else {
            unreachable!("line_panel is called for line plots only")
        };
        let point =
            |y: &Values, r: usize| (data.x[r].unwrap_or(f64::NAN), y[r].unwrap_or(f64::NAN));
        let series: Vec<Trace> = match (&data.series, series_name) {
            (Some(ids), Some(name)) => {
                let mut curves: Vec<(f64, Vec<usize>)> = Vec::new();
                for &r in rows {
                    let Some(id) = ids[r] else { continue };
                    match curves.iter_mut().find(|(v, _)| *v == id) {
                        Some((_, members)) => members.push(r),
                        None => curves.push((id, vec![r])),
                    }
                }
                curves
                    .into_iter()
                    .map(|(id, members)| Trace {
                        label: data
                            .labels
                            .as_ref()
                            .and_then(|l| l[members[0]].clone())
                            .unwrap_or_else(|| format!("{name} = {}", woodpile_plot::tick(&id))),
                        points: members.iter().map(|&r| point(&data.y[0], r)).collect(),
                        style: SeriesStyle::default(),
                    })
                    .collect()
            }
            _ => y_names
                .iter()
                .zip(&data.y)
                .map(|(name, y)| Trace {
                    label: name.clone(),
                    points: rows.iter().map(|&r| point(y, r)).collect(),
                    style: SeriesStyle::default(),
                })
                .collect(),
        };
        let series: Vec<Trace> = series
            .into_iter()
            .map(|s: Trace| Trace {
                style: styles
                    .iter()
                    .find(|c| c.name == s.label)
                    .map_or(SeriesStyle::default(), |c| c.style),
                ..s
            })
            .collect();
        let mut marks = self.marks.clone();
        if *mark_halving {
            marks.extend(series.iter().filter_map(halving_mark));
        }
        Panel::Lines(LinePanel {
            title,
            x_label: x_label.clone(),
            y_label: y_label.clone(),
            series,
            marks,
            view: self.view,
        })
    }

    /// One heat-map panel from `data` on `rows`.
    fn heat_panel(&self, data: &HeatData, rows: &[usize], title: String) -> Panel {
        let Plot::Heatmap {
            x_label,
            y_label,
            z_label,
            mark_max,
            overlays,
            colours,
            z_range,
            ..
        } = &self.plot
        else {
            unreachable!("heat_panel is called for heat maps only")
        };
        let y = on(&data.y, rows);
        let grid = Grid::from_rows(&on(&data.x, rows), &y, &on(&data.z, rows));
        // Each overlay: its x on every row of the map, as a step line over the row's cell.
        let overlays = overlays
            .iter()
            .zip(&data.overlays)
            .map(|((_, label), at)| Trace {
                label: label.clone(),
                points: grid.row_steps(&y, &on(at, rows)),
                style: SeriesStyle::default(),
            })
            .collect();
        Panel::Heat(HeatPanel {
            title,
            x_label: x_label.clone(),
            y_label: y_label.clone(),
            z_label: z_label.clone(),
            overlays,
            marker: grid
                .max
                .filter(|_| *mark_max)
                .map(|(x, y, v)| (x, y, format!("max {v:.4}"))),
            xs: grid.xs,
            ys: grid.ys,
            z: grid.z,
            colours: colours.clone(),
            z_range: match *z_range {
                ZRange::Fixed(lo, hi) => Some((lo, hi)),
                ZRange::Full | ZRange::Robust => None,
            },
            marks: self.marks.clone(),
            view: self.view,
        })
    }
}

/// A vertical mark where `series` first falls to half its first value, in the table's order
/// (the lossless end: γ = 0 first, or the largest quality factor first), found by
/// interpolating between the two samples around the crossing (in log x when both are
/// positive, as the axes these curves are drawn on). `None` when it never does.
fn halving_mark(series: &Trace) -> Option<Mark> {
    let points: Vec<(f64, f64)> = series
        .points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    let half = 0.5 * points.first()?.1;
    let crossing = points
        .windows(2)
        .find(|w| w[0].1 > half && w[1].1 <= half)?;
    let [(x0, y0), (x1, y1)] = [crossing[0], crossing[1]];
    let share = (y0 - half) / (y0 - y1);
    let x = match x0 > 0.0 && x1 > 0.0 {
        true => (x0.ln() + share * (x1.ln() - x0.ln())).exp(),
        false => x0 + share * (x1 - x0),
    };
    Some(Mark {
        at: MarkAt::X(x),
        label: format!("{} halves", series.label),
    })
}

/// The rows of a table that a panel's `where` keeps.
struct Kept<'a> {
    input: &'a DataFrame,
    rows: Vec<usize>,
}

impl Kept<'_> {
    /// Column `name` as floats, on the kept rows.
    fn column(&self, name: &str) -> Result<Values> {
        let values = f64_column(self.input, name)?;
        Ok(self.rows.iter().map(|&r| values[r]).collect())
    }

    /// An optional string column (curve or panel names), on the kept rows.
    fn text_column(&self, name: Option<&String>) -> Result<Option<Vec<Option<String>>>> {
        let Some(name) = name else { return Ok(None) };
        let values = str_column(self.input, name)?;
        Ok(Some(self.rows.iter().map(|&r| values[r].clone()).collect()))
    }
}

/// The panels' values of the `panels` column, in order, at most [`MAX_PANELS`] of them.
fn panel_keys(panel_values: &[Option<f64>], panel_name: Option<&String>) -> Result<Vec<f64>> {
    let mut keys: Vec<f64> = panel_values.iter().flatten().copied().collect();
    keys.sort_by(f64::total_cmp);
    keys.dedup();
    if keys.len() > MAX_PANELS {
        return Err(PipelineError::stage(
            "render",
            format!(
                "`panels = \"{}\"` makes {} panels, more than the {MAX_PANELS} a figure may have; filter the rows with `where` or choose another column",
                panel_name.map_or("", |p| p.as_str()),
                keys.len()
            ),
        ));
    }
    Ok(keys)
}

#[cfg(test)]
mod halving_tests {
    use super::*;

    fn series(points: &[(f64, f64)]) -> Trace {
        Trace {
            label: "E_tr".into(),
            points: points.to_vec(),
            style: SeriesStyle::default(),
        }
    }

    #[test]
    fn the_halving_point_is_interpolated_in_log_x() {
        let falling = series(&[(0.0, 0.8), (0.01, 0.7), (0.1, 0.6), (1.0, 0.2)]);
        let mark = halving_mark(&falling).unwrap();
        // Half of 0.8 is 0.4, halfway from 0.6 to 0.2: log-halfway from 0.1 to 1.
        let MarkAt::X(x) = mark.at else { panic!() };
        assert!((x - 0.1f64.sqrt()).abs() < 1e-12, "{x}");
        assert_eq!(mark.label, "E_tr halves");
        assert!(halving_mark(&series(&[(0.0, 0.8), (1.0, 0.5)])).is_none());
        // A falling quality factor: the table starts at the lossless end, the largest x.
        let quality = series(&[(1e4, 0.6), (100.0, 0.5), (10.0, 0.2)]);
        let MarkAt::X(q) = halving_mark(&quality).unwrap().at else {
            panic!()
        };
        // Half of 0.6 is 0.3, two thirds of the way from 0.5 to 0.2: log-x from 100 to 10.
        assert!((q - 10f64.powf(4.0 / 3.0)).abs() < 1e-9, "{q}");
    }
}
