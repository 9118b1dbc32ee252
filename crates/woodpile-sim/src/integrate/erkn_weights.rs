//! The coefficients of the extended Nyström step (`super::exact_resonator`): for a pair
//! vibrating at ω and a step h, how much each of the tableau's coefficients changes along the
//! pair's fast mode at θ = ω h. Each change is that of an interpolatory rule of the
//! variation-of-constants integral on the stage nodes the coefficient may use, so it vanishes
//! at θ = 0 (where the step is the tableau's) and makes the φ-weighted integrals exact for
//! polynomial forcing at any θ.

/// What the extended step needs of a Nyström tableau ending on the force at the new position
/// (FSAL): its nodes and both weight vectors.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NystromWeights<const S: usize> {
    /// Stage times.
    pub c: [f64; S],
    /// Position weights (times h²), also the last stage's row.
    pub b: [f64; S],
    /// Velocity weights (times h).
    pub b_prime: [f64; S],
}

/// A pair's coefficient changes for one step size h, θ = ω h: what the ERKN step adds to the
/// plain tableau's, as multiples of the fast mode.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PairStep<const S: usize> {
    pub theta: f64,
    /// Stage i: φ0(c_i²θ²) − 1 (times the stretch) and c_i h (φ1(c_i²θ²) − 1) (times its rate).
    pub stage_q: [f64; S],
    pub stage_p: [f64; S],
    /// h² (ā_ij(θ²) − a_ij).
    pub stage_g: [[f64; S]; S],
    /// The new velocity: −θ sin θ / h, cos θ − 1 and h (b_i(θ²) − b_i(0)).
    pub velocity_q: f64,
    pub velocity_p: f64,
    pub velocity_g: [f64; S],
    /// The weight functions at θ² themselves (unscaled), for the contact correction: the new
    /// velocity's b_i and the new position's b̄_i.
    pub b_velocity: [f64; S],
    pub b_position: [f64; S],
}

/// The coefficient changes of one pair at θ = ω h for step size `h`.
pub(crate) fn pair_step<const S: usize>(
    tableau: &NystromWeights<S>,
    theta: f64,
    h: f64,
) -> PairStep<S> {
    let c = tableau.c;
    let mut stage_q = [0.0; S];
    let mut stage_p = [0.0; S];
    let mut stage_g = [[0.0; S]; S];
    for i in 1..S {
        let phi = phis(c[i] * c[i] * theta * theta);
        stage_q[i] = phi[0] - 1.0;
        stage_p[i] = c[i] * h * (phi[1] - 1.0);
        let change: [f64; S] = position_weight_change(&c[..i], c[i], theta);
        for j in 0..i {
            stage_g[i][j] = h * h * change[j];
        }
    }
    let phi = phis(theta * theta);
    let velocity_change = velocity_weight_change(&c, theta);
    let position_change: [f64; S] = position_weight_change(&c[..S - 1], 1.0, theta);
    PairStep {
        theta,
        stage_q,
        stage_p,
        stage_g,
        velocity_q: -theta * theta * phi[1] / h,
        velocity_p: phi[0] - 1.0,
        velocity_g: std::array::from_fn(|i| h * velocity_change[i]),
        b_velocity: std::array::from_fn(|i| tableau.b_prime[i] + velocity_change[i]),
        b_position: std::array::from_fn(|i| tableau.b[i] + position_change[i]),
    }
}

/// φ_0 ..= φ_7 at x = θ² ≥ 0: φ_j(x) = Σ_m (−x)^m / (2m + j)!, so φ_0 = cos θ and
/// φ_1 = sin θ / θ. The series for x ≤ 16 (its terms then fall from the first for j ≥ 2, or
/// cancel by at most a factor 10), the recurrence φ_{j+2} = (1/j! − φ_j) / x beyond.
pub(crate) fn phis(x: f64) -> [f64; 8] {
    let theta = x.sqrt();
    let mut phi = [0.0; 8];
    phi[0] = theta.cos();
    phi[1] = if theta == 0.0 {
        1.0
    } else {
        theta.sin() / theta
    };
    let mut factorial = [1.0f64; 48];
    for k in 1..48 {
        factorial[k] = factorial[k - 1] * k as f64;
    }
    for j in 2..8 {
        phi[j] = if x <= 16.0 {
            let mut sum = 0.0;
            let mut power = 1.0;
            for m in 0..20 {
                sum += power / factorial[2 * m + j];
                power *= -x;
            }
            sum
        } else {
            (1.0 / factorial[j - 2] - phi[j - 2]) / x
        };
    }
    phi
}

/// The change from θ = 0 to θ of the interpolatory weights on `nodes` (fractions of the step)
/// of the position integral to `end`: ∫_0^end (end − z) φ1((end − z)² θ²) g(z) dz, whose
/// moments are ∫ z^k … = k! end^{k+2} φ_{k+2}(end² θ²).
fn position_weight_change<const S: usize>(nodes: &[f64], end: f64, theta: f64) -> [f64; S] {
    let moments = |x: f64| {
        let phi = phis(end * end * x);
        let mut out = [0.0; S];
        let mut scale = end * end;
        for k in 0..nodes.len() {
            out[k] = scale * phi[k + 2];
            scale *= (k + 1) as f64 * end;
        }
        out
    };
    weight_change(nodes, moments(theta * theta), moments(0.0))
}

