//! The one error type of the crate: every way a description can be refused or a computation can
//! decline, each with the numbers that explain it. Nothing in the crate panics on its input.

use thiserror::Error;

/// Why a chain, a cell or a computation on them was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SpectrumError {
    /// A chain or cell without sites.
    #[error("a chain needs at least one site")]
    EmptyChain,
    /// A list has the wrong length for the chain it describes.
    #[error("{what} has {len} entries, expected {expected}")]
    Length {
        /// The list.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The length the chain needs.
        expected: usize,
    },
    /// A value that must be finite is not.
    #[error("{what} must be finite, got {value}")]
    NotFinite {
        /// The quantity.
        what: String,
        /// Its value.
        value: f64,
    },
    /// A value that must be finite and > 0 is not.
    #[error("{what} must be finite and > 0, got {value}")]
    NotPositive {
        /// The quantity.
        what: String,
        /// Its value.
        value: f64,
    },
    /// A value that must be finite and ≥ 0 is not.
    #[error("{what} must be finite and >= 0, got {value}")]
    Negative {
        /// The quantity.
        what: String,
        /// Its value.
        value: f64,
    },
    /// A resonator hosted by a site the chain does not have.
    #[error("resonator {resonator} sits on site {site}, but the chain has {n_sites} sites")]
    SiteOutOfRange {
        /// Index of the resonator.
        resonator: usize,
        /// Its host site.
        site: usize,
        /// Number of sites.
        n_sites: usize,
    },
    /// A contact between two sites carries no static force, so its Hertzian stiffness
    /// α a δ0^{α−1} is zero (α > 1) or undefined (α = 1, at the kink): the chain is a sonic
    /// vacuum there and has no linear spectrum.
    #[error(
        "contact {bond} has no static overlap (δ0 = {overlap}): no static load, so the chain is \
         a sonic vacuum with no linear spectrum; give chain.precompression (walls at both \
         ends) or chain.gravity (a free top, a supported bottom)"
    )]
    NoStaticLoad {
        /// The bond (0 = left wall, b joins sites b−1 and b).
        bond: usize,
        /// Its static overlap.
        overlap: f64,
    },
    /// The dense eigenproblem would be too large for memory and time.
    #[error(
        "a dense eigenproblem of order {order} exceeds the limit {limit}; use the localised-mode \
         search (Sturm count and inverse iteration) for long chains"
    )]
    TooLargeForDense {
        /// Order of the matrix that would be decomposed.
        order: usize,
        /// The largest order accepted ([`crate::modes::MAX_DENSE_ORDER`]).
        limit: usize,
    },
    /// The linear-algebra crate's eigensolver did not converge.
    #[error("the eigensolver did not converge on the {what}")]
    NoConvergence {
        /// The matrix it was given.
        what: &'static str,
    },
    /// A frequency window whose bounds are not 0 ≤ lower < upper, finite.
    #[error("frequency window [{lower}, {upper}] must satisfy 0 <= lower < upper, both finite")]
    BadWindow {
        /// Lower bound (rad per unit time).
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// A window holds more eigenfrequencies than a localised-mode search returns: it overlaps
    /// a band of the chain rather than a gap.
    #[error(
        "window [{lower}, {upper}] holds {count} modes (limit {limit}): it overlaps a pass band, \
         not only a gap"
    )]
    TooManyModes {
        /// Lower bound of the window.
        lower: f64,
        /// Upper bound.
        upper: f64,
        /// Eigenfrequencies inside.
        count: usize,
        /// The most a search returns ([`crate::localised::MAX_LOCALISED`]).
        limit: usize,
    },
    /// A cell resonator with a dashpot: bands are those of the conservative cell.
    #[error("resonator {resonator} of the cell has a dashpot; bands are of the undamped cell")]
    DampedCell {
        /// Index of the resonator.
        resonator: usize,
    },
    /// Too few wavenumbers to sample a band structure.
    #[error("a band structure needs at least 2 wavenumbers in [0, pi], got {n_q}")]
    TooFewWavenumbers {
        /// Requested number.
        n_q: usize,
    },
    /// A scattering frequency at which the leads carry no travelling wave.
    #[error(
        "frequency {omega} is outside the leads' pass band (0, {cutoff}): no incoming wave to \
         scatter"
    )]
    OutsideLeadBand {
        /// The frequency.
        omega: f64,
        /// The leads' cutoff 2 sqrt(K/m).
        cutoff: f64,
    },
    /// A scattering region one of whose end bonds is zero: it is not coupled to that lead.
    #[error(
        "the scattering region's {side} end bond is zero: it is not coupled to the {side} lead"
    )]
    Detached {
        /// "left" or "right".
        side: &'static str,
    },
    /// A cell asked for, or a chain searched for one, that is not periodic.
    #[error("the cell does not repeat: {reason}")]
    CellDoesNotRepeat {
        /// Which site breaks the pattern, or why no copy fits.
        reason: String,
    },
    /// A chain with no uniform lead to scatter waves from.
    #[error("no transmission: {reason}")]
    NoLead {
        /// Why the chain's ends are not a uniform lead.
        reason: String,
    },
    /// A frequency range that holds no frequency, or lies outside the leads' pass band.
    #[error("frequency range [{lower}, {upper}] with {points} point(s): {fault}")]
    BadRange {
        /// Its lower end (rad per unit time).
        lower: f64,
        /// Its upper end.
        upper: f64,
        /// How many frequencies were asked for.
        points: usize,
        /// What is wrong with it.
        fault: RangeFault,
    },
}

/// What is wrong with a frequency range.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum RangeFault {
    /// An end is NaN or infinite.
    #[error("both ends must be finite")]
    NotFinite,
    /// Lower above upper, no points, or one point over a span.
    #[error(
        "it holds no frequency: need lower < upper and at least 2 points, or lower = upper and 1 point"
    )]
    Empty,
    /// Outside (0, cutoff).
    #[error("must lie inside the leads' pass band (0, {cutoff}), where a wave travels to scatter")]
    OutsideBand {
        /// The leads' cutoff (rad per unit time).
        cutoff: f64,
    },
}
