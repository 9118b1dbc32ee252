//! Bounded nonlinear least squares for a model the caller can only evaluate: Levenberg–Marquardt
//! with a forward-difference Jacobian, each parameter kept in its box by clamping the trial
//! point, and the covariance s² (JᵀJ)⁻¹ at the optimum, s² = SSR / (m − p).
//!
//! Why forward differences: the residuals come from simulations, whose cost dominates; a
//! central difference would double it for a Jacobian the damping of the method forgives. Why
//! clamping rather than a transform: the covariance is then that of the parameters as given,
//! and a bound that is active is reported as such.
// p×p linear algebra reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

/// One fitted parameter's box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Least value.
    pub min: f64,
    /// Greatest value.
    pub max: f64,
    /// The forward difference's step, when the parameter's size is not its value (a
    /// logarithm near 0 stands for a value near 1); `None`: [`STEP`] of its value.
    pub step: Option<f64>,
}

impl Bounds {
    /// `x` moved into the box.
    pub fn clamp(self, x: f64) -> f64 {
        x.clamp(self.min, self.max)
    }
}

/// A least-squares fit.
#[derive(Debug, Clone, PartialEq)]
pub struct LeastSquares {
    /// The parameters at the optimum.
    pub params: Vec<f64>,
    /// Their standard errors, from s² (JᵀJ)⁻¹ (NaN where JᵀJ is singular).
    pub std_errors: Vec<f64>,
    /// The residuals at the optimum.
    pub residuals: Vec<f64>,
    /// The sum of squared residuals.
    pub ssr: f64,
    /// Iterations taken.
    pub iterations: usize,
    /// Model evaluations made (the Jacobians' included).
    pub evaluations: usize,
    /// Which parameters ended on a bound.
    pub at_bound: Vec<bool>,
}

/// The forward difference's relative step. Not the 1e-8 a smooth function would take: the
/// residuals of a simulation are smooth only to about 1e-9 relative (its contact events), and
/// a step that small reads that roughness as slope.
pub const STEP: f64 = 1e-3;

/// Most iterations before the fit gives up.
pub const MAX_ITERATIONS: usize = 200;

