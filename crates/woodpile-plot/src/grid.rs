//! Shaping scattered (x, y, z) rows into the rectangular grid a heat map draws, and lines over
//! such a grid: the table-to-picture step that every caller of [`crate::HeatPanel`] needs.

use crate::heat::cell_edges;

/// A heat map's grid: the distinct x and y values, increasing, and z row by row (y outer).
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Distinct x values, increasing.
    pub xs: Vec<f64>,
    /// Distinct y values, increasing.
    pub ys: Vec<f64>,
    /// `z[j * xs.len() + i]` at `(xs[i], ys[j])`; `None` where no row gives it.
    pub z: Vec<Option<f64>>,
    /// The row with the largest finite z (the first of equals): (x, y, z).
    pub max: Option<(f64, f64, f64)>,
}

impl Grid {
    /// The grid of the rows `(x[r], y[r], z[r])`: a row without x or y is left out.
    pub fn from_rows(x: &[Option<f64>], y: &[Option<f64>], z: &[Option<f64>]) -> Grid {
        let (xs, ys) = (distinct(x), distinct(y));
        let mut cells = vec![None; xs.len() * ys.len()];
        let mut max: Option<(f64, f64, f64)> = None;
        for ((&x, &y), &v) in x.iter().zip(y).zip(z) {
            let (Some(x), Some(y)) = (x, y) else {
                continue;
            };
            let i = xs.partition_point(|&c| c < x);
            let j = ys.partition_point(|&c| c < y);
            cells[j * xs.len() + i] = v;
            if let Some(v) = v.filter(|v| v.is_finite()) {
                if max.is_none_or(|(_, _, best)| v > best) {
                    max = Some((x, y, v));
                }
            }
        }
        Grid {
            xs,
            ys,
            z: cells,
            max,
        }
    }

    /// A line through (`at[r]`, y) for every y of the grid, drawn as a vertical step over that
    /// y's cell: `at` is read from the first row (of `y`) at each grid y; a y whose row has no
    /// value is skipped.
    pub fn row_steps(&self, y: &[Option<f64>], at: &[Option<f64>]) -> Vec<(f64, f64)> {
        let edges = cell_edges(&self.ys);
        self.ys
            .iter()
            .enumerate()
            .filter_map(|(j, &grid_y)| {
                let x = y
                    .iter()
                    .position(|&v| v == Some(grid_y))
                    .and_then(|r| at[r])?;
                Some([(x, edges[j]), (x, edges[j + 1])])
            })
            .flatten()
            .collect()
    }
}

/// The distinct values present, increasing.
fn distinct(values: &[Option<f64>]) -> Vec<f64> {
    let mut v: Vec<f64> = values.iter().flatten().copied().collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_in_any_order_make_one_grid_with_its_maximum() {
        let x = [Some(2.0), Some(1.0), Some(2.0), Some(1.0), None];
        let y = [Some(0.0), Some(0.0), Some(5.0), Some(5.0), Some(5.0)];
        let z = [Some(4.0), Some(1.0), None, Some(f64::NAN), Some(9.0)];
        let g = Grid::from_rows(&x, &y, &z);
        assert_eq!(g.xs, vec![1.0, 2.0]);
        assert_eq!(g.ys, vec![0.0, 5.0]);
        assert_eq!(g.z[..2], [Some(1.0), Some(4.0)]);
        assert!(g.z[2].unwrap().is_nan());
        assert_eq!(g.z[3], None);
        assert_eq!(g.max, Some((2.0, 0.0, 4.0)));
    }

    #[test]
    fn row_steps_cover_each_row_cell() {
        let y = [Some(0.0), Some(1.0), Some(0.0)];
        let g = Grid::from_rows(&[Some(0.0), Some(0.0), Some(1.0)], &y, &[None; 3]);
        let at = [Some(7.0), None, Some(8.0)];
        assert_eq!(g.row_steps(&y, &at), vec![(7.0, -0.5), (7.0, 0.5)]);
    }
}
