//! Levenberg–Marquardt least squares for the paper's three-parameter forms (Section V,
//! Fig. 9): T(eps) = A eps^B + C and R(eps) = A tanh(B eps) + C, with analytic Jacobians and
//! the standard errors of A, B, C from the covariance s² (JᵀJ)⁻¹, s² = SSR / (n - 3).
//!
//! Three parameters need no linear-algebra crate: the normal equations are solved by Gaussian
//! elimination with partial pivoting.

// 3x3 linear algebra reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

/// A fitted form.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// A x^B + C (x > 0).
    Power,
    /// A tanh(B x) + C.
    Tanh,
}

impl Form {
    /// Every form under its stage-file name: the one table names are read from.
    pub const OPTIONS: [(&'static str, Form); 2] = [("power", Form::Power), ("tanh", Form::Tanh)];

    /// The name used in stage files.
    pub fn name(self) -> &'static str {
        Form::OPTIONS
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("", |(n, _)| n)
    }

    /// The form called `name` in [`Form::OPTIONS`].
    pub fn from_name(name: &str) -> Option<Form> {
        Form::OPTIONS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, f)| f)
    }

    /// f(x; p).
    pub fn eval(self, p: [f64; 3], x: f64) -> f64 {
        match self {
            Form::Power => p[0] * x.powf(p[1]) + p[2],
            Form::Tanh => p[0] * (p[1] * x).tanh() + p[2],
        }
    }

    /// ∂f/∂(A, B, C) at x.
    fn gradient(self, p: [f64; 3], x: f64) -> [f64; 3] {
        match self {
            Form::Power => {
                let xb = x.powf(p[1]);
                [xb, p[0] * xb * x.ln(), 1.0]
            }
            Form::Tanh => {
                let t = (p[1] * x).tanh();
                [t, p[0] * x * (1.0 - t * t), 1.0]
            }
        }
    }
}

/// A converged fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// A, B, C.
    pub params: [f64; 3],
    /// Their standard errors.
    pub std_errors: [f64; 3],
    /// Sum of squared residuals.
    pub ssr: f64,
    /// ‖y − f‖₂ / ‖y‖₂.
    pub relative_error: f64,
    /// Iterations taken.
    pub iterations: usize,
}

/// Most iterations before giving up.
const MAX_ITERATIONS: usize = 500;

/// Fits `form` to (x, y) from `start`; if that does not converge, again from the best start a
/// profile over B finds (for each B on a grid, A and C are a linear least-squares problem).
/// `Err` when neither converges (too few points, singular normal equations, no convergence).
///
/// Why the fallback: a nearly flat power law (T(eps) on all of (0, 60]) has A, B and C so
/// correlated that a start far from the optimum can wander for hundreds of iterations; the
/// profile lands near the optimum in B, the one nonlinear parameter. Fits that converge from
/// the given start are untouched.
pub fn fit(form: Form, x: &[f64], y: &[f64], start: [f64; 3]) -> Result<Fit, String> {
    let first = levenberg_marquardt(form, x, y, start);
    match first {
        Ok(fit) => Ok(fit),
        Err(reason) => match profile_start(form, x, y) {
            Some(profiled) => levenberg_marquardt(form, x, y, profiled)
                .map_err(|again| format!("{reason} (and from a start profiled over B: {again})")),
            None => Err(reason),
        },
    }
}

/// The (A, B, C) with the smallest residual over a grid of B, A and C solved exactly for each.
fn profile_start(form: Form, x: &[f64], y: &[f64]) -> Option<[f64; 3]> {
    let grid: Vec<f64> = match form {
        Form::Power => (0..=240)
            .map(|k| -3.0 + 6.0 * k as f64 / 240.0)
            .filter(|b: &f64| b.abs() > 1e-6)
            .collect(),
        Form::Tanh => (0..=240)
            .map(|k| 10f64.powf(-3.0 + 5.0 * k as f64 / 240.0))
            .collect(),
    };
    let n = x.len() as f64;
    grid.into_iter()
        .filter_map(|b| {
            let g: Vec<f64> = x.iter().map(|&xi| form.eval([1.0, b, 0.0], xi)).collect();
            let (sg, sgg) = (g.iter().sum::<f64>(), g.iter().map(|v| v * v).sum::<f64>());
            let (sy, sgy) = (
                y.iter().sum::<f64>(),
                g.iter().zip(y).map(|(a, b)| a * b).sum::<f64>(),
            );
            let det = n * sgg - sg * sg;
            if det.is_nan() || det.abs() <= 1e-300 {
                return None;
            }
            let a = (n * sgy - sg * sy) / det;
            let c = (sy - a * sg) / n;
            let ssr: f64 = g
                .iter()
                .zip(y)
                .map(|(gi, yi)| (a * gi + c - yi).powi(2))
                .sum();
            ssr.is_finite().then_some(([a, b, c], ssr))
        })
        .min_by(|p, q| p.1.total_cmp(&q.1))
        .map(|(p, _)| p)
}

