//! The chain's pencil K − σM with every resonator eliminated into its host, which leaves a
//! symmetric tridiagonal matrix over the sites: a Sturm count (how many eigenvalues lie below σ)
//! and a solve of (K − σM) x = f, both in O(S + R).
//!
//! Resonator r (mass m_r, spring k_r, on site n) couples only to its host, so eliminating it
//! first creates no fill: its pivot is p_r = k_r − σ m_r and the host's diagonal becomes
//!
//! ```text
//! d_n = K_n + K_{n+1} + Σ_r k_r − σ m_n − Σ_r k_r² / p_r  =  K_n + K_{n+1} − σ m_eff,n(√σ)
//! ```
//!
//! By Sylvester's law of inertia the number of negative pivots of this symmetric elimination
//! (the p_r, then the tridiagonal Sturm sequence q_n = d_n − K_n² / q_{n−1}) is the number of
//! eigenvalues ω² < σ (Wilkinson, *The Algebraic Eigenvalue Problem*, §5.36–5.39; LAPACK
//! `dstebz`). A zero pivot is replaced by −pivmin as `dstebz` does. The solve uses Gaussian
//! elimination with partial pivoting on the tridiagonal (LAPACK `dgtsv`), then recovers the
//! resonators.

use crate::chain::LinearChain;

/// The condensed pencil at one shift σ.
pub(crate) struct Condensed<'a> {
    chain: &'a LinearChain,
    sigma: f64,
    /// p_r, with an exact zero nudged off zero.
    pivots: Vec<f64>,
    /// d_n.
    diagonal: Vec<f64>,
}

