//! The columns that kinds hand to each other, named once: a sweep's table is written by
//! `sweep` and read back by `reduce`, and the fractions (`R`, `T`, `E_tr`) are what reduce
//! maximises, optimize and design optimise, and report quotes.

/// The columns of a sweep's table: one row per sample of each point (or one row with the
/// reason for a point that failed), after the point's axis values under the axes' names.
pub mod sweep {
    /// The point's index in the grid.
    pub const POINT: &str = "point";
    /// The sample time.
    pub const TIME: &str = "t";
    /// The striker's share S (only in sweeps whose scenes have a `[striker]`).
    pub const STRIKER: &str = "S";
    /// The dissipated share D (sweeps of scenes with damping).
    pub const DISSIPATED: &str = "D";
    /// The total energy (or, for a kinetic series, the kinetic share of the impact energy).
    pub const ENERGY: &str = "E";
    /// The method of the reported run.
    pub const METHOD: &str = "method";
    /// Its fixed step, if any.
    pub const DT: &str = "dt";
    /// Its steps.
    pub const STEPS: &str = "steps";
    /// `auto`'s error estimate.
    pub const ERROR_ESTIMATE: &str = "error_estimate";
    /// The largest relative energy drift.
    pub const ENERGY_DRIFT: &str = "energy_drift";
    /// Why the point failed (null when it did not).
    pub const FAILURE: &str = "failure";
    /// The point's cache key.
    pub const SCENE_KEY: &str = "scene_key";
}

/// One of the energy fractions, by its column name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fraction {
    /// Trapped, `E_tr`.
    Trapped,
    /// Reflected, `R`.
    Reflected,
    /// Transmitted, `T`.
    Transmitted,
}

impl Fraction {
    /// Every fraction, in the order messages list them.
    pub const ALL: [Fraction; 3] = [
        Fraction::Trapped,
        Fraction::Reflected,
        Fraction::Transmitted,
    ];

    /// Its column name.
    pub fn column(self) -> &'static str {
        match self {
            Fraction::Trapped => "E_tr",
            Fraction::Reflected => "R",
            Fraction::Transmitted => "T",
        }
    }

    /// The fraction whose column is `name`.
    pub fn named(name: &str) -> Option<Fraction> {
        Fraction::ALL.into_iter().find(|f| f.column() == name)
    }

    /// Its value among (reflected, transmitted, trapped).
    pub fn of(self, reflected: f64, transmitted: f64, trapped: f64) -> f64 {
        match self {
            Fraction::Trapped => trapped,
            Fraction::Reflected => reflected,
            Fraction::Transmitted => transmitted,
        }
    }

    /// `["E_tr", "R", "T"]`, for messages.
    pub fn listed() -> String {
        format!("{:?}", Fraction::ALL.map(Fraction::column))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_round_trip_through_their_names() {
        for f in Fraction::ALL {
            assert_eq!(Fraction::named(f.column()), Some(f));
        }
        assert_eq!(Fraction::named("E"), None);
        assert_eq!(Fraction::listed(), r#"["E_tr", "R", "T"]"#);
        assert_eq!(Fraction::Reflected.of(0.1, 0.2, 0.3), 0.1);
    }
}
