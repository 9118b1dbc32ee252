//! Contact laws: everything the simulator knows about how two neighbours push on each other,
//! one type per law behind one trait (`Law`), each in its own file and named once in the
//! registry at the end of this file ([`ChainLaw`]).
//!
//! - [`hertz`]: the paper's law, `[d]_+^{3/2}` with unit coefficients and no precompression
//!   (`PaperHertz`), a type with no data whose loops compile to the paper's own.
//! - [`general`]: the experiment's law ([`ContactLaw`]): a coefficient per contact, any
//!   exponent, a precompression or gravity's weights.
//! - [`linear_gap`]: a one-sided linear spring across a gap ([`LinearGap`]), the worked example
//!   of docs/adding-a-law.md.
//!
//! A model holds one [`ChainLaw`] ([`crate::Model::law`]), and `with_law!` runs generic
//! code with the law's own type, so that the choice is made once per call, outside every loop.
//! A new law is a new file with a type that implements `Law`, and one line in the registry.
//!
//! Bonds are numbered as the recorded bond forces are: bond 0 is the left wall, bond b
//! (1 ≤ b < S) joins sites b − 1 and b, bond S is the right wall. A bond's relative
//! displacement r is its left member's minus its right member's (a wall counts as at rest).

pub use general::{ContactLaw, LawParts, EXPONENT_RANGE};
pub use hertz::{hertz_force, hertz_potential, PaperHertz};
pub use linear_gap::LinearGap;

use crate::damping::Damping;
use crate::integrate::contact_event::BondPath;

/// Largest contact force for which an opening or closing is left to the method: the correction
/// of such a bond is below |force| h, under 1e-15 in a dimensionless chain struck at unit
/// velocity. Four in five contact changes on the paper's scenes are grazing touches of the
/// quiet chain behind the wave, with forces below 1e-16; skipping them changes no fraction by
/// more than 1e-16 and saves most of the correction's cost.
pub(crate) const NEGLIGIBLE_FORCE: f64 = 1e-14;

/// What a contact law is to the simulator: its forces, its potential, the integrals the
/// contact-event correction takes along a bond's path, the bounds the scan and the planner
/// use, and its dissipative part. Each force is computed by the same operations wherever it
/// is used (the chain loops, the patch after a corrected step, the walls), which is what keeps
/// every path's bits equal.
pub(crate) trait Law {
    /// The number of bonds (sites + 1, walls included) the law is written for, or `None` for
    /// a law that is the same at every bond.
    fn n_bonds(&self) -> Option<usize>;

    /// What the law was built from, for cache keys ([`crate::model::parts`]).
    fn describe(&self) -> LawOf<'_>;

    /// Whether walls at both ends must hold the law's static forces (a precompression).
    fn held_by_walls(&self) -> bool {
        false
    }

    /// The contact exponent α.
    fn exponent(&self) -> f64;

    /// g when the contacts carry the weights above them, 0 otherwise.
    fn gravity(&self) -> f64;

    /// The static overlap δ_b of bond `bond`: 0 without a load, positive under one, negative
    /// across a gap.
    fn static_overlap(&self, bond: usize) -> f64;

    /// The total overlap c of bond `bond` at relative displacement `r`: its static overlap
    /// plus r.
    #[inline(always)]
    fn overlap(&self, bond: usize, r: f64) -> f64 {
        self.static_overlap(bond) + r
    }

    /// The elastic force of bond `bond` at relative displacement `r`: what is recorded, and
    /// positive exactly while the contact is closed.
    fn elastic(&self, bond: usize, r: f64) -> f64;

    /// The static force the rest state balances at bond `bond` (0 without a load).
    fn static_force(&self, bond: usize) -> f64;

    /// The force bond `bond` adds to the rest state's, from its `elastic` force: what pushes.
    /// Zero, exactly, at rest.
    fn net(&self, bond: usize, elastic: f64) -> f64;

    /// The potential of bond `bond` at relative displacement `r`, measured from the rest
    /// state; its derivative in r is the net force.
    fn potential(&self, bond: usize, r: f64) -> f64;

    /// The static overlap of every bond, or `None` when all are 0 (then a bond's overlap is its
    /// relative displacement, and the contact scan takes its block test).
    fn static_overlaps(&self) -> Option<&[f64]>;

    /// `(∫_0^h F ds, ∫_0^h (h − s) F ds)` of bond `bond`'s elastic force along `path` (a path
    /// of the total overlap), over a step of size `h`.
    fn path_integrals(&self, bond: usize, path: &BondPath, h: f64) -> (f64, f64);

    /// [`Law::path_integrals`] under the fast-mode weights of an exactly integrated resonator
    /// (θ = ω h; [`crate::integrate::contact_event::oscillating_path_integrals`]).
    fn oscillating_integrals(&self, bond: usize, path: &BondPath, h: f64, theta: f64)
        -> (f64, f64);

    /// Whether bond `bond`'s elastic force at total overlap `c` is below the contact scan's
    /// negligible force ([`NEGLIGIBLE_FORCE`]).
    fn force_negligible(&self, bond: usize, c: f64) -> bool;

    /// The stiffness dF/dc of bond `bond` at total overlap `c` > 0 (the linear picture's
    /// spring about a static state).
    fn stiffness(&self, bond: usize, c: f64) -> f64;

    /// A bound on the total overlap bond `bond` reaches when it holds all of `energy` on top
    /// of its static state.
    fn overlap_within(&self, bond: usize, energy: f64) -> f64;

