//! The active window: a step works only on the sites the wave has reached, plus a margin.

use crate::model::{Model, Window};

/// The sites that have ever moved, and the window a step must cover: those sites plus a
/// margin of twice the stepper's reach. Sites beyond the margin are exactly at rest (zero
/// displacement, velocity and force), so skipping them changes no bit of the result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ActiveSites {
    /// First and last site that has moved (None: nothing has moved yet).
    moved: Option<(usize, usize)>,
    margin: usize,
    n_sites: usize,
    enabled: bool,
}

impl ActiveSites {
    /// The moved sites of state `y`, for a stepper of reach `reach`. Disabled, the window is
    /// always the whole chain.
    pub fn new(model: &Model, y: &[f64], reach: usize, enabled: bool) -> Self {
        let mut active = Self {
            moved: None,
            margin: 2 * reach + 2,
            n_sites: model.n_sites(),
            enabled,
        };
        let n_dof = model.n_dof();
        let moving = |i: usize| y[i] != 0.0 || y[n_dof + i] != 0.0;
        let mut sites: Vec<usize> = (0..model.n_sites()).filter(|&i| moving(i)).collect();
        // A resonator that moves marks its site (an initial state may set one).
        for (j, r) in model.resonators().iter().enumerate() {
            let k = model.n_sites() + j;
            if y[k] != 0.0 || y[n_dof + k] != 0.0 {
                sites.push(r.site);
            }
        }
        if let (Some(&lo), Some(&hi)) = (sites.iter().min(), sites.iter().max()) {
            active.moved = Some((lo, hi));
        }
        active
    }

    /// The window for the next step.
    pub fn window(&self) -> Window {
        match (self.enabled, self.moved) {
            (true, Some((lo, hi))) => Window {
                lo: lo.saturating_sub(self.margin),
                hi: (hi + self.margin).min(self.n_sites - 1),
            },
            (true, None) => Window { lo: 0, hi: 0 },
            (false, _) => Window {
                lo: 0,
                hi: self.n_sites - 1,
            },
        }
    }

    /// Extends the moved sites after a step over `window`: only its margins can have changed.
    pub fn update(&mut self, model: &Model, y: &[f64], window: Window) {
        let n_dof = model.n_dof();
        self.update_by(window, |i| y[i] != 0.0 || y[n_dof + i] != 0.0);
    }

    /// [`ActiveSites::update`] for a state read through `moving(site)`: whether the site's
    /// displacement or velocity is not zero (a lane of a batch, `super::lanes`).
    pub(crate) fn update_by(&mut self, window: Window, moving: impl Fn(usize) -> bool) {
        if !self.enabled {
            return;
        }
        self.moved = match self.moved {
            None => {
                let lo = (window.lo..=window.hi).find(|&i| moving(i));
                let hi = (window.lo..=window.hi).rev().find(|&i| moving(i));
                lo.zip(hi)
            }
            Some((lo, hi)) => {
                let new_lo = (window.lo..lo).find(|&i| moving(i)).unwrap_or(lo);
                let new_hi = (hi + 1..=window.hi)
                    .rev()
                    .find(|&i| moving(i))
                    .unwrap_or(hi);
                Some((new_lo, new_hi))
            }
        };
    }
}