fn levenberg_marquardt(form: Form, x: &[f64], y: &[f64], start: [f64; 3]) -> Result<Fit, String> {
    let n = x.len();
    if n != y.len() || n < 4 {
        return Err(format!("need at least 4 points with x and y, have {n}"));
    }
    if form == Form::Power && x.iter().any(|&v| v <= 0.0) {
        return Err("the power form needs x > 0".into());
    }
    let ssr_of = |p: [f64; 3]| {
        x.iter()
            .zip(y)
            .map(|(&a, &b)| (form.eval(p, a) - b).powi(2))
            .sum::<f64>()
    };
    let mut p = start;
    let mut ssr = ssr_of(p);
    let mut lambda = 1e-3;
    let mut iterations = 0;
    let mut converged = false;
    while iterations < MAX_ITERATIONS {
        iterations += 1;
        let (jtj, jtr) = normal_equations(form, p, x, y);
        let mut improved = false;
        while lambda < 1e16 {
            let mut a = jtj;
            for k in 0..3 {
                a[k][k] += lambda * jtj[k][k].max(1e-300);
            }
            let Some(step) = solve(a, jtr.map(|v| -v)) else {
                lambda *= 10.0;
                continue;
            };
            let trial = [p[0] + step[0], p[1] + step[1], p[2] + step[2]];
            let trial_ssr = ssr_of(trial);
            if trial_ssr.is_finite() && trial_ssr <= ssr {
                let small = step
                    .iter()
                    .zip(p)
                    .all(|(s, v)| s.abs() <= 1e-12 * (v.abs() + 1e-12));
                converged = small || (ssr - trial_ssr) <= 1e-15 * ssr.max(1e-300);
                p = trial;
                ssr = trial_ssr;
                lambda = (lambda / 10.0).max(1e-12);
                improved = true;
                break;
            }
            lambda *= 10.0;
        }
        if converged || !improved {
            converged = true;
            break;
        }
    }
    if !converged {
        let drift = if form == Form::Power && p[1].abs() < 1e-2 && p[0].abs() > 10.0 {
            "; the fit drifts to B → 0, |A| → ∞, the limit a + b ln x: no power law fits these data"
        } else {
            ""
        };
        return Err(format!(
            "no convergence in {MAX_ITERATIONS} iterations (last A, B, C = {:.4e}, {:.4e}, {:.4e}){drift}",
            p[0], p[1], p[2]
        ));
    }
    let (jtj, _) = normal_equations(form, p, x, y);
    let inverse = invert(jtj)
        .ok_or("singular normal equations at the optimum (parameters not identifiable)")?;
    let s2 = ssr / (n - 3) as f64;
    let std_errors = [0, 1, 2].map(|k| (s2 * inverse[k][k]).max(0.0).sqrt());
    let norm_y = y.iter().map(|v| v * v).sum::<f64>().sqrt();
    Ok(Fit {
        params: p,
        std_errors,
        ssr,
        relative_error: ssr.sqrt() / norm_y,
        iterations,
    })
}

type Matrix = [[f64; 3]; 3];

fn normal_equations(form: Form, p: [f64; 3], x: &[f64], y: &[f64]) -> (Matrix, [f64; 3]) {
    let mut jtj = [[0.0; 3]; 3];
    let mut jtr = [0.0; 3];
    for (&xi, &yi) in x.iter().zip(y) {
        let g = form.gradient(p, xi);
        let r = form.eval(p, xi) - yi;
        for a in 0..3 {
            jtr[a] += g[a] * r;
            for b in 0..3 {
                jtj[a][b] += g[a] * g[b];
            }
        }
    }
    (jtj, jtr)
}

/// Solves a x = b by Gaussian elimination with partial pivoting.
fn solve(mut a: Matrix, mut b: [f64; 3]) -> Option<[f64; 3]> {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for col in 0..3 {
        let pivot = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() <= 1e-14 * scale {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let rest: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - rest) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

fn invert(a: Matrix) -> Option<Matrix> {
    let columns = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| solve(a, e));
    let mut inv = [[0.0; 3]; 3];
    for (j, column) in columns.into_iter().enumerate() {
        let column = column?;
        for i in 0..3 {
            inv[i][j] = column[i];
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> Vec<f64> {
        (1..=600).map(|i| i as f64 * 0.1).collect()
    }

    #[test]
    fn recovers_exact_parameters_of_both_forms() {
        let x = grid();
        for (form, truth, start) in [
            (Form::Power, [0.5630, -0.0110, 0.3345], [1.0, -0.5, 0.0]),
            (Form::Tanh, [0.5491, 0.0830, 0.0760], [0.3, 0.3, 0.0]),
        ] {
            let y: Vec<f64> = x.iter().map(|&v| form.eval(truth, v)).collect();
            let fit = fit(form, &x, &y, start).unwrap();
            for k in 0..3 {
                assert!(
                    (fit.params[k] - truth[k]).abs() < 1e-7,
                    "{form:?} {k}: {:?}",
                    fit.params
                );
            }
            assert!(fit.relative_error < 1e-9);
        }
    }

    #[test]
    fn standard_errors_match_the_scatter_of_the_data() {
        // Deterministic "noise" of amplitude 1e-3: the errors are of that order over sqrt(n).
        let x = grid();
        let truth = [0.55, 0.08, 0.07];
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                Form::Tanh.eval(truth, v) + 1e-3 * ((i * 7919 % 1000) as f64 / 500.0 - 1.0)
            })
            .collect();
        let fit = fit(Form::Tanh, &x, &y, [0.3, 0.3, 0.0]).unwrap();
        for k in 0..3 {
            assert!(
                fit.std_errors[k] > 0.0 && fit.std_errors[k] < 1e-3,
                "{:?}",
                fit.std_errors
            );
            assert!((fit.params[k] - truth[k]).abs() < 5.0 * fit.std_errors[k] + 1e-4);
        }
    }

    #[test]
    fn bad_inputs_are_errors() {
        assert!(fit(
            Form::Power,
            &[0.0, 1.0, 2.0, 3.0],
            &[1.0; 4],
            [1.0, 1.0, 0.0]
        )
        .is_err());
        assert!(fit(Form::Tanh, &[1.0, 2.0], &[1.0, 2.0], [1.0, 1.0, 0.0]).is_err());
        // A constant cannot identify A and B.
        assert!(fit(Form::Tanh, &grid(), &vec![0.3; 600], [0.0, 0.0, 0.3]).is_err());
    }
}
