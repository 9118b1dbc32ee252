//! The columns that kinds hand to each other, named once: a sweep's table is written by
//! `sweep` and read back by `reduce`, and the fractions (`R`, `T`, `E_tr`) are what reduce
//! maximises, optimize and design optimise, and report quotes.

/// The columns of a sweep's table, named where the table is made (`woodpile_points::rows`,
/// shared with Python's `sweep`).
pub use woodpile_points::rows::sweep;

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

    /// Every fraction under its column's name, the name a stage file gives it: the one table
    /// names are read from.
    pub const OPTIONS: [(&'static str, Fraction); 3] = [
        (sweep::TRAPPED, Fraction::Trapped),
        (sweep::REFLECTED, Fraction::Reflected),
        (sweep::TRANSMITTED, Fraction::Transmitted),
    ];

    /// Its column name.
    pub fn column(self) -> &'static str {
        match self {
            Fraction::Trapped => sweep::TRAPPED,
            Fraction::Reflected => sweep::REFLECTED,
            Fraction::Transmitted => sweep::TRANSMITTED,
        }
    }

    /// Its value among (reflected, transmitted, trapped).
    pub fn of(self, reflected: f64, transmitted: f64, trapped: f64) -> f64 {
        match self {
            Fraction::Trapped => trapped,
            Fraction::Reflected => reflected,
            Fraction::Transmitted => transmitted,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_round_trip_through_their_names() {
        for (name, f) in Fraction::OPTIONS {
            assert_eq!(f.column(), name);
        }
        assert_eq!(Fraction::OPTIONS.map(|(_, f)| f), Fraction::ALL);
        assert_eq!(Fraction::Reflected.of(0.1, 0.2, 0.3), 0.1);
    }
}
