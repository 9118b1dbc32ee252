//! The energy shares, named once. Every output that reports shares (the JSON of a run, its
//! series, a sweep's table, `reduce`, Python's `simulate`, `simulate_many` and `sweep`)
//! iterates [`ShareSet`], so that a share is present, named and ordered alike everywhere: R,
//! T and E_tr always, S with a striker, D with losses.

use crate::energy::{Fractions, Region};
use crate::model::Model;
use crate::observe::FractionSeries;

/// One share of the impact's energy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Share {
    /// R: left of the read-out region.
    Reflected,
    /// T: right of it.
    Transmitted,
    /// E_tr: inside it.
    Trapped,
    /// S: the striker's own.
    Striker,
    /// D: dissipated so far.
    Dissipated,
}

impl Share {
    /// Every share, in the order outputs list them.
    pub const ALL: [Share; 5] = [
        Share::Reflected,
        Share::Transmitted,
        Share::Trapped,
        Share::Striker,
        Share::Dissipated,
    ];

    /// Its column and JSON name.
    pub const fn name(self) -> &'static str {
        match self {
            Share::Reflected => "R",
            Share::Transmitted => "T",
            Share::Trapped => "E_tr",
            Share::Striker => "S",
            Share::Dissipated => "D",
        }
    }

    /// Its value in `fractions`.
    pub fn of(self, fractions: &Fractions) -> f64 {
        match self {
            Share::Reflected => fractions.reflected,
            Share::Transmitted => fractions.transmitted,
            Share::Trapped => fractions.trapped,
            Share::Striker => fractions.striker,
            Share::Dissipated => fractions.dissipated,
        }
    }

    /// Its samples in `series`.
    pub fn in_series(self, series: &FractionSeries) -> &[f64] {
        match self {
            Share::Reflected => &series.reflected,
            Share::Transmitted => &series.transmitted,
            Share::Trapped => &series.trapped,
            Share::Striker => &series.striker,
            Share::Dissipated => &series.dissipated,
        }
    }

    /// Its samples in `series`, moved out.
    pub fn take_series(self, series: &mut FractionSeries) -> Vec<f64> {
        std::mem::take(match self {
            Share::Reflected => &mut series.reflected,
            Share::Transmitted => &mut series.transmitted,
            Share::Trapped => &mut series.trapped,
            Share::Striker => &mut series.striker,
            Share::Dissipated => &mut series.dissipated,
        })
    }
}

/// The shares a scene's outputs carry (the default: R, T and E_tr alone).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ShareSet {
    /// Whether site 0 is a striker (then S is reported).
    pub striker: bool,
    /// Whether anything dissipates (then D is reported).
    pub dissipative: bool,
}

impl ShareSet {
    /// The shares a run of `model` read out over `region` reports.
    pub fn of(model: &Model, region: &Region) -> ShareSet {
        ShareSet {
            striker: region.has_striker(),
            dissipative: model.is_dissipative(),
        }
    }

    /// The shares either set reports: those of a table whose rows come from many scenes.
    pub fn union(self, other: ShareSet) -> ShareSet {
        ShareSet {
            striker: self.striker || other.striker,
            dissipative: self.dissipative || other.dissipative,
        }
    }

    /// Whether `share` is reported.
    pub fn has(self, share: Share) -> bool {
        match share {
            Share::Reflected | Share::Transmitted | Share::Trapped => true,
            Share::Striker => self.striker,
            Share::Dissipated => self.dissipative,
        }
    }

    /// The reported shares, in [`Share::ALL`]'s order.
    pub fn iter(self) -> impl Iterator<Item = Share> {
        Share::ALL.into_iter().filter(move |&share| self.has(share))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_lists_its_shares_in_order() {
        let names = |set: ShareSet| set.iter().map(Share::name).collect::<Vec<_>>();
        let paper = ShareSet {
            striker: false,
            dissipative: false,
        };
        assert_eq!(names(paper), ["R", "T", "E_tr"]);
        let both = ShareSet {
            striker: true,
            dissipative: true,
        };
        assert_eq!(names(both), ["R", "T", "E_tr", "S", "D"]);
        let damped = ShareSet {
            striker: false,
            dissipative: true,
        };
        assert_eq!(names(damped), ["R", "T", "E_tr", "D"]);
    }

    #[test]
    fn each_share_reads_its_own_field() {
        let f = Fractions {
            reflected: 0.1,
            transmitted: 0.2,
            trapped: 0.3,
            striker: 0.15,
            dissipated: 0.25,
            total: 1.0,
        };
        let values: Vec<f64> = Share::ALL.iter().map(|s| s.of(&f)).collect();
        assert_eq!(values, [0.1, 0.2, 0.3, 0.15, 0.25]);
    }
}
