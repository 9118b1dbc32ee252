//! One scene's vector of degrees of freedom, read and written the same way whether it is a
//! state's own slice or one lane of a batch of four: what lets the pair steps, the contact
//! corrections and the force patch be written once for both.

/// A vector of degrees of freedom as the pair steps, the contact corrections and the force
/// patch read it: a state's own slice, or one lane of four (`crate::integrate::lanes`). Reads
/// and writes are plain loads, stores and additions, so both give the same bits.
pub(crate) trait Dofs {
    /// Entry `k`.
    fn at(&self, k: usize) -> f64;
}

/// [`Dofs`] that the pair steps also write.
pub(crate) trait DofsMut: Dofs {
    /// Entry `k` becomes `x`.
    fn set(&mut self, k: usize, x: f64);
    /// Entry `k` += `x`.
    #[inline(always)]
    fn add(&mut self, k: usize, x: f64) {
        self.set(k, self.at(k) + x);
    }
    /// Entry `k` −= `x`.
    #[inline(always)]
    fn sub(&mut self, k: usize, x: f64) {
        self.set(k, self.at(k) - x);
    }
}

impl Dofs for [f64] {
    #[inline(always)]
    fn at(&self, k: usize) -> f64 {
        self[k]
    }
}

impl DofsMut for [f64] {
    #[inline(always)]
    fn set(&mut self, k: usize, x: f64) {
        self[k] = x;
    }
}