    /// The stiffness dF/dc of bond `bond` at the largest overlap `energy` allows, which bounds
    /// an explicit step; `None` for a law the steps are calibrated on (the paper's, whose
    /// methods' first steps were measured on it).
    fn stiffness_within(&self, bond: usize, energy: f64) -> Option<f64> {
        Some(self.stiffness(bond, self.overlap_within(bond, energy)))
    }

    /// The elastic force of each of `n_bonds` bonds at rest (what a record reads for a bond
    /// outside the active window).
    fn forces_at_rest(&self, n_bonds: usize) -> Vec<f64> {
        (0..n_bonds).map(|b| self.static_force(b)).collect()
    }

    /// The dissipative part: bond `bond`'s force at relative displacement `r` closing at
    /// `rate` under `damping`'s contact dashpot (if any), and the dashpot's power.
    #[inline(always)]
    fn damped(
        &self,
        damping: Option<&Damping>,
        bond: usize,
        r: f64,
        rate: f64,
    ) -> (BondForce, f64) {
        let (c, elastic, rest) = (
            self.overlap(bond, r),
            self.elastic(bond, r),
            self.static_force(bond),
        );
        // At c = 0 the dashpot already acts: a contact closing from touching (an impulse
        // given to a site beside one at rest) feels γ ċ from its first instant.
        let total = match damping {
            Some(d) if d.contact_at(bond) > 0.0 && c >= 0.0 => {
                (elastic + d.law.force(d.contact_at(bond), c, rate)).max(0.0)
            }
            _ => elastic,
        };
        (
            BondForce {
                total,
                elastic,
                rest,
            },
            (total - elastic) * rate,
        )
    }
}

/// `a` times both of a path's integrals `(∫ F ds, ∫ (h − s) F ds)`: a law's coefficient taken
/// out of its quadrature.
#[inline(always)]
pub(crate) fn scaled(a: f64, (impulse, moment): (f64, f64)) -> (f64, f64) {
    (a * impulse, a * moment)
}

/// One contact's force: the total the sites feel (clipped at zero), its elastic part, and the
/// static force the rest state balances (0 without precompression).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BondForce {
    pub total: f64,
    pub elastic: f64,
    pub rest: f64,
}

/// What a law was built from, as a cache key hashes it.
#[derive(Debug, Clone, PartialEq)]
pub enum LawOf<'a> {
    /// The paper's law, which adds nothing to a key.
    Paper,
    /// The experiment's law ([`ContactLaw::parts`]).
    Experiment(LawParts<'a>),
    /// Any other law: its name, and its defining numbers by name.
    Named {
        /// The law's name, unique in the registry.
        name: &'static str,
        /// Each defining array, by name.
        numbers: Vec<(&'static str, &'a [f64])>,
    },
}

/// Declares the registry: the modules of the laws, [`ChainLaw`] with one variant per law, its
/// conversions, and `with_law!`, which dispatches on it. `$d` is a `$` passed in, so that the
/// inner macro can name its own metavariables.
macro_rules! registry {
    ($d:tt $( $(#[$doc:meta])* $variant:ident => $module:ident :: $law:ident, )*) => {
        $( pub mod $module; )*

        /// A chain's contact law: one variant per law in the registry.
        #[derive(Debug, Clone, PartialEq)]
        pub enum ChainLaw {
            $( $(#[$doc])* $variant($module::$law), )*
        }

        $(
            impl From<$module::$law> for ChainLaw {
                fn from(law: $module::$law) -> ChainLaw {
                    ChainLaw::$variant(law)
                }
            }
        )*

        /// Runs `$body` with `$law` bound to the law of `$contacts` (a `&ChainLaw`) as a
        /// reference to its own type, so that generic code over [`Law`] is compiled once per
        /// law and the choice is made here, once, outside its loops.
        macro_rules! with_law {
            ($d contacts:expr, |$d law:ident| $d body:expr) => {
                match $d contacts {
                    $( $crate::contact::ChainLaw::$variant($d law) => $d body, )*
                }
            };
        }
    };
}

// The registry: every law the simulator runs, one line each.
registry! { $
    /// The paper's law.
    Paper => hertz::PaperHertz,
    /// The experiment's law.
    Experiment => general::ContactLaw,
    /// A one-sided linear spring across a gap.
    LinearGap => linear_gap::LinearGap,
}
pub(crate) use with_law;

impl ChainLaw {
    /// Whether this is the paper's law (unit coefficients, exponent 3/2, no static force).
    pub fn is_papers(&self) -> bool {
        matches!(self, ChainLaw::Paper(_))
    }

    /// The law's exponent α.
    pub fn exponent(&self) -> f64 {
        with_law!(self, |law| Law::exponent(law))
    }

    /// The number of bonds the law is written for (`None`: the same law at every bond).
    pub fn n_bonds(&self) -> Option<usize> {
        with_law!(self, |law| Law::n_bonds(law))
    }

    /// Whether walls at both ends must hold the law's static forces (a precompression).
    pub fn held_by_walls(&self) -> bool {
        with_law!(self, |law| Law::held_by_walls(law))
    }

    /// What the law was built from, for cache keys.
    pub fn describe(&self) -> LawOf<'_> {
        with_law!(self, |law| Law::describe(law))
    }
}

impl Default for ChainLaw {
    fn default() -> ChainLaw {
        ChainLaw::Paper(PaperHertz)
    }
}
