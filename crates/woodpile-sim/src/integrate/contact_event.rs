//! Exact impulses of a Hertz contact that opens or closes inside a step.
//!
//! Why: the contact force F(d) = \[d\]_+^{3/2} has a kink at d = 0. A step that contains the
//! moment a contact closes or opens integrates (t - t*)_+^{3/2} with RK4's quadrature, which
//! is only accurate to O(h^{5/2}); that single term is why every fixed-step method converges at
//! order 2.5 on a Hertzian chain instead of its classical order. `rk4-contact` keeps RK4 for
//! everything else and, for the few bonds whose overlap changes sign during a step, replaces
//! RK4's quadrature of that bond's force by the integral along the bond's path.
//!
//! The path is the cubic Hermite interpolant of the overlap d(s), s in [0, h], through its
//! values and rates at both ends of the step (the end values from the RK4 step itself). Over
//! the step the two sites receive the impulse `I0 = ∫ F(d(s)) ds` and the position change
//! `I1 = ∫ (h - s) F(d(s)) ds`, where RK4 gave `Q0 = h/6 (F1 + 2 F2 + 2 F3 + F4)` and
//! `Q1 = h²/6 (F1 + F2 + F3)` from its stage forces F1..F4; the correction adds I - Q.
//!
//! The integrals are computed on each sub-interval where d > 0: the cubic's critical points
//! split [0, 1] into monotone pieces, each with at most one root, found by bisection; on each
//! positive piece the substitution s = a + (b - a)(3x² - 2x³) makes the integrand smooth at a
//! root (F ~ (s - s*)^{3/2} becomes a smooth x³ (3 - 2x)^{3/2}), so 16-point Gauss–Legendre is
//! accurate to about 1e-14 relative (8 points give only 2e-7; tested against a fine rule).

/// Sixteen-point Gauss–Legendre on [-1, 1]: the positive nodes and their weights.
const GAUSS16_HALF: [(f64, f64); 8] = [
    (0.095_012_509_837_637_44, 0.189_450_610_455_068_64),
    (0.281_603_550_779_258_9, 0.182_603_415_044_923_64),
    (0.458_016_777_657_227_37, 0.169_156_519_395_002_65),
    (0.617_876_244_402_643_8, 0.149_595_988_816_576_7),
    (0.755_404_408_355_003, 0.124_628_971_255_534_07),
    (0.865_631_202_387_831_8, 0.095_158_511_682_492_6),
    (0.944_575_023_073_232_6, 0.062_253_523_938_647_456),
    (0.989_400_934_991_649_9, 0.027_152_459_411_754_176),
];

/// The same rule on [0, 1]: (node, weight) pairs.
fn gauss16() -> impl Iterator<Item = (f64, f64)> {
    GAUSS16_NODES.into_iter().zip(GAUSS16_WEIGHTS)
}

/// The nodes of [`gauss16`], in its order: each pair of ±x mapped to [0, 1].
const GAUSS16_NODES: [f64; 16] = {
    let mut nodes = [0.0; 16];
    let mut i = 0;
    while i < 8 {
        let x = GAUSS16_HALF[i].0;
        nodes[2 * i] = 0.5 - 0.5 * x;
        nodes[2 * i + 1] = 0.5 + 0.5 * x;
        i += 1;
    }
    nodes
};

/// The weights of [`gauss16`], in its order.
const GAUSS16_WEIGHTS: [f64; 16] = {
    let mut weights = [0.0; 16];
    let mut i = 0;
    while i < 16 {
        weights[i] = 0.5 * GAUSS16_HALF[i / 2].1;
        i += 1;
    }
    weights
};

/// One bond's overlap over a step: value and rate (d/ds) at s = 0 and s = h.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BondPath {
    pub d0: f64,
    pub rate0: f64,
    pub d1: f64,
    pub rate1: f64,
}

/// The overlap as a cubic in x = s/h: c0 + c1 x + c2 x² + c3 x³ (Hermite form).
struct Cubic([f64; 4]);