/// The change from θ = 0 to θ of the interpolatory weights on `nodes` of the velocity
/// integral ∫_0^1 φ0((1 − z)² θ²) g(z) dz, whose moments are k! φ_{k+1}(θ²).
fn velocity_weight_change<const S: usize>(nodes: &[f64; S], theta: f64) -> [f64; S] {
    let moments = |x: f64| {
        let phi = phis(x);
        let mut out = [0.0; S];
        let mut factorial = 1.0;
        for k in 0..S {
            out[k] = factorial * phi[k + 1];
            factorial *= (k + 1) as f64;
        }
        out
    };
    weight_change(nodes, moments(theta * theta), moments(0.0))
}

/// w(θ) − w(0) for the interpolatory weights w on `nodes` with moments `at_theta` and
/// `at_zero` (Σ_i w_i c_i^k = moment_k): one solve of the Vandermonde system with their
/// difference.
fn weight_change<const S: usize>(nodes: &[f64], at_theta: [f64; S], at_zero: [f64; S]) -> [f64; S] {
    let n = nodes.len();
    let mut rhs = [0.0; S];
    for k in 0..n {
        rhs[k] = at_theta[k] - at_zero[k];
    }
    let mut matrix = [[0.0; S]; S];
    for (k, row) in matrix.iter_mut().enumerate().take(n) {
        for (i, node) in nodes.iter().enumerate() {
            row[i] = node.powi(k as i32);
        }
    }
    solve(&mut matrix, &mut rhs, n);
    rhs
}

/// Solves the leading n × n system in place by Gaussian elimination with partial pivoting.
fn solve<const S: usize>(matrix: &mut [[f64; S]; S], rhs: &mut [f64; S], n: usize) {
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&a, &b| matrix[a][col].abs().total_cmp(&matrix[b][col].abs()))
            .unwrap_or(col);
        matrix.swap(col, pivot);
        rhs.swap(col, pivot);
        let pivot_row = matrix[col];
        for row in col + 1..n {
            let factor = matrix[row][col] / pivot_row[col];
            for (entry, pivot_entry) in matrix[row][col..n].iter_mut().zip(&pivot_row[col..n]) {
                *entry -= factor * pivot_entry;
            }
            rhs[row] -= factor * rhs[col];
        }
    }
    for col in (0..n).rev() {
        let mut value = rhs[col];
        for (entry, solved) in matrix[col][col + 1..n].iter().zip(&rhs[col + 1..n]) {
            value -= entry * solved;
        }
        rhs[col] = value / matrix[col][col];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::DPRKN6;

    const DPRKN6_WEIGHTS: NystromWeights<6> = NystromWeights {
        c: DPRKN6.c,
        b: DPRKN6.b,
        b_prime: DPRKN6.b_prime,
    };

    /// The φ functions by series and by recurrence agree where both are accurate, and match
    /// their closed forms.
    #[test]
    fn phi_functions_match_their_closed_forms() {
        for x in [0.0, 0.3, 2.0, 9.0, 16.0, 25.0, 100.0] {
            let phi = phis(x);
            let theta: f64 = x.sqrt();
            assert!((phi[0] - theta.cos()).abs() < 1e-15);
            if x > 0.0 {
                assert!((phi[2] - (1.0 - theta.cos()) / x).abs() < 1e-14, "φ2({x})");
                assert!(
                    (phi[3] - (1.0 - theta.sin() / theta) / x).abs() < 1e-14,
                    "φ3({x})"
                );
            }
            for j in 2..6 {
                let by_recurrence =
                    (1.0 / [1.0, 1.0, 2.0, 6.0, 24.0, 120.0][j - 2] - phi[j - 2]) / x;
                if x >= 9.0 {
                    assert!(
                        (phi[j] - by_recurrence).abs() < 1e-12 * phi[j].abs().max(1e-3),
                        "φ{j}({x})"
                    );
                }
            }
        }
    }

    /// With θ the velocity weights integrate φ0((1 − z)²θ²) z^k exactly for k < 6, and the
    /// position weights (five nodes) (1 − z) φ1 z^k for k < 5; at θ = 0 they are DPRKN6's.
    #[test]
    fn weights_are_exact_for_polynomial_forcing() {
        for theta in [0.0, 0.4, 1.3, 3.0] {
            let step = pair_step(&DPRKN6_WEIGHTS, theta, 0.2);
            let phi = phis(theta * theta);
            // Σ_i w_i c_i^k against its exact moment k! φ_j(θ²).
            let moment =
                |w: &[f64; 6], k: i32| -> f64 { (0..6).map(|i| w[i] * DPRKN6.c[i].powi(k)).sum() };
            let mut factorial = 1.0;
            for k in 0..6 {
                let velocity = moment(&step.b_velocity, k) - factorial * phi[k as usize + 1];
                assert!(velocity.abs() < 1e-13, "b θ={theta} k={k}");
                if k < 5 {
                    let position = moment(&step.b_position, k) - factorial * phi[k as usize + 2];
                    assert!(position.abs() < 1e-13, "b̄ θ={theta} k={k}");
                }
                factorial *= f64::from(k + 1);
            }
            assert_eq!(
                step.b_position[5], 0.0,
                "the new position cannot use its own force"
            );
        }
        let at_zero = pair_step(&DPRKN6_WEIGHTS, 0.0, 0.2);
        assert_eq!(at_zero.b_velocity, DPRKN6.b_prime);
        assert_eq!(at_zero.b_position, DPRKN6.b);
    }
}
