//! The searches a design runs, each evaluation labelled by the one that made it.

/// Where an evaluation comes from, in the order of the table's `search_index`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Search {
    /// The optimiser.
    DifferentialEvolution = 0,
    /// The baseline of the same budget.
    Random = 1,
    /// Nelder–Mead from the optimiser's best.
    Refinement = 2,
    /// The best design again at the verification tolerance.
    Verification = 3,
    /// The best design with eps and kappa off by up to ±1%.
    Robustness1 = 4,
    /// ... by up to ±5%.
    Robustness5 = 5,
    /// Nelder–Mead from the baseline's best.
    RefinementOfRandom = 6,
    /// ... by up to another spread.
    Robustness = 7,
}

impl Search {
    /// Every search, by `search_index`.
    pub const ALL: [Search; 8] = [
        Search::DifferentialEvolution,
        Search::Random,
        Search::Refinement,
        Search::Verification,
        Search::Robustness1,
        Search::Robustness5,
        Search::RefinementOfRandom,
        Search::Robustness,
    ];

    /// The name in the table's `search` column.
    pub fn label(self) -> &'static str {
        match self {
            Search::DifferentialEvolution => "differential evolution",
            Search::Random => "random",
            Search::Refinement => "refinement",
            Search::Verification => "verification",
            Search::Robustness1 => "robustness ±1%",
            Search::Robustness5 => "robustness ±5%",
            Search::RefinementOfRandom => "refinement of random",
            Search::Robustness => "robustness",
        }
    }

    /// The robustness study at relative spread `spread`.
    pub(super) fn robustness(spread: f64) -> Search {
        match spread {
            0.01 => Search::Robustness1,
            0.05 => Search::Robustness5,
            _ => Search::Robustness,
        }
    }

    pub(super) fn is_robustness(self) -> bool {
        matches!(
            self,
            Search::Robustness1 | Search::Robustness5 | Search::Robustness
        )
    }
}