impl Cubic {
    fn hermite(path: &BondPath, h: f64) -> Self {
        let (d0, m0, d1, m1) = (path.d0, h * path.rate0, path.d1, h * path.rate1);
        Cubic([
            d0,
            m0,
            -3.0 * d0 - 2.0 * m0 + 3.0 * d1 - m1,
            2.0 * d0 + m0 - 2.0 * d1 + m1,
        ])
    }

    fn at(&self, x: f64) -> f64 {
        let c = &self.0;
        c[0] + x * (c[1] + x * (c[2] + x * c[3]))
    }

    /// d/dx of the cubic.
    fn slope(&self, x: f64) -> f64 {
        let c = &self.0;
        c[1] + x * (2.0 * c[2] + x * 3.0 * c[3])
    }

    /// Critical points strictly inside (0, 1), sorted.
    fn critical_points(&self) -> ([f64; 2], usize) {
        let (a, b, c) = (3.0 * self.0[3], 2.0 * self.0[2], self.0[1]);
        let mut out = [0.0; 2];
        let mut n = 0;
        let mut push = |x: f64| {
            if x > 0.0 && x < 1.0 {
                out[n] = x;
                n += 1;
            }
        };
        if a.abs() <= 1e-300 {
            if b != 0.0 {
                push(-c / b);
            }
        } else {
            let disc = b * b - 4.0 * a * c;
            if disc > 0.0 {
                let root = disc.sqrt();
                // Numerically stable pair of roots.
                let q = -0.5 * (b + b.signum() * root);
                let (x1, x2) = (q / a, if q != 0.0 { c / q } else { f64::NAN });
                let (lo, hi) = if x1 <= x2 { (x1, x2) } else { (x2, x1) };
                push(lo);
                push(hi);
            }
        }
        (out, n)
    }

    /// 0, the critical points inside (0, 1) and 1: the ends of the pieces on which the cubic is
    /// monotone (each holds at most one root), and how many there are.
    fn monotone_knots(&self) -> ([f64; 4], usize) {
        let (critical, n_critical) = self.critical_points();
        let mut knots = [0.0; 4];
        knots[1..=n_critical].copy_from_slice(&critical[..n_critical]);
        knots[n_critical + 1] = 1.0;
        (knots, n_critical + 2)
    }

    /// The root in [a, b] of a cubic monotone there with a sign change: Newton from the
    /// secant point, kept inside a shrinking bracket (bisection when Newton leaves it).
    fn root_between(&self, mut a: f64, mut b: f64) -> f64 {
        let (mut fa, fb) = (self.at(a), self.at(b));
        let positive_at_a = fa > 0.0;
        let mut x = a + (b - a) * fa / (fa - fb);
        for _ in 0..60 {
            let fx = self.at(x);
            if (fx > 0.0) == positive_at_a {
                a = x;
                fa = fx;
            } else {
                b = x;
            }
            let c = &self.0;
            let slope = c[1] + x * (2.0 * c[2] + x * 3.0 * c[3]);
            let newton = x - fx / slope;
            let next = if newton > a && newton < b {
                newton
            } else {
                0.5 * (a + b)
            };
            if (next - x).abs() <= 1e-15 || b - a <= 1e-15 {
                return next;
            }
            x = next;
        }
        let _ = fa;
        x
    }
}

/// The first moment, as a fraction of the step in (`after`, 1), at which the bond's Hermite path
/// crosses zero (a contact opens or closes), if any.
pub(crate) fn first_crossing(path: &BondPath, h: f64, after: f64) -> Option<f64> {
    let cubic = Cubic::hermite(path, h);
    let (knots, n_knots) = cubic.monotone_knots();
    knots[..n_knots].windows(2).find_map(|piece| {
        let (a, b) = (piece[0].max(after), piece[1]);
        let crosses = a < b && (cubic.at(a) > 0.0) != (cubic.at(b) > 0.0);
        crosses.then(|| cubic.root_between(a, b))
    })
}

