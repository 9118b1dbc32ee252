//! The chain as the independent reference writes it: its own forces, powers and energies,
//! read from a [`Model`]'s defining parts ([`Model::parts`]) and nothing the simulator
//! derived from them, so that a mistake in the simulator's force code cannot hide in both.
//!
//! ```text
//! bond b between bodies l and r:  c = δ_b + x_l − x_r,  ċ = v_l − v_r   (a wall's x, v are 0)
//! pushing:   F = a_b [c]_+^α + γ_b g(c) ċ,  g = 1 or √[c]_+,   on l: −F, on r: +F
//! clipped:   F = 0 (the dashpot would pull), power −a_b [c]_+^α ċ
//! resonator: f = κ(t) s^p + c_j ṡ,  s = x_host − x_j,            on host: −f, on j: +f
//! ground −g v on each site; a soft end −k x − d v on its end site
//! ```
//!
//! Forces are physical (not measured from the precompressed rest state, as the simulator's
//! are), and each bond is in one [`Mode`] for a whole step: the driver ends a step where a
//! bond changes mode, so every step integrates a smooth right-hand side.

use woodpile_sim::contact::LawOf;
use woodpile_sim::damping::DashpotLaw;
use woodpile_sim::model::{Coupling, End, Model};

/// What a bond does for the length of one step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Apart: no force.
    Open,
    /// Touching and pushing with its spring and dashpot.
    Pushing,
    /// Touching, but the dashpot would pull harder than the spring pushes: no force.
    Clipped,
}

/// Each bond's coefficient, the exponent and each bond's overlap at rest, read from the law's
/// defining parts: the paper's, the experiment's (δ_b = (F0 / a_b)^{1/α} under a
/// precompression F0), or the linear law across gaps `linear-gap` (α = 1, δ_b = −g_b).
/// Refuses a chain in gravity and any other law, which the reference does not model.
fn contact_law(law: &LawOf<'_>, sites: usize) -> Result<(Vec<f64>, f64, Vec<f64>), String> {
    match law {
        LawOf::Experiment(law) if law.gravity > 0.0 => Err("a chain in gravity".into()),
        LawOf::Experiment(law) => {
            let rest = law.coefficients.iter().map(|&a| match law.precompression {
                0.0 => 0.0,
                f0 => (f0 / a).powf(1.0 / law.exponent),
            });
            Ok((law.coefficients.to_vec(), law.exponent, rest.collect()))
        }
        LawOf::Paper => Ok((vec![1.0; sites + 1], 1.5, vec![0.0; sites + 1])),
        LawOf::Named { name, numbers } if *name == "linear-gap" => {
            let named = |key: &str| numbers.iter().find(|(k, _)| *k == key).map(|(_, v)| *v);
            match (named("stiffness"), named("gap")) {
                (Some(k), Some(g)) => Ok((k.to_vec(), 1.0, g.iter().map(|&g| -g).collect())),
                _ => Err("a linear-gap law without its stiffness and gap".into()),
            }
        }
        LawOf::Named { name, .. } => Err(format!("the contact law {name}")),
    }
}

/// One contact: the bodies on each side (`None`: a wall), its law and its dashpot.
#[derive(Debug, Clone, Copy)]
struct Bond {
    left: Option<usize>,
    right: Option<usize>,
    coefficient: f64,
    exponent: f64,
    /// The overlap at rest: δ_b = (F0 / a_b)^{1/α} under a precompression F0, −g_b across a
    /// gap g_b.
    rest_overlap: f64,
    gamma: f64,
}

/// A bond's overlap c, its rate ċ, its spring's force and its total unclipped force.
#[derive(Debug, Clone, Copy)]
struct BondState {
    overlap: f64,
    rate: f64,
    spring: f64,
    total: f64,
}

/// A resonator: host, mass, coupling and dashpot.
#[derive(Debug, Clone, Copy)]
struct Inner {
    host: usize,
    coupling: Coupling,
    p: u32,
    damping: f64,
}

