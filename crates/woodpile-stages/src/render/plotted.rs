//! The stage's table: exactly the numbers a figure drew, one row per curve point or heat-map
//! cell, each under the name of the column it came from.

use woodpile_pipeline::table::Columns;
use woodpile_plot::Panel;

/// The source columns a panel plots: x, the y of each curve (by curve label; `None`: the
/// panel's single y), and for heat maps y and z.
#[derive(Clone)]
pub(super) struct PlottedColumns {
    pub(super) x: String,
    pub(super) y: Option<String>,
    pub(super) z: Option<String>,
    pub(super) overlays: Vec<(String, String)>,
}

/// The plotted numbers of `panels`: one row per curve point or heat-map cell, with the panel's
/// index and the curve's (or the colour bar's) label, each number under the name of the column
/// it was drawn from, so a diff can give a column (a wall time, say) its own tolerance.
pub(super) fn plotted(panels: &[Panel], names: &[PlottedColumns]) -> Columns {
    /// A drawn point: its panel, its curve's label, and its numbers by source column.
    type Plotted = (usize, String, Vec<(String, Option<f64>)>);
    let mut order: Vec<String> = Vec::new();
    let mut rows: Vec<Plotted> = Vec::new();
    let mut push = |p: usize, label: &str, cells: Vec<(String, Option<f64>)>| {
        for (name, _) in &cells {
            if !order.contains(name) {
                order.push(name.clone());
            }
        }
        rows.push((p, label.to_string(), cells));
    };
    for (p, (drawn, cols)) in panels.iter().zip(names).enumerate() {
        match drawn {
            Panel::Lines(l) => {
                for s in &l.series {
                    let y = cols.y.clone().unwrap_or_else(|| s.label.clone());
                    for &(x, v) in &s.points {
                        push(
                            p,
                            &s.label,
                            vec![(cols.x.clone(), Some(x)), (y.clone(), Some(v))],
                        );
                    }
                }
            }
            Panel::Heat(h) => {
                let (y, z) = (
                    cols.y.clone().unwrap_or_default(),
                    cols.z.clone().unwrap_or_default(),
                );
                for (j, &yv) in h.ys.iter().enumerate() {
                    for (i, &xv) in h.xs.iter().enumerate() {
                        let cells = vec![
                            (cols.x.clone(), Some(xv)),
                            (y.clone(), Some(yv)),
                            (z.clone(), h.z[j * h.xs.len() + i]),
                        ];
                        push(p, &h.z_label, cells);
                    }
                }
                for (s, (column, _)) in h.overlays.iter().zip(&cols.overlays) {
                    for &(xv, yv) in &s.points {
                        push(
                            p,
                            &s.label,
                            vec![(column.clone(), Some(xv)), (y.clone(), Some(yv))],
                        );
                    }
                }
            }
        }
    }
    let mut columns = Columns::new();
    columns
        .i64("panel", rows.iter().map(|r| Some(r.0 as i64)).collect())
        .str("series", rows.iter().map(|r| Some(r.1.clone())).collect());
    for name in &order {
        let values = rows
            .iter()
            .map(|r| r.2.iter().find(|(n, _)| n == name).and_then(|(_, v)| *v))
            .collect();
        columns.f64(name, values);
    }
    columns
}