/// `(∫_0^h F(d(s)) ds, ∫_0^h (h - s) F(d(s)) ds)` along the Hermite path, F = \[d\]_+^{3/2}.
pub(crate) fn path_integrals(path: &BondPath, h: f64) -> (f64, f64) {
    path_integrals_of(path, h, |d| d * d.sqrt())
}

/// [`path_integrals`] of the force `force(d)` of a positive overlap d, which must vanish like
/// a power d^α (α ≥ 1) as d closes: under the smoothing substitution the integrand then goes
/// like x^{2α}, smooth enough for the 16-point rule.
pub(crate) fn path_integrals_of(path: &BondPath, h: f64, force: impl Fn(f64) -> f64) -> (f64, f64) {
    let [impulse, moment] = weighted_path_integrals(path, h, force, |x| [1.0, 1.0 - x]);
    (impulse * h, moment * h * h)
}

/// [`path_integrals_of`] for a bond whose member hosts a resonator integrated exactly
/// (`erkn6-contact`, θ = ω h > 0): the variation-of-constants weights of the pair's fast mode,
/// `(∫_0^h cos(ω (h − s)) F ds, ∫_0^h sin(ω (h − s)) / ω F ds)`.
pub(crate) fn oscillating_path_integrals(
    path: &BondPath,
    h: f64,
    theta: f64,
    force: impl Fn(f64) -> f64,
) -> (f64, f64) {
    let weights = |x: f64| {
        let phase = theta * (1.0 - x);
        [phase.cos(), phase.sin() / theta]
    };
    let [impulse, moment] = weighted_path_integrals(path, h, force, weights);
    (impulse * h, moment * h * h)
}

/// `∫_0^1 w_k(x) F(d(x h)) dx` for the weights `weights(x)` along the Hermite path, on the
/// pieces where the overlap is positive.
fn weighted_path_integrals<const K: usize>(
    path: &BondPath,
    h: f64,
    force: impl Fn(f64) -> f64,
    weights: impl Fn(f64) -> [f64; K],
) -> [f64; K] {
    let cubic = Cubic::hermite(path, h);
    // Break points: 0, the critical points, 1; then the roots inside each monotone piece.
    let (knots, n_knots) = cubic.monotone_knots();
    let mut points = [0.0; 8];
    let mut n_points = 0;
    for piece in knots[..n_knots].windows(2) {
        let (a, b) = (piece[0], piece[1]);
        points[n_points] = a;
        n_points += 1;
        if (cubic.at(a) > 0.0) != (cubic.at(b) > 0.0) {
            points[n_points] = cubic.root_between(a, b);
            n_points += 1;
        }
    }
    points[n_points] = 1.0;
    n_points += 1;

    let mut sums = [0.0; K];
    for span in points[..n_points].windows(2) {
        let (a, b) = (span[0], span[1]);
        if !(b > a) || !(cubic.at(0.5 * (a + b)) > 0.0) {
            continue;
        }
        // The sixteen terms first, independent of each other (a loop that vectorises: most of
        // a corrected step's time is here), then added in the rule's order.
        let mut terms = [[0.0; K]; 16];
        for (i, term) in terms.iter_mut().enumerate() {
            let (x, w) = (GAUSS16_NODES[i], GAUSS16_WEIGHTS[i]);
            let smooth = x * x * (3.0 - 2.0 * x);
            let xi = a + (b - a) * smooth;
            let jacobian = 6.0 * x * (1.0 - x) * (b - a);
            let f = force(cubic.at(xi).max(0.0));
            for (t, weight) in term.iter_mut().zip(weights(xi)) {
                *t = w * jacobian * weight * f;
            }
        }
        for term in &terms {
            for (sum, t) in sums.iter_mut().zip(term) {
                *sum += t;
            }
        }
    }
    sums
}