/// The chain, its contacts, resonators and losses; see the module documentation.
#[derive(Debug, Clone)]
pub struct Chain {
    sites: usize,
    mass: Vec<f64>,
    bonds: Vec<Bond>,
    law: DashpotLaw,
    inner: Vec<Inner>,
    ground: f64,
    /// The soft ends' spring and dashpot, [left, right].
    soft: [Option<(f64, f64)>; 2],
}

impl Chain {
    /// The chain of `model`. Refuses a chain in gravity, which the reference does not model.
    pub fn of(model: &Model) -> Result<Chain, String> {
        let parts = model.parts();
        let sites = parts.n_sites;
        let (coefficients, exponent, rest) = contact_law(&parts.contacts, sites)?;
        let damping = parts.damping;
        let gamma = |b: usize| damping.map_or(0.0, |d| d.contact_at(b));
        let walls = [
            parts.boundary.left() == End::Fixed,
            parts.boundary.right() == End::Fixed,
        ];
        let bonds = (0..=sites)
            .filter(|&b| (b > 0 || walls[0]) && (b < sites || walls[1]))
            .map(|b| Bond {
                left: b.checked_sub(1),
                right: (b < sites).then_some(b),
                coefficient: coefficients[b],
                exponent,
                rest_overlap: rest[b],
                gamma: gamma(b),
            })
            .collect();
        let mut mass: Vec<f64> = match parts.site_masses {
            Some(m) => m.to_vec(),
            None => vec![1.0; sites],
        };
        mass.extend(parts.resonators.iter().map(|r| r.eps));
        let inner = parts
            .resonators
            .iter()
            .enumerate()
            .map(|(j, r)| Inner {
                host: r.site,
                coupling: r.coupling,
                p: r.p,
                damping: damping.map_or(0.0, |d| d.resonator(j)),
            })
            .collect();
        Ok(Chain {
            sites,
            mass,
            bonds,
            law: damping.map_or(DashpotLaw::Linear, |d| d.law),
            inner,
            ground: damping.map_or(0.0, |d| d.ground),
            soft: [parts.boundary.left().soft(), parts.boundary.right().soft()],
        })
    }

    /// Degrees of freedom: sites, then resonators.
    pub fn dof(&self) -> usize {
        self.mass.len()
    }

    /// The state's length: `[x, v, D]`.
    pub fn state_len(&self) -> usize {
        2 * self.dof() + 1
    }

    /// How many sites the chain has.
    pub fn sites(&self) -> usize {
        self.sites
    }

    /// The bond's overlap, rate and forces in state `y`.
    fn bond_state(&self, bond: &Bond, y: &[f64]) -> BondState {
        let n = self.dof();
        let at = |body: Option<usize>, offset: usize| body.map_or(0.0, |i| y[offset + i]);
        let overlap = bond.rest_overlap + at(bond.left, 0) - at(bond.right, 0);
        let rate = at(bond.left, n) - at(bond.right, n);
        let spring = match overlap > 0.0 {
            true => bond.coefficient * overlap.powf(bond.exponent),
            false => 0.0,
        };
        let dashpot = match self.law {
            DashpotLaw::Linear => bond.gamma * rate,
            DashpotLaw::Hertzian => bond.gamma * overlap.max(0.0).sqrt() * rate,
        };
        BondState {
            overlap,
            rate,
            spring,
            total: spring + dashpot,
        }
    }

    /// Each bond's mode in state `y`, given its mode `before` it: a bond switches only when
    /// its overlap or its total force has crossed zero.
    pub fn modes_at(&self, y: &[f64], before: &[Mode], modes: &mut Vec<Mode>) {
        modes.clear();
        modes.extend(self.bonds.iter().zip(before).map(|(bond, &was)| {
            let s = self.bond_state(bond, y);
            let touching = s.overlap > 0.0 || (s.overlap == 0.0 && s.rate > 0.0);
            match (was, touching) {
                (Mode::Open, false) => Mode::Open,
                (Mode::Pushing | Mode::Clipped, _) if s.overlap < 0.0 => Mode::Open,
                (Mode::Clipped, _) if s.total <= 0.0 => Mode::Clipped,
                (_, _) if bond.gamma > 0.0 && s.total < 0.0 => Mode::Clipped,
                (_, _) => Mode::Pushing,
            }
        }));
    }

