//! A Nyström step's sums (each stage position, the new position and velocity) in one pass over
//! the window each, instead of one pass per coefficient.
//!
//! A stage position is `q + c h v + h² Σ_j a_ij k_j`: written as one pass per term it loads
//! and stores the sum once per term, and on a short range (a chain's few resonators) each pass
//! is mostly loop overhead. Here every element is summed in a register, term after term, in
//! the order of the pass-by-pass form: the same operations in the same order, so the same bits.
//! The number of terms is made a constant (one copy of the loop per count) so that the loop
//! over the elements vectorises with the terms unrolled inside it.

/// The first operand of a sum: `x`, or `x + c·y` (a position and its velocity).
#[derive(Clone, Copy)]
pub(crate) enum Base<'a> {
    /// `x` alone.
    Of(&'a [f64]),
    /// `x + c·y`.
    Plus(&'a [f64], f64, &'a [f64]),
}

/// The most terms a sum takes: a tableau's stages.
pub(crate) const MAX_TERMS: usize = 6;

/// The terms `w_j·a_j` of one sum, in the order they are added (zero weights left out).
pub(crate) struct Terms<'a> {
    weights: [f64; MAX_TERMS],
    slices: [&'a [f64]; MAX_TERMS],
    len: usize,
}

impl<'a> Terms<'a> {
    /// No terms yet.
    pub(crate) fn new() -> Self {
        Self {
            weights: [0.0; MAX_TERMS],
            slices: [&[]; MAX_TERMS],
            len: 0,
        }
    }

    /// Adds `w·a` after the terms already there; a zero `w` adds nothing (the pass-by-pass form
    /// skips it too). At most [`MAX_TERMS`] nonzero terms (`Rkn::new` checks its tableau's
    /// stages against it).
    pub(crate) fn push(&mut self, w: f64, a: &'a [f64]) {
        if w != 0.0 {
            self.weights[self.len] = w;
            self.slices[self.len] = a;
            self.len += 1;
        }
    }
}

/// `out[k] = base[k] + w_0·a_0[k] + w_1·a_1[k] + …`, added left to right. Every slice must be
/// at least `out.len()` long.
#[inline(always)]
pub(crate) fn sum_into(out: &mut [f64], base: Base<'_>, terms: &Terms<'_>) {
    match base {
        Base::Of(x) => by_count::<false>(out, (x, 0.0, x), terms),
        Base::Plus(x, c, y) => by_count::<true>(out, (x, c, y), terms),
    }
}

/// [`sum_into`] with the number of terms made a constant, one copy of the loop per count.
#[inline(always)]
fn by_count<const PLUS: bool>(out: &mut [f64], base: (&[f64], f64, &[f64]), terms: &Terms<'_>) {
    match terms.len {
        0 => fixed::<PLUS, 0>(out, base, terms),
        1 => fixed::<PLUS, 1>(out, base, terms),
        2 => fixed::<PLUS, 2>(out, base, terms),
        3 => fixed::<PLUS, 3>(out, base, terms),
        4 => fixed::<PLUS, 4>(out, base, terms),
        5 => fixed::<PLUS, 5>(out, base, terms),
        _ => fixed::<PLUS, MAX_TERMS>(out, base, terms),
    }
}

/// The sum with `J` terms, `x + c·y` when `PLUS` (else `x`) first.
#[inline(always)]
fn fixed<const PLUS: bool, const J: usize>(
    out: &mut [f64],
    (x, c, y): (&[f64], f64, &[f64]),
    terms: &Terms<'_>,
) {
    let n = out.len();
    let (x, y) = (&x[..n], &y[..n]);
    let w: [f64; J] = std::array::from_fn(|j| terms.weights[j]);
    let a: [&[f64]; J] = std::array::from_fn(|j| &terms.slices[j][..n]);
    for k in 0..n {
        let mut s = if PLUS { x[k] + c * y[k] } else { x[k] };
        for j in 0..J {
            s += w[j] * a[j][k];
        }
        out[k] = s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pass-by-pass form the fused sum replaces.
    fn by_passes(base: Base<'_>, terms: &[(f64, &[f64])], n: usize) -> Vec<f64> {
        let mut out: Vec<f64> = match base {
            Base::Of(x) => x[..n].to_vec(),
            Base::Plus(x, c, y) => (0..n).map(|k| x[k] + c * y[k]).collect(),
        };
        for &(w, a) in terms {
            if w != 0.0 {
                for k in 0..n {
                    out[k] += w * a[k];
                }
            }
        }
        out
    }

    #[test]
    fn every_term_count_gives_the_pass_by_pass_bits() {
        // Values of wildly different scales (and signed zeros) so that any reordering of the
        // additions would show in the bits.
        let column = |seed: u64| -> Vec<f64> {
            (0..37)
                .map(|k| {
                    let x = ((k as u64 * 2654435761 + seed * 40503) % 1000) as f64 - 500.0;
                    if k % 7 == 0 {
                        -0.0
                    } else {
                        x * 10f64.powi((k % 9) - 4)
                    }
                })
                .collect()
        };
        let (x, y) = (column(1), column(2));
        let a: Vec<Vec<f64>> = (3..9).map(column).collect();
        let weights = [0.37, 0.0, -1.3e-3, 2.5e4, -0.0, 1.0 / 3.0];
        for count in 0..=MAX_TERMS {
            let listed: Vec<(f64, &[f64])> = (0..count).map(|j| (weights[j], &a[j][..])).collect();
            let mut terms = Terms::new();
            for &(w, s) in &listed {
                terms.push(w, s);
            }
            for base in [Base::Of(&x), Base::Plus(&x, 0.129, &y)] {
                for n in [0, 1, 5, 37] {
                    let mut out = vec![f64::NAN; n];
                    sum_into(&mut out, base, &terms);
                    let expected = by_passes(base, &listed, n);
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&out), bits(&expected), "{count} terms, n = {n}");
                }
            }
        }
    }
}