/// [`path_integrals_of`] for a contact with a dashpot: `force(c, ċ)` gives the bond's total
/// force (clipped at zero) and its dashpot power at overlap c > 0 closing at rate ċ. Returns
/// the impulse, the moment and the energy dissipated along the path.
///
/// The force may jump where the contact closes (a linear dashpot's γ ċ) and has a kink where
/// the clip starts (the dashpot pulling harder than the spring pushes, as the contact opens):
/// each positive piece is split at those clip points too, found by bisection between a
/// grid of [`CLIP_SCAN`] points, so that the rule integrates a smooth function on every part.
pub(crate) fn damped_path_integrals(
    path: &BondPath,
    h: f64,
    force: impl Fn(f64, f64) -> (f64, f64),
) -> (f64, f64, f64) {
    let cubic = Cubic::hermite(path, h);
    let at = |x: f64| {
        let c = cubic.at(x);
        let rate = cubic.slope(x) / h;
        (c, rate)
    };
    // The unclipped force's sign decides the clip: total > 0 where it pushes.
    let pushes = |x: f64| {
        let (c, rate) = at(x);
        c > 0.0 && force(c, rate).0 > 0.0
    };
    let (mut impulse, mut moment, mut lost) = (0.0, 0.0, 0.0);
    for (a, b) in positive_pieces(&cubic) {
        // Samples just inside both ends and at the grid's midpoints; each change of "pushes"
        // between neighbours is a clip point.
        let inside = 1e-12 * (b - a);
        let samples: Vec<f64> = std::iter::once(a + inside)
            .chain((0..CLIP_SCAN).map(|k| a + (b - a) * (k as f64 + 0.5) / CLIP_SCAN as f64))
            .chain(std::iter::once(b - inside))
            .collect();
        let mut cuts = vec![a];
        for pair in samples.windows(2) {
            if pushes(pair[0]) != pushes(pair[1]) {
                cuts.push(bisect(&pushes, pair[0], pair[1]));
            }
        }
        cuts.push(b);
        for part in cuts.windows(2) {
            let (p, q) = (part[0], part[1]);
            if !(q > p) {
                continue;
            }
            for (x, w) in gauss16() {
                let smooth = x * x * (3.0 - 2.0 * x);
                let xi = p + (q - p) * smooth;
                let jacobian = 6.0 * x * (1.0 - x) * (q - p);
                let (c, rate) = at(xi);
                if !(c > 0.0) {
                    continue;
                }
                let (f, power) = force(c, rate);
                impulse += w * jacobian * f;
                moment += w * jacobian * (1.0 - xi) * f;
                lost += w * jacobian * power;
            }
        }
    }
    (impulse * h, moment * h * h, lost * h)
}

/// The first moment, as a fraction of the step in (0, 1), at which a damped contact's force
/// switches along its path: the contact closes (its force jumps to γ ċ with a linear dashpot,
/// and rises as √c with a Hertzian one) or its clip starts (a kink). `force(c, ċ)` is as for
/// [`damped_path_integrals`]. Found on a grid of [`CLIP_SCAN`] points, then by bisection.
pub(crate) fn first_switch(
    path: &BondPath,
    h: f64,
    force: impl Fn(f64, f64) -> (f64, f64),
) -> Option<f64> {
    let cubic = Cubic::hermite(path, h);
    let pushes = |x: f64| {
        let c = cubic.at(x);
        c > 0.0 && force(c, cubic.slope(x) / h).0 > 0.0
    };
    let grid = |k: usize| k as f64 / CLIP_SCAN as f64;
    (1..=CLIP_SCAN)
        .map(|k| (grid(k - 1), grid(k)))
        .find(|&(a, b)| pushes(a) != pushes(b))
        .map(|(a, b)| bisect(&pushes, a, b))
}

/// Sub-intervals a positive piece is scanned in for the start of a dashpot's clip.
const CLIP_SCAN: usize = 32;

