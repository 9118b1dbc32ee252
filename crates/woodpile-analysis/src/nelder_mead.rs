//! Nelder–Mead maximisation: no derivatives, few evaluations, for smooth objectives whose
//! every evaluation is a simulation (the pipeline's optima between grid points, the design
//! stage's refinement). The objective may fail; its error ends the search.

/// Maximises `f` by Nelder–Mead from `start` with initial steps `steps`, in at most `budget`
/// evaluations; `f(start)` is given.
pub fn maximise<E>(
    f: &mut dyn FnMut(&[f64]) -> Result<f64, E>,
    start: &[f64],
    steps: &[f64],
    f_start: f64,
    budget: usize,
) -> Result<(Vec<f64>, f64), E> {
    let n = start.len();
    // Minimise -f.
    let mut simplex: Vec<(Vec<f64>, f64)> = vec![(start.to_vec(), -f_start)];
    for i in 0..n {
        let mut x = start.to_vec();
        x[i] += 0.5 * steps[i];
        let v = -f(&x)?;
        simplex.push((x, v));
    }
    let size = |s: &[(Vec<f64>, f64)]| -> f64 {
        (0..n)
            .map(|i| {
                let (lo, hi) = s
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                        (l.min(p.0[i]), h.max(p.0[i]))
                    });
                (hi - lo) / steps[i]
            })
            .fold(0.0, f64::max)
    };
    let mut spent = n + 1;
    while spent < budget && size(&simplex) > 1e-3 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let centroid: Vec<f64> = (0..n)
            .map(|i| simplex[..n].iter().map(|p| p.0[i]).sum::<f64>() / n as f64)
            .collect();
        let worst = simplex[n].clone();
        let along = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|i| centroid[i] + t * (worst.0[i] - centroid[i]))
                .collect()
        };
        let xr = along(-1.0);
        let fr = -f(&xr)?;
        spent += 1;
        if fr < simplex[0].1 {
            let xe = along(-2.0);
            let fe = -f(&xe)?;
            spent += 1;
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let xc = if fr < worst.1 {
                along(-0.5)
            } else {
                along(0.5)
            };
            let fc = -f(&xc)?;
            spent += 1;
            if fc < worst.1.min(fr) {
                simplex[n] = (xc, fc);
            } else {
                // Shrink towards the best vertex.
                let best = simplex[0].0.clone();
                for p in simplex.iter_mut().skip(1) {
                    p.0 = (0..n).map(|i| best[i] + 0.5 * (p.0[i] - best[i])).collect();
                    p.1 = -f(&p.0)?;
                    spent += 1;
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    Ok((simplex[0].0.clone(), -simplex[0].1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_smooth_maximum_between_grid_points() {
        let mut f = |x: &[f64]| -> Result<f64, ()> {
            Ok(1.0 - (x[0] - 0.37).powi(2) - 2.0 * (x[1] + 0.21).powi(2))
        };
        let start = [0.0, 0.0];
        let f0 = f(&start).unwrap();
        let (x, v) = maximise(&mut f, &start, &[0.1, 0.1], f0, 120).unwrap();
        assert!(
            (x[0] - 0.37).abs() < 1e-3 && (x[1] + 0.21).abs() < 1e-3,
            "{x:?}"
        );
        assert!(v > f0 && (v - 1.0).abs() < 1e-5);
    }

    #[test]
    fn the_budget_bounds_the_evaluations_and_an_error_ends_the_search() {
        let mut calls = 0;
        let mut f = |x: &[f64]| -> Result<f64, ()> {
            calls += 1;
            Ok(-(x[0] - 3.0).powi(2))
        };
        maximise(&mut f, &[0.0], &[0.1], -9.0, 10).unwrap();
        assert!(calls <= 12, "{calls}");
        let mut failing = |_: &[f64]| -> Result<f64, &str> { Err("blew up") };
        assert_eq!(
            maximise(&mut failing, &[0.0], &[0.1], 0.0, 10),
            Err("blew up")
        );
    }
}
