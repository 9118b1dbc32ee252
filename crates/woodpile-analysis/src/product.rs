//! The paper's product approximation of the energy trapped between two separated defects
//! (Section V, Fig. 9): a wave transmitted by the first defect, reflected by the second, by the
//! first and by the second again,
//!
//!   E_tr(eps1, eps2) ≈ T1(eps1) R(eps2) R(eps1) R(eps2),
//!
//! with T1 and R fitted to single-defect numerics, and the two measures of how far it is from
//! the two-defect numerics.

use crate::lm::Form;

/// A fitted single-defect fraction: its form and coefficients A, B, C.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fitted {
    /// The form.
    pub form: Form,
    /// A, B, C.
    pub params: [f64; 3],
}

impl Fitted {
    fn at(&self, x: f64) -> f64 {
        self.form.eval(self.params, x)
    }
}

/// T1(a) R(b) R(a) R(b).
pub fn product(transmission: Fitted, reflection: Fitted, a: f64, b: f64) -> f64 {
    transmission.at(a) * reflection.at(b) * reflection.at(a) * reflection.at(b)
}

/// How far `approximation` is from `numerics` over the rows `keep` accepts (a row missing
/// either is skipped): the relative L2 error ‖f − y‖/‖y‖, and the root-mean-square difference
/// sqrt(mean (f − y)²), the measure that reproduces the paper's "relative error ~0.0369".
pub fn errors(
    numerics: &[Option<f64>],
    approximation: &[Option<f64>],
    keep: impl Fn(usize) -> bool,
) -> (Option<f64>, Option<f64>) {
    let (mut num, mut den, mut count) = (0.0, 0.0, 0usize);
    for i in (0..numerics.len()).filter(|&i| keep(i)) {
        let (Some(y), Some(f)) = (numerics[i], approximation.get(i).copied().flatten()) else {
            continue;
        };
        num += (f - y) * (f - y);
        den += y * y;
        count += 1;
    }
    (
        (den > 0.0).then(|| (num / den).sqrt()),
        (count > 0).then(|| (num / count as f64).sqrt()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_product_multiplies_the_four_passages() {
        let t = Fitted {
            form: Form::Power,
            params: [1.0, 1.0, 0.0],
        };
        let r = Fitted {
            form: Form::Tanh,
            params: [1.0, 1.0, 0.0],
        };
        let (a, b): (f64, f64) = (0.5, 2.0);
        let expected = a * b.tanh() * a.tanh() * b.tanh();
        assert!((product(t, r, a, b) - expected).abs() < 1e-15);
    }

    #[test]
    fn errors_are_relative_l2_and_rms_over_the_kept_rows() {
        let y = [Some(1.0), Some(2.0), None, Some(4.0)];
        let f = [Some(1.5), Some(2.0), Some(9.0), None];
        let (rel, rms) = errors(&y, &f, |_| true);
        assert!((rel.unwrap() - (0.25f64 / 5.0).sqrt()).abs() < 1e-15);
        assert!((rms.unwrap() - (0.25f64 / 2.0).sqrt()).abs() < 1e-15);
        assert_eq!(errors(&y, &f, |_| false), (None, None));
    }
}
