//! Linear resonators integrated exactly: the extended Nyström step of `erkn6-contact`.
//!
//! Why: a linear resonator (p = 1, constant κ) and its host vibrate against each other at
//! ω² = κ (1/m + 1/ε), and light resonators make ω large. An ordinary Nyström step resolves
//! that vibration only while ω h is small: DPRKN6 grows its amplitude by 4e-6 a step at ω h = 1,
//! so `auto` capped ω h at 0.5, and on F7's light resonators the coarse run of its first pair
//! missed by 18 times what a heavy resonator's did (docs/performance.md). Here the pair's spring
//! is integrated exactly and only the rest of the force, g (the contacts), by the tableau.
//!
//! Each pair's spring is a linear term −Ω² q of rank one: on the pair's coordinates (u, v)
//! Ω² = κ [[1/m, −1/m], [−1/ε, 1/ε]], whose eigenvalues are 0 and ω². So any function of
//! V = h²Ω² is f(V) x = f(0) x + (f(θ²) − f(0)) P x with θ = ω h and P the projector on the fast
//! mode, P x = (κ/ω²)(x_u − x_v) (1/m, −1/ε). The step is the extended Runge–Kutta–Nyström
//! (ERKN) form of the variation-of-constants formula (Wu, You and Wang, 2013):
//!
//! ```text
//! Q_i = φ0(c_i² V) q + c_i h φ1(c_i² V) p + h² Σ_j ā_ij(V) g(Q_j)
//! q+  = φ0(V) q + h φ1(V) p + h² Σ_i b̄_i(V) g(Q_i)
//! p+  = −h Ω² φ1(V) q + φ0(V) p + h Σ_i b_i(V) g(Q_i)
//! ```
//!
//! with φ0(x) = cos √x and φ1(x) = sin √x / √x. Every coefficient function equals the tableau's
//! own at V = 0, so the step is the plain tableau's on every other degree of freedom, and on a
//! pair it is the plain step plus a shift along the fast mode (`Shift`). Each coefficient's
//! change with V is that of an interpolatory rule of the variation-of-constants integral on the
//! stage nodes available to it, `exact_weights`: the weights of the new velocity are exact
//! for a forcing polynomial of degree S − 1 in time, those of a stage and of the new position
//! for degree i − 2 on the i − 1 nodes before stage i. At V = 0 those changes vanish, so the
//! method keeps the tableau's order conditions; for any θ the free vibration (g = 0) and a
//! constant forcing are integrated exactly.

use crate::model::Model;

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

/// One host site and its harmonic resonator.
#[derive(Debug, Clone, Copy)]
struct Pair {
    /// The host site, which is also its position's index in the state.
    host: usize,
    /// The resonator's position index in the state.
    resonator: usize,
    kappa: f64,
    inv_host_mass: f64,
    omega: f64,
    /// The fast mode's direction, scaled by κ/ω²: P x = (x_u − x_v) `mode`.
    mode: [f64; 2],
}

/// A pair's coefficient changes for one step size h, θ = ω h: what the ERKN step adds to the
/// plain tableau's, as multiples of the fast mode.
#[derive(Debug, Clone, Copy)]
struct PairStep<const S: usize> {
    theta: f64,
    /// Stage i: φ0(c_i²θ²) − 1 (times the stretch) and c_i h (φ1(c_i²θ²) − 1) (times its rate).
    stage_q: [f64; S],
    stage_p: [f64; S],
    /// h² (ā_ij(θ²) − a_ij).
    stage_g: [[f64; S]; S],
    /// The new velocity: −θ sin θ / h, cos θ − 1 and h (b_i(θ²) − b_i(0)).
    velocity_q: f64,
    velocity_p: f64,
    velocity_g: [f64; S],
    /// The weight functions at θ² themselves (unscaled), for the contact correction: the new
    /// velocity's b_i and the new position's b̄_i.
    b_velocity: [f64; S],
    b_position: [f64; S],
}

/// The harmonic pairs of a model and their coefficients for the step size last prepared.
#[derive(Debug, Clone)]
pub(crate) struct ExactResonators<const S: usize> {
    tableau: NystromWeights<S>,
    pairs: Vec<Pair>,
    /// Each site's pair, if it hosts one: the contact correction asks per corrected bond.
    pair_of_site: Vec<Option<usize>>,
    steps: Vec<PairStep<S>>,
    /// The step size `steps` are for.
    h: f64,
}

impl<const S: usize> ExactResonators<S> {
    /// The harmonic pairs of `model` ([`Model::is_harmonic`]) for the tableau of `weights`, or
    /// `None` when it has none. The tableau must end on the force at the new position (FSAL),
    /// as DPRKN6 does: the new position is then its last stage, shifted like every stage.
    pub fn of(model: &Model, tableau: NystromWeights<S>) -> Option<Self> {
        assert!(
            tableau.c[S - 1] == 1.0,
            "an exact resonator step needs an FSAL tableau"
        );
        let pairs: Vec<Pair> = (0..model.resonators().len())
            .filter(|&j| model.is_harmonic(j))
            .map(|j| {
                let r = model.resonators()[j];
                let kappa = r.coupling.max_value();
                let inv_host_mass = 1.0 / model.site_mass(r.site);
                let inv_eps = 1.0 / r.eps;
                let omega_squared = kappa * (inv_host_mass + inv_eps);
                let scale = kappa / omega_squared;
                Pair {
                    host: r.site,
                    resonator: model.n_sites() + j,
                    kappa,
                    inv_host_mass,

                    omega: omega_squared.sqrt(),
                    mode: [scale * inv_host_mass, -scale * inv_eps],
                }
            })
            .collect();
        let mut pair_of_site = vec![None; model.n_sites()];
        for (k, pair) in pairs.iter().enumerate() {
            pair_of_site[pair.host] = Some(k);
        }
        (!pairs.is_empty()).then(|| Self {
            tableau,
            pairs,
            pair_of_site,
            steps: Vec::new(),
            h: f64::NAN,
        })
    }

