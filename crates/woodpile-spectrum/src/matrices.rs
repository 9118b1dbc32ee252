//! The dense stiffness and damping matrices of a chain, for the dense eigenproblems of
//! [`crate::modes`] and [`crate::damped`]. Both are stamped by one loop over bonds, ground
//! dashpots and resonators, so the two cannot disagree on the layout (sites, then resonators).

use faer::Mat;

use crate::chain::{LinearChain, LinearResonator};

/// K: bonds, end bonds to the supports, resonator springs.
pub(crate) fn stiffness(chain: &LinearChain) -> Mat<f64> {
    stamp(chain, |b| chain.stiffness(b), |_| 0.0, |r| r.stiffness)
}

/// C: bond dashpots, ground dashpots, resonator dashpots.
pub(crate) fn damping(chain: &LinearChain) -> Mat<f64> {
    stamp(
        chain,
        |b| chain.bond_damping(b),
        |site| chain.ground_damping(site),
        |r| r.damping,
    )
}

/// The symmetric matrix of springs (or dashpots) `bond(b)` on bonds 0..=S, `ground(n)` from each
/// site to the ground, and `resonator(r)` between each resonator and its host.
fn stamp(
    chain: &LinearChain,
    bond: impl Fn(usize) -> f64,
    ground: impl Fn(usize) -> f64,
    resonator: impl Fn(&LinearResonator) -> f64,
) -> Mat<f64> {
    let n = chain.n_sites();
    let mut a = Mat::<f64>::zeros(chain.n_dof(), chain.n_dof());
    for b in 0..=n {
        let k = bond(b);
        let left = b.checked_sub(1);
        let right = (b < n).then_some(b);
        for site in [left, right].into_iter().flatten() {
            a[(site, site)] += k;
        }
        if let (Some(l), Some(r)) = (left, right) {
            a[(l, r)] -= k;
            a[(r, l)] -= k;
        }
    }
    for site in 0..n {
        a[(site, site)] += ground(site);
    }
    for (j, r) in chain.resonators().iter().enumerate() {
        let (host, dof, k) = (r.site, n + j, resonator(r));
        a[(host, host)] += k;
        a[(dof, dof)] += k;
        a[(host, dof)] -= k;
        a[(dof, host)] -= k;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chain::ChainSpec;

    #[test]
    fn stamps_bonds_ends_and_resonators() {
        let mut spec = ChainSpec::uniform(3, 1.0, 2.0);
        spec.bond_stiffness[3] = 0.0;
        spec.ground_damping = vec![0.0, 0.5, 0.0];
        spec.resonators.push(LinearResonator {
            site: 1,
            mass: 1.0,
            stiffness: 0.25,
            damping: 0.125,
        });
        let chain = LinearChain::new(spec).unwrap();
        let k = stiffness(&chain);
        let expected = [
            [4.0, -2.0, 0.0, 0.0],
            [-2.0, 4.25, -2.0, -0.25],
            [0.0, -2.0, 2.0, 0.0],
            [0.0, -0.25, 0.0, 0.25],
        ];
        for (i, row) in expected.iter().enumerate() {
            for (j, &value) in row.iter().enumerate() {
                assert_eq!(k[(i, j)], value, "K[{i}][{j}]");
            }
        }
        let c = damping(&chain);
        assert_eq!(c[(1, 1)], 0.625);
        assert_eq!(c[(3, 1)], -0.125);
        assert_eq!(c[(0, 0)], 0.0);
    }
}