/// Minimises the sum of squares of `residuals(params)` over the box `bounds`, from `start`.
/// `residuals` may fail (a parameter the model refuses), which the fit treats as a step too
/// far. Stops when a step changes the sum by less than a relative 1e-10.
pub fn least_squares<F>(
    mut residuals: F,
    start: &[f64],
    bounds: &[Bounds],
) -> Result<LeastSquares, String>
where
    F: FnMut(&[f64]) -> Result<Vec<f64>, String>,
{
    let p = start.len();
    let mut x: Vec<f64> = start.iter().zip(bounds).map(|(&s, b)| b.clamp(s)).collect();
    let mut r = residuals(&x).map_err(|e| format!("at the start: {e}"))?;
    let m = r.len();
    if m <= p {
        return Err(format!("{m} residuals cannot fit {p} parameters"));
    }
    let mut evaluations = 1;
    let mut ssr = sum_of_squares(&r);
    let mut lambda = 1e-3;
    for iteration in 1..=MAX_ITERATIONS {
        let jac = jacobian(&mut residuals, &x, &r, bounds)?;
        evaluations += p;
        let (jtj, jtr) = normal_equations(&jac, &r);
        let mut improved = false;
        while lambda < 1e12 {
            let step = damped_step(&jtj, &jtr, lambda);
            let trial: Vec<f64> = (0..p).map(|i| bounds[i].clamp(x[i] - step[i])).collect();
            evaluations += 1;
            let Ok(tr) = residuals(&trial) else {
                lambda *= 10.0;
                continue;
            };
            let trial_ssr = sum_of_squares(&tr);
            if trial_ssr < ssr {
                let change = (ssr - trial_ssr) / ssr.max(f64::MIN_POSITIVE);
                (x, r, ssr) = (trial, tr, trial_ssr);
                lambda = (lambda / 10.0).max(1e-12);
                improved = true;
                if change < 1e-10 {
                    return finish(&mut residuals, x, r, bounds, iteration, evaluations);
                }
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            return finish(&mut residuals, x, r, bounds, iteration, evaluations);
        }
    }
    Err(format!(
        "no convergence in {MAX_ITERATIONS} iterations (sum of squares {ssr:e})"
    ))
}

/// The fit at `x`, as if a search had ended there: its residuals and its standard errors from
/// the Jacobian there (for a point a derivative-free polish found).
pub fn assess<F>(mut residuals: F, x: &[f64], bounds: &[Bounds]) -> Result<LeastSquares, String>
where
    F: FnMut(&[f64]) -> Result<Vec<f64>, String>,
{
    let r = residuals(x)?;
    finish(&mut residuals, x.to_vec(), r, bounds, 0, 1)
}

/// The fit at `x`: its standard errors from the Jacobian there.
fn finish<F>(
    residuals: &mut F,
    x: Vec<f64>,
    r: Vec<f64>,
    bounds: &[Bounds],
    iterations: usize,
    evaluations: usize,
) -> Result<LeastSquares, String>
where
    F: FnMut(&[f64]) -> Result<Vec<f64>, String>,
{
    let p = x.len();
    let jac = jacobian(residuals, &x, &r, bounds)?;
    let (jtj, _) = normal_equations(&jac, &r);
    let ssr = sum_of_squares(&r);
    let s2 = ssr / (r.len() - p) as f64;
    let std_errors = match invert(&jtj) {
        Some(inv) => (0..p).map(|i| (s2 * inv[i][i]).sqrt()).collect(),
        None => vec![f64::NAN; p],
    };
    let at_bound = (0..p)
        .map(|i| x[i] <= bounds[i].min || x[i] >= bounds[i].max)
        .collect();
    Ok(LeastSquares {
        params: x,
        std_errors,
        residuals: r,
        ssr,
        iterations,
        evaluations: evaluations + p,
        at_bound,
    })
}

/// ∂r/∂x by forward differences, stepping inward from a bound.
fn jacobian<F>(
    residuals: &mut F,
    x: &[f64],
    r: &[f64],
    bounds: &[Bounds],
) -> Result<Vec<Vec<f64>>, String>
where
    F: FnMut(&[f64]) -> Result<Vec<f64>, String>,
{
    let mut columns = Vec::with_capacity(x.len());
    for i in 0..x.len() {
        let relative = STEP * x[i].abs().max(1e-3 * (bounds[i].max - bounds[i].min).abs());
        let mut h = bounds[i].step.unwrap_or(relative);
        if x[i] + h > bounds[i].max {
            h = -h;
        }
        let mut shifted = x.to_vec();
        shifted[i] += h;
        let rs = residuals(&shifted).map_err(|e| format!("in the Jacobian: {e}"))?;
        columns.push(rs.iter().zip(r).map(|(a, b)| (a - b) / h).collect());
    }
    Ok(columns)
}

/// JᵀJ and Jᵀr for a Jacobian stored by columns.
fn normal_equations(jac: &[Vec<f64>], r: &[f64]) -> (Vec<Vec<f64>>, Vec<f64>) {
    let p = jac.len();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let jtj = (0..p)
        .map(|i| (0..p).map(|k| dot(&jac[i], &jac[k])).collect())
        .collect();
    let jtr = (0..p).map(|i| dot(&jac[i], r)).collect();
    (jtj, jtr)
}

/// The step (JᵀJ + λ diag JᵀJ)⁻¹ Jᵀr (Marquardt's scaling); zero where the system is singular.
fn damped_step(jtj: &[Vec<f64>], jtr: &[f64], lambda: f64) -> Vec<f64> {
    let p = jtr.len();
    let mut a = jtj.to_vec();
    for i in 0..p {
        a[i][i] += lambda * jtj[i][i].max(1e-300);
    }
    match invert(&a) {
        Some(inv) => (0..p)
            .map(|i| (0..p).map(|k| inv[i][k] * jtr[k]).sum())
            .collect(),
        None => vec![0.0; p],
    }
}

/// The inverse of a small square matrix by Gauss–Jordan elimination with partial pivoting.
fn invert(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let mut m: Vec<Vec<f64>> = a.to_vec();
    let mut inv: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|k| f64::from(u8::from(i == k))).collect())
        .collect();
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &k| m[i][col].abs().total_cmp(&m[k][col].abs()))?;
        if m[pivot][col].abs() <= 1e-300 || !m[pivot][col].is_finite() {
            return None;
        }
        m.swap(col, pivot);
        inv.swap(col, pivot);
        let d = m[col][col];
        for k in 0..n {
            m[col][k] /= d;
            inv[col][k] /= d;
        }
        for row in 0..n {
            if row != col {
                let f = m[row][col];
                for k in 0..n {
                    m[row][k] -= f * m[col][k];
                    inv[row][k] -= f * inv[col][k];
                }
            }
        }
    }
    Some(inv)
}