/// The point in [a, b] where `holds` changes, by bisection to the last bit.
fn bisect(holds: &impl Fn(f64) -> bool, mut a: f64, mut b: f64) -> f64 {
    let at_a = holds(a);
    for _ in 0..64 {
        let mid = 0.5 * (a + b);
        if mid <= a || mid >= b {
            break;
        }
        if holds(mid) == at_a {
            a = mid;
        } else {
            b = mid;
        }
    }
    0.5 * (a + b)
}

/// The pieces of [0, 1] on which the cubic is positive, split at its roots.
fn positive_pieces(cubic: &Cubic) -> impl Iterator<Item = (f64, f64)> + '_ {
    let (knots, n_knots) = cubic.monotone_knots();
    let mut points = vec![];
    for piece in knots[..n_knots].windows(2) {
        let (a, b) = (piece[0], piece[1]);
        points.push(a);
        if (cubic.at(a) > 0.0) != (cubic.at(b) > 0.0) {
            points.push(cubic.root_between(a, b));
        }
    }
    points.push(1.0);
    let spans: Vec<(f64, f64)> = points.windows(2).map(|w| (w[0], w[1])).collect();
    spans
        .into_iter()
        .filter(move |&(a, b)| b > a && cubic.at(0.5 * (a + b)) > 0.0)
}

/// RK4's own quadrature of a bond force from its four stage values:
/// `(h/6 (F1 + 2 F2 + 2 F3 + F4), h²/6 (F1 + F2 + F3))`.
pub(crate) fn rk4_quadrature(stage_forces: [f64; 4], h: f64) -> (f64, f64) {
    let [f1, f2, f3, f4] = stage_forces;
    (
        h / 6.0 * (f1 + 2.0 * f2 + 2.0 * f3 + f4),
        h * h / 6.0 * (f1 + f2 + f3),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(path: &BondPath, h: f64) -> (f64, f64) {
        // Composite midpoint rule on a million points: slow, simple, accurate to ~1e-12.
        let cubic = Cubic::hermite(path, h);
        let n = 1_000_000;
        let (mut i0, mut i1) = (0.0, 0.0);
        for k in 0..n {
            let x = (k as f64 + 0.5) / n as f64;
            let d = cubic.at(x).max(0.0);
            let f = d * d.sqrt();
            i0 += f;
            i1 += (1.0 - x) * f;
        }
        (i0 * h / n as f64, i1 * h * h / n as f64)
    }

    #[test]
    fn integrals_match_a_fine_quadrature_for_closing_opening_and_grazing_contacts() {
        let cases = [
            // closing: negative to positive
            BondPath {
                d0: -0.01,
                rate0: 0.5,
                d1: 0.02,
                rate1: 0.45,
            },
            // opening
            BondPath {
                d0: 0.03,
                rate0: -0.4,
                d1: -0.01,
                rate1: -0.3,
            },
            // closes and reopens inside the step
            BondPath {
                d0: -0.002,
                rate0: 0.2,
                d1: -0.002,
                rate1: -0.2,
            },
            // fully positive (no kink): plain smooth integral
            BondPath {
                d0: 0.1,
                rate0: 0.1,
                d1: 0.12,
                rate1: 0.0,
            },
        ];
        for path in &cases {
            let h = 0.1;
            let (i0, i1) = path_integrals(path, h);
            let (r0, r1) = reference(path, h);
            assert!(
                (i0 - r0).abs() <= 1e-10 * r0.abs().max(1e-12),
                "{path:?}: {i0} vs {r0}"
            );
            assert!(
                (i1 - r1).abs() <= 1e-10 * r1.abs().max(1e-12),
                "{path:?}: {i1} vs {r1}"
            );
        }
    }

    #[test]
    fn open_paths_carry_no_impulse() {
        let path = BondPath {
            d0: -0.1,
            rate0: 0.1,
            d1: -0.05,
            rate1: 0.0,
        };
        assert_eq!(path_integrals(&path, 0.1), (0.0, 0.0));
    }
}