impl<'a> Condensed<'a> {
    /// K − σM with the resonators eliminated.
    pub(crate) fn new(chain: &'a LinearChain, sigma: f64) -> Condensed<'a> {
        let tiny = pivmin(chain);
        let pivots: Vec<f64> = chain
            .resonators()
            .iter()
            .map(|r| match r.stiffness - sigma * r.mass {
                0.0 => -tiny,
                p => p,
            })
            .collect();
        let diagonal = (0..chain.n_sites())
            .map(|site| {
                let mut d =
                    chain.stiffness(site) + chain.stiffness(site + 1) - sigma * chain.mass(site);
                for &j in chain.resonators_on(site) {
                    let k = chain.resonators()[j].stiffness;
                    d += k - k * k / pivots[j];
                }
                d
            })
            .collect();
        Condensed {
            chain,
            sigma,
            pivots,
            diagonal,
        }
    }

    /// The number of eigenvalues ω² of K v = ω² M v below σ.
    pub(crate) fn count_below(&self) -> usize {
        let tiny = pivmin(self.chain);
        let mut count = self.pivots.iter().filter(|&&p| p < 0.0).count();
        let mut previous = 1.0;
        for (site, &d) in self.diagonal.iter().enumerate() {
            let mut q = d;
            if site > 0 {
                let k = self.chain.stiffness(site);
                q -= k * k / previous;
            }
            if q == 0.0 {
                q = -tiny;
            }
            count += usize::from(q < 0.0);
            previous = q;
        }
        count
    }

    /// x with (K − σM) x = `rhs` over every degree of freedom (sites, then resonators). Where
    /// the pencil is singular (σ an eigenvalue, as inverse iteration asks) a zero pivot is
    /// replaced by a relative epsilon, and the result is a large multiple of the eigenvector.
    pub(crate) fn solve(&self, rhs: &[f64]) -> Vec<f64> {
        let chain = self.chain;
        let n = chain.n_sites();
        let resonators = chain.resonators();
        // Right-hand side of the sites after eliminating the resonators.
        let mut b: Vec<f64> = (0..n)
            .map(|site| {
                let folded = chain
                    .resonators_on(site)
                    .iter()
                    .map(|&j| resonators[j].stiffness * rhs[n + j] / self.pivots[j]);
                rhs[site] + folded.sum::<f64>()
            })
            .collect();
        let off: Vec<f64> = (1..n).map(|bond| -chain.stiffness(bond)).collect();
        let epsilon = f64::EPSILON * scale(chain).max(self.sigma * max_mass(chain));
        solve_tridiagonal(self.diagonal.clone(), off.clone(), off, &mut b, epsilon);
        let attached: Vec<f64> = resonators
            .iter()
            .enumerate()
            .map(|(j, r)| (rhs[n + j] + r.stiffness * b[r.site]) / self.pivots[j])
            .collect();
        b.extend(attached);
        b
    }
}

/// Solves T x = b in place for the tridiagonal T with diagonal `d`, subdiagonal `dl`
/// (`dl[i] = T[i+1][i]`) and superdiagonal `du` (`du[i] = T[i][i+1]`), by Gaussian elimination with
/// partial pivoting as LAPACK `dgtsv`; a zero pivot is replaced by `epsilon`.
fn solve_tridiagonal(
    mut d: Vec<f64>,
    mut dl: Vec<f64>,
    mut du: Vec<f64>,
    b: &mut [f64],
    epsilon: f64,
) {
    let n = d.len();
    for i in 0..n.saturating_sub(1) {
        if d[i].abs() >= dl[i].abs() {
            if d[i] == 0.0 {
                d[i] = epsilon;
            }
            let fact = dl[i] / d[i];
            d[i + 1] -= fact * du[i];
            b[i + 1] -= fact * b[i];
            dl[i] = 0.0;
        } else {
            // Interchange rows i and i + 1; dl[i] becomes the second superdiagonal.
            let fact = d[i] / dl[i];
            d[i] = dl[i];
            let temp = d[i + 1];
            d[i + 1] = du[i] - fact * temp;
            if i + 2 < n {
                dl[i] = du[i + 1];
                du[i + 1] = -fact * dl[i];
            } else {
                dl[i] = 0.0;
            }
            du[i] = temp;
            b.swap(i, i + 1);
            b[i + 1] -= fact * b[i];
        }
    }
    for i in (0..n).rev() {
        if d[i] == 0.0 {
            d[i] = epsilon;
        }
        let mut value = b[i];
        if i + 1 < n {
            value -= du[i] * b[i + 1];
        }
        if i + 2 < n {
            value -= dl[i] * b[i + 2];
        }
        b[i] = value / d[i];
    }
}

/// The largest spring of the chain (bonds and resonators), at least 1e-300.
fn scale(chain: &LinearChain) -> f64 {
    let bonds = (0..=chain.n_sites()).map(|b| chain.stiffness(b));
    let springs = chain.resonators().iter().map(|r| r.stiffness);
    bonds.chain(springs).fold(1e-300, f64::max)
}

fn max_mass(chain: &LinearChain) -> f64 {
    chain.dof_masses().into_iter().fold(0.0, f64::max)
}

/// The smallest pivot magnitude of the Sturm count, as `dstebz`'s: safe minimum × scale².
fn pivmin(chain: &LinearChain) -> f64 {
    f64::MIN_POSITIVE * scale(chain).powi(2).max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chain::{ChainSpec, LinearResonator};
    use crate::matrices;

    #[test]
    fn counts_the_uniform_chain_modes() {
        // ω_k² = 4 (K/m) sin²(kπ / (2(N+1))), k = 1..N.
        let (n, m, k) = (30, 1.0, 1.0);
        let chain = LinearChain::new(ChainSpec::uniform(n, m, k)).unwrap();
        let omega2 = |j: usize| {
            4.0 * (j as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64))
                .sin()
                .powi(2)
        };
        for j in 0..=n {
            let sigma = match j {
                0 => 0.5 * omega2(1),
                j if j == n => omega2(n) + 1.0,
                j => 0.5 * (omega2(j) + omega2(j + 1)),
            };
            assert_eq!(Condensed::new(&chain, sigma).count_below(), j);
        }
    }

    #[test]
    fn solves_against_the_dense_matrix() {
        let mut spec = ChainSpec::uniform(7, 1.0, 1.0);
        spec.masses[2] = 0.4;
        spec.bond_stiffness[0] = 0.0;
        spec.resonators = vec![
            LinearResonator {
                site: 3,
                mass: 0.5,
                stiffness: 0.7,
                damping: 0.0,
            },
            LinearResonator {
                site: 3,
                mass: 0.2,
                stiffness: 1.9,
                damping: 0.0,
            },
            LinearResonator {
                site: 6,
                mass: 1.5,
                stiffness: 0.3,
                damping: 0.0,
            },
        ];
        let chain = LinearChain::new(spec).unwrap();
        let k = matrices::stiffness(&chain);
        let masses = chain.dof_masses();
        let rhs: Vec<f64> = (0..chain.n_dof())
            .map(|i| (i as f64 * 0.77).sin() + 0.3)
            .collect();
        // Shifts below, between and above the resonators' own frequencies.
        for sigma in [0.1, 0.9, 1.7, 5.0] {
            let x = Condensed::new(&chain, sigma).solve(&rhs);
            for i in 0..chain.n_dof() {
                let row: f64 = (0..chain.n_dof()).map(|j| k[(i, j)] * x[j]).sum::<f64>()
                    - sigma * masses[i] * x[i];
                assert!(
                    (row - rhs[i]).abs() < 1e-11,
                    "σ {sigma}, row {i}: {row} vs {}",
                    rhs[i]
                );
            }
        }
    }
}