    /// Makes the coefficients those of step size `h` (computed only when it changed).
    pub fn prepare(&mut self, h: f64) {
        if h == self.h {
            return;
        }
        self.h = h;
        let tableau = self.tableau;
        self.steps = self
            .pairs
            .iter()
            .map(|p| pair_step(&tableau, p.omega * h, h))
            .collect();
    }

    /// Turns stage accelerations `acc` (of positions `q`) into the forcing g: each pair's spring
    /// force taken out of its host's acceleration, and its resonator's set to zero (a
    /// resonator feels its spring only). Pairs whose host is outside `lo..=hi` are at rest.
    #[inline(always)]
    pub fn to_forcing(&self, q: &[f64], acc: &mut [f64], (lo, hi): (usize, usize)) {
        for p in &self.pairs {
            if p.host < lo || p.host > hi {
                continue;
            }
            acc[p.host] += p.kappa * (q[p.host] - q[p.resonator]) * p.inv_host_mass;
            acc[p.resonator] = 0.0;
        }
    }

    /// Adds stage `i`'s shift along each pair's fast mode to the stage position `q_stage`
    /// (already the plain tableau's), from the step's start (`q`, `p`) and the forcings `g` of
    /// the stages before it.
    #[inline(always)]
    pub fn shift_stage(
        &self,
        i: usize,
        (q, p): (&[f64], &[f64]),
        g: &[Vec<f64>; S],
        q_stage: &mut [f64],
        (lo, hi): (usize, usize),
    ) {
        for (pair, step) in self.pairs.iter().zip(&self.steps) {
            if pair.host < lo || pair.host > hi {
                continue;
            }
            let stretch = |x: &[f64]| x[pair.host] - x[pair.resonator];
            let mut shift = step.stage_q[i] * stretch(q) + step.stage_p[i] * stretch(p);
            for (j, g_j) in g.iter().enumerate().take(i) {
                shift += step.stage_g[i][j] * stretch(g_j);
            }
            q_stage[pair.host] += shift * pair.mode[0];
            q_stage[pair.resonator] += shift * pair.mode[1];
        }
    }

    /// Adds each pair's fast-mode shift to the new velocity `new_p` (already the plain
    /// tableau's). The new position needs none of its own: it is the last stage's.
    #[inline(always)]
    pub fn shift_velocity(
        &self,
        (q, p): (&[f64], &[f64]),
        g: &[Vec<f64>; S],
        new_p: &mut [f64],
        (lo, hi): (usize, usize),
    ) {
        for (pair, step) in self.pairs.iter().zip(&self.steps) {
            if pair.host < lo || pair.host > hi {
                continue;
            }
            let stretch = |x: &[f64]| x[pair.host] - x[pair.resonator];
            let mut shift = step.velocity_q * stretch(q) + step.velocity_p * stretch(p);
            for (weight, g_i) in step.velocity_g.iter().zip(g) {
                shift += weight * stretch(g_i);
            }
            new_p[pair.host] += shift * pair.mode[0];
            new_p[pair.resonator] += shift * pair.mode[1];
        }
    }

    /// The pair whose host is `site`, if any: its index, θ and the fast mode's share of a unit
    /// force on the host, `P e_host / m` (host and resonator entries).
    pub fn host(&self, site: usize) -> Option<HostOf<S>> {
        let k = self.pair_of_site[site]?;
        let (pair, step) = (&self.pairs[k], &self.steps[k]);
        Some(HostOf {
            host: pair.host,
            resonator: pair.resonator,
            theta: step.theta,
            share: [
                pair.mode[0] * pair.inv_host_mass,
                pair.mode[1] * pair.inv_host_mass,
            ],
            b_velocity: step.b_velocity,
            b_position: step.b_position,
        })
    }
}

/// What the contact correction needs of a host's pair ([`ExactResonators::host`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct HostOf<const S: usize> {
    pub host: usize,
    pub resonator: usize,
    /// ω h.
    pub theta: f64,
    /// P e_host / m_host: how a unit impulse on the host splits into the fast mode.
    pub share: [f64; 2],
    /// The ERKN weights at θ²: the new velocity's b_i and the new position's b̄_i.
    pub b_velocity: [f64; S],
    pub b_position: [f64; S],
}

/// The coefficient changes of one pair at θ = ω h for step size `h`.
fn pair_step<const S: usize>(tableau: &NystromWeights<S>, theta: f64, h: f64) -> PairStep<S> {
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
            let mut factorial = 1.0;
            for k in 0..6 {
                let sum: f64 = (0..6)
                    .map(|i| step.b_velocity[i] * DPRKN6.c[i].powi(k))
                    .sum();
                assert!(
                    (sum - factorial * phi[k as usize + 1]).abs() < 1e-13,
                    "b θ={theta} k={k}"
                );
                if k < 5 {
                    let sum: f64 = (0..6)
                        .map(|i| step.b_position[i] * DPRKN6.c[i].powi(k))
                        .sum();
                    assert!(
                        (sum - factorial * phi[k as usize + 2]).abs() < 1e-13,
                        "b̄ θ={theta} k={k}"
                    );
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