fn sum_of_squares(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = a e^{−b x} from exact data: the fit recovers (a, b) from a start far off, and the
    /// standard errors vanish with the residuals.
    #[test]
    fn an_exponential_decay_is_recovered() {
        let x: Vec<f64> = (0..30).map(|i| i as f64 * 0.2).collect();
        let y: Vec<f64> = x.iter().map(|&x| 2.5 * (-0.7 * x).exp()).collect();
        let model = |p: &[f64]| -> Result<Vec<f64>, String> {
            Ok(x.iter()
                .zip(&y)
                .map(|(&x, &y)| p[0] * (-p[1] * x).exp() - y)
                .collect())
        };
        let bounds = [
            Bounds {
                min: 0.0,
                max: 10.0,
                step: None,
            },
            Bounds {
                min: 0.0,
                max: 5.0,
                step: None,
            },
        ];
        let fit = least_squares(model, &[1.0, 2.0], &bounds).unwrap();
        assert!((fit.params[0] - 2.5).abs() < 1e-6, "{fit:?}");
        assert!((fit.params[1] - 0.7).abs() < 1e-6, "{fit:?}");
        assert!(fit.std_errors.iter().all(|&s| s < 1e-5));
    }

    /// The standard error of a straight line's slope matches the closed form
    /// s / sqrt(Σ (x − x̄)²), and a bound holds a parameter whose optimum lies beyond it.
    #[test]
    fn a_line_has_its_textbook_errors_and_bounds_hold() {
        let x: Vec<f64> = (0..20).map(f64::from).collect();
        let noise = |i: usize| if i.is_multiple_of(2) { 0.1 } else { -0.1 };
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, &x)| 1.0 + 0.5 * x + noise(i))
            .collect();
        let model = |p: &[f64]| -> Result<Vec<f64>, String> {
            Ok(x.iter()
                .zip(&y)
                .map(|(&x, &y)| p[0] + p[1] * x - y)
                .collect())
        };
        let wide = [Bounds {
            min: -10.0,
            max: 10.0,
            step: None,
        }; 2];
        let fit = least_squares(model, &[0.0, 0.0], &wide).unwrap();
        let mean = x.iter().sum::<f64>() / 20.0;
        let sxx: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
        let s = (fit.ssr / 18.0).sqrt();
        assert!(
            (fit.std_errors[1] - s / sxx.sqrt()).abs() < 1e-6 * s,
            "{fit:?}"
        );
        let narrow = [
            Bounds {
                min: -10.0,
                max: 10.0,
                step: None,
            },
            Bounds {
                min: 0.0,
                max: 0.4,
                step: None,
            },
        ];
        let held = least_squares(model, &[0.0, 0.0], &narrow).unwrap();
        assert_eq!(held.params[1], 0.4);
        assert!(held.at_bound[1] && !held.at_bound[0]);
    }
}
