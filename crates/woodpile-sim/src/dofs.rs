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

/// A state's positions and velocities, each read through [`Dofs`]: a step's start or end as
/// the contact corrections read it.
pub(crate) struct Phase<'a, D: ?Sized> {
    pub q: &'a D,
    pub v: &'a D,
}

impl<D: ?Sized> Clone for Phase<'_, D> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<D: ?Sized> Copy for Phase<'_, D> {}

impl<'a> Phase<'a, [f64]> {
    /// The positions and velocities of a state `[q, q', …]` of `n_dof` degrees of freedom.
    #[inline(always)]
    pub fn of(state: &'a [f64], n_dof: usize) -> Self {
        let (q, rest) = state.split_at(n_dof);
        Phase {
            q,
            v: &rest[..n_dof],
        }
    }
}

/// A step's two states `[q, q', …]`: the one it began from and the one it ended at, before
/// any correction: what the contact scans read to find the bonds that changed.
#[derive(Clone, Copy)]
pub(crate) struct StepStates<'a> {
    pub start: &'a [f64],
    pub end: &'a [f64],
}

/// [`StepStates`] whose end the corrections write.
pub(crate) struct StepStatesMut<'a> {
    pub start: &'a [f64],
    pub end: &'a mut [f64],
}

/// [`Phase`], written through [`DofsMut`]: a step's end as the corrections change it.
pub(crate) struct PhaseMut<'a, D: ?Sized> {
    pub q: &'a mut D,
    pub v: &'a mut D,
}

impl<D: ?Sized> PhaseMut<'_, D> {
    /// The same state, borrowed again for one more writer.
    #[inline(always)]
    pub fn reborrow(&mut self) -> PhaseMut<'_, D> {
        PhaseMut {
            q: &mut *self.q,
            v: &mut *self.v,
        }
    }
}