    /// Every bond open: the modes a driver starts from before asking [`Chain::modes_at`].
    pub fn all_open(&self) -> Vec<Mode> {
        vec![Mode::Open; self.bonds.len()]
    }

    /// dy/dt at time `t` for the bonds' `modes`: velocities, accelerations and the power
    /// dissipated.
    pub fn derivative(&self, t: f64, y: &[f64], modes: &[Mode], dy: &mut [f64]) {
        let n = self.dof();
        let (x, v) = (&y[..n], &y[n..2 * n]);
        dy[..n].copy_from_slice(v);
        let force = &mut dy[n..2 * n];
        force.fill(0.0);
        let mut power = 0.0;
        for (bond, &mode) in self.bonds.iter().zip(modes) {
            let s = self.bond_state(bond, y);
            let push = match mode {
                Mode::Open => 0.0,
                Mode::Pushing => s.total,
                Mode::Clipped => 0.0,
            };
            if mode != Mode::Open {
                power += (push - s.spring) * s.rate;
            }
            if let Some(l) = bond.left {
                force[l] -= push;
            }
            if let Some(r) = bond.right {
                force[r] += push;
            }
        }
        for (j, r) in self.inner.iter().enumerate() {
            let me = self.sites + j;
            let (stretch, rate) = (x[r.host] - x[me], v[r.host] - v[me]);
            let f = r.coupling.at(t) * stretch.powi(r.p as i32) + r.damping * rate;
            force[r.host] -= f;
            force[me] += f;
            power += r.damping * rate * rate;
        }
        for site in 0..self.sites {
            force[site] -= self.ground * v[site];
            power += self.ground * v[site] * v[site];
        }
        for (soft, site) in self.soft.iter().zip([0, self.sites - 1]) {
            if let Some((spring, damping)) = *soft {
                force[site] -= spring * x[site] + damping * v[site];
                power += damping * v[site] * v[site];
            }
        }
        for (f, m) in force.iter_mut().zip(&self.mass) {
            *f /= m;
        }
        dy[2 * n] = power;
    }

    /// The energy each site holds at time `t` (its resonators', its springs' and half of each
    /// interior contact's potential; a wall's contact wholly), measured from the rest state.
    pub fn density(&self, t: f64, y: &[f64]) -> Vec<f64> {
        let n = self.dof();
        let (x, v) = (&y[..n], &y[n..2 * n]);
        let mut e: Vec<f64> = (0..self.sites)
            .map(|i| 0.5 * self.mass[i] * v[i] * v[i])
            .collect();
        for bond in &self.bonds {
            let s = self.bond_state(bond, y);
            let (a, alpha, delta) = (bond.coefficient, bond.exponent, bond.rest_overlap);
            let rise = |c: f64| a / (alpha + 1.0) * c.max(0.0).powf(alpha + 1.0);
            // A gap (δ < 0) holds nothing at rest.
            let held_at_rest = a * delta.max(0.0).powf(alpha);
            let potential = rise(s.overlap) - rise(delta) - held_at_rest * (s.overlap - delta);
            match (bond.left, bond.right) {
                (Some(l), Some(r)) => {
                    e[l] += 0.5 * potential;
                    e[r] += 0.5 * potential;
                }
                (Some(site), None) | (None, Some(site)) => e[site] += potential,
                (None, None) => {}
            }
        }
        for (j, r) in self.inner.iter().enumerate() {
            let me = self.sites + j;
            let stretch = x[r.host] - x[me];
            let p1 = r.p as i32 + 1;
            e[r.host] += 0.5 * self.mass[me] * v[me] * v[me]
                + r.coupling.at(t) * stretch.powi(p1) / f64::from(p1);
        }
        for (soft, site) in self.soft.iter().zip([0, self.sites - 1]) {
            if let Some((spring, _)) = *soft {
                e[site] += 0.5 * spring * x[site] * x[site];
            }
        }
        e
    }
}
