//! What lies beyond the chain's two end sites: walls, free ends, or soft ends (a spring and a
//! dashpot on a rigid support), per end.

/// What lies beyond the two end sites.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Boundary {
    /// Immovable walls at u_{-1} = u_{S} = 0 (the paper's "zero boundary conditions"): an end
    /// site pushing outwards compresses a Hertzian contact with the wall.
    Fixed,
    /// Free ends: the end sites have a single neighbour.
    Free,
    /// One end walled and the other free (a chain struck at its free left end and resting on
    /// a wall). Built by [`Boundary::ends`], which never makes it with equal ends.
    Ends {
        /// Beyond the first site.
        left: End,
        /// Beyond the last site.
        right: End,
    },
}

/// One end of the chain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum End {
    /// An immovable wall, touching through a contact.
    Fixed,
    /// Nothing: the end site has a single neighbour.
    Free,
    /// A soft support (the foam an experiment rests its chain on): a linear spring and a
    /// dashpot between the end site and a rigid support, acting both ways, force
    /// −spring u − damping u̇ on the end site. With `damping = 0` the end is conservative.
    Soft {
        /// Spring constant (≥ 0).
        spring: f64,
        /// Dashpot coefficient (≥ 0).
        damping: f64,
    },
}

impl End {
    /// The soft end's spring and dashpot, if this end is soft.
    #[inline(always)]
    pub fn soft(self) -> Option<(f64, f64)> {
        match self {
            End::Soft { spring, damping } => Some((spring, damping)),
            _ => None,
        }
    }
}

impl Boundary {
    /// The boundary with these two ends: [`Boundary::Fixed`] or [`Boundary::Free`] when they
    /// agree, so that each boundary has one spelling.
    pub fn ends(left: End, right: End) -> Boundary {
        match (left, right) {
            (End::Fixed, End::Fixed) => Boundary::Fixed,
            (End::Free, End::Free) => Boundary::Free,
            (left, right) => Boundary::Ends { left, right },
        }
    }

    /// The end beyond the first site.
    pub fn left(self) -> End {
        match self {
            Boundary::Fixed => End::Fixed,
            Boundary::Free => End::Free,
            Boundary::Ends { left, .. } => left,
        }
    }

    /// The end beyond the last site.
    pub fn right(self) -> End {
        match self {
            Boundary::Fixed => End::Fixed,
            Boundary::Free => End::Free,
            Boundary::Ends { right, .. } => right,
        }
    }

    /// Whether a wall lies beyond the first site.
    #[inline(always)]
    pub fn left_wall(self) -> bool {
        matches!(self.left(), End::Fixed)
    }

    /// Whether a wall lies beyond the last site.
    #[inline(always)]
    pub fn right_wall(self) -> bool {
        matches!(self.right(), End::Fixed)
    }

    /// Whether either end is soft (a spring, perhaps with a dashpot).
    pub fn has_soft_end(self) -> bool {
        self.left().soft().is_some() || self.right().soft().is_some()
    }

    /// Whether a soft end carries a dashpot.
    pub fn dissipates(self) -> bool {
        [self.left(), self.right()]
            .into_iter()
            .any(|end| end.soft().is_some_and(|(_, c)| c > 0.0))
    }
}
