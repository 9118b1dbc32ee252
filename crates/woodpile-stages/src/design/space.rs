//! The space a design searches: how many resonators, on which sites, with which eps, kappa
//! and p; and the decoding of a genome in [0, 1]^d into one layout of it.

/// A real parameter's range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// Searched on a log scale.
    pub log: bool,
}

impl Range {
    pub(super) fn at(&self, u: f64) -> f64 {
        // The ends exactly: exp(ln 0.1) is not 0.1.
        if u.is_nan() || u <= 0.0 {
            return self.min;
        }
        if u >= 1.0 {
            return self.max;
        }
        let x = if self.log {
            (self.min.ln() + u * (self.max.ln() - self.min.ln())).exp()
        } else {
            self.min + u * (self.max - self.min)
        };
        x.clamp(self.min, self.max)
    }
}

/// A parameter's values: a range, or a list to choose from (rods come in a few lengths).
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Any value of the range.
    Range(Range),
    /// One of these.
    List(Vec<f64>),
}

impl Values {
    pub(super) fn at(&self, u: f64) -> f64 {
        match self {
            Values::Range(r) => r.at(u),
            Values::List(values) => values[pick(u, values.len())],
        }
    }
}

/// Where resonators may go.
#[derive(Debug, Clone, PartialEq)]
pub enum Sites {
    /// Any paper site first..=last (`sites = [first, last]`).
    Range(i64, i64),
    /// Any of these sites (`sites = { among = [...] }`, or a list of three or more).
    Among(Vec<i64>),
    /// One resonator on each of these sites (`sites = { fixed = [...] }`): only the
    /// parameters are searched.
    Fixed(Vec<i64>),
}

impl Sites {
    /// How many sites there are to choose from.
    pub(super) fn count(&self) -> usize {
        match self {
            Sites::Range(a, b) => (b - a + 1).max(0) as usize,
            Sites::Among(list) | Sites::Fixed(list) => list.len(),
        }
    }
}

/// The index `u` in [0, 1] picks among `n` choices.
fn pick(u: f64, n: usize) -> usize {
    ((u.clamp(0.0, 1.0) * n as f64) as usize).min(n.saturating_sub(1))
}

/// What may vary.
#[derive(Debug, Clone, PartialEq)]
pub struct Space {
    /// Fewest and most resonators.
    pub resonators: (usize, usize),
    /// Where they may go.
    pub sites: Sites,
    /// Mass ratio.
    pub eps: Values,
    /// Coupling.
    pub kappa: Values,
    /// Allowed exponents.
    pub p: Vec<i64>,
    /// Bound on the sum of eps.
    pub max_total_eps: Option<f64>,
    /// In a `[physical]` scene, the defect rods' lengths (m) instead of eps, kappa and p: each
    /// placed resonator is a rod of that length, its masses and spring derived from its
    /// bending mode (`defect.rod`).
    pub length: Option<Values>,
}

/// One resonator of a design.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resonator {
    /// Its paper site.
    pub site: i64,
    /// Mass ratio.
    pub eps: f64,
    /// Coupling.
    pub kappa: f64,
    /// Coupling exponent.
    pub p: i64,
    /// A defect rod's length (m), when the space searches rods: eps and kappa are then the
    /// values its rod derives ([`Design::with_derived`](super::Design)).
    pub length: Option<f64>,
}

/// One decoded design: resonators sorted by site.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The resonators, by increasing site.
    pub resonators: Vec<Resonator>,
}

impl Layout {
    /// The added mass, the sum of eps.
    pub fn total_eps(&self) -> f64 {
        self.resonators.iter().map(|r| r.eps).sum()
    }

    /// One field of every resonator, as a comma-separated list.
    pub fn list<T: std::fmt::Display>(&self, pick: impl Fn(&Resonator) -> T) -> String {
        self.resonators
            .iter()
            .map(|r| pick(r).to_string())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Genes per resonator slot: site, eps, kappa, p.
pub(super) const GENES: usize = 4;

impl Space {
    /// The genome's length: the count, then four genes per slot.
    pub(super) fn dimension(&self) -> usize {
        1 + GENES * self.resonators.1
    }

    /// The layout a genome in [0, 1]^d stands for, always inside the space: a resonator whose
    /// site is taken goes to the next free one (in the order of the sites, wrapping), so a
    /// design has exactly the count its genome says, and equal genomes give equal layouts.
    pub(super) fn decode(&self, genome: &[f64]) -> Layout {
        let (lo, hi) = self.resonators;
        let choices = self.site_list();
        let count = (lo + pick(genome[0], hi - lo + 1)).min(choices.len());
        let mut taken = vec![false; choices.len()];
        let mut resonators: Vec<Resonator> = Vec::with_capacity(count);
        for slot in 0..count {
            let g = &genome[1 + GENES * slot..1 + GENES * (slot + 1)];
            let wanted = match &self.sites {
                Sites::Fixed(_) => slot,
                _ => pick(g[0], choices.len()),
            };
            let Some(index) = (0..choices.len())
                .map(|k| (wanted + k) % choices.len())
                .find(|&i| !taken[i])
            else {
                break;
            };
            taken[index] = true;
            resonators.push(match &self.length {
                // A rod: its length in the eps gene; eps and kappa follow from the rod.
                Some(length) => Resonator {
                    site: choices[index],
                    eps: 0.0,
                    kappa: 0.0,
                    p: 1,
                    length: Some(round_sig(length.at(g[1]))),
                },
                None => Resonator {
                    site: choices[index],
                    eps: round_sig(self.eps.at(g[1])),
                    kappa: round_sig(self.kappa.at(g[2])),
                    p: self.p[pick(g[3], self.p.len())],
                    length: None,
                },
            });
        }
        resonators.sort_by_key(|r| r.site);
        Layout { resonators }
    }

    /// The sites resonators may take, in order, each once.
    fn site_list(&self) -> Vec<i64> {
        let mut list = match &self.sites {
            Sites::Range(first, last) => (*first..=*last).collect(),
            Sites::Among(list) | Sites::Fixed(list) => list.clone(),
        };
        if !matches!(self.sites, Sites::Fixed(_)) {
            list.sort_unstable();
            list.dedup();
        }
        list
    }

    /// Whether `layout` lies in the space: its count, distinct sites among those allowed, eps,
    /// kappa and p from their values (to the 10 digits a design keeps), and its total eps
    /// within the bound.
    pub fn contains(&self, layout: &Layout) -> bool {
        let n = layout.resonators.len();
        let sites = self.site_list();
        let mut seen: Vec<i64> = layout.resonators.iter().map(|r| r.site).collect();
        seen.sort_unstable();
        seen.dedup();
        let within = |values: &Values, x: f64| match values {
            Values::Range(r) => x >= round_sig(r.min) && x <= round_sig(r.max),
            Values::List(list) => list.iter().any(|&v| round_sig(v) == x),
        };
        (self.resonators.0..=self.resonators.1).contains(&n)
            && seen.len() == n
            && layout.resonators.iter().all(|r| {
                let parameters = match (&self.length, r.length) {
                    (Some(lengths), Some(length)) => within(lengths, length),
                    (None, None) => {
                        within(&self.eps, r.eps)
                            && within(&self.kappa, r.kappa)
                            && self.p.contains(&r.p)
                    }
                    _ => false,
                };
                sites.contains(&r.site) && parameters
            })
            && self
                .max_total_eps
                .is_none_or(|bound| layout.total_eps() <= bound)
    }
}

/// 10 significant digits: a design file states its numbers exactly as they were simulated,
/// and nearby genomes share cached points.
pub(super) fn round_sig(x: f64) -> f64 {
    woodpile_scene::grid::round_sig(x, 10)
}

#[cfg(test)]
mod tests {
    use super::*;
    use woodpile_analysis::search::SplitMix64;

    fn space() -> Space {
        Space {
            resonators: (1, 3),
            sites: Sites::Range(0, 4),
            eps: Values::Range(Range {
                min: 0.1,
                max: 100.0,
                log: true,
            }),
            kappa: Values::Range(Range {
                min: 1.0,
                max: 2.0,
                log: false,
            }),
            p: vec![1, 3],
            max_total_eps: None,
            length: None,
        }
    }

    #[test]
    fn genomes_decode_to_sorted_distinct_sites_within_the_space() {
        let s = space();
        let mut rng = SplitMix64(7);
        for _ in 0..500 {
            let g: Vec<f64> = (0..s.dimension()).map(|_| rng.uniform()).collect();
            let layout = s.decode(&g);
            let sites: Vec<i64> = layout.resonators.iter().map(|r| r.site).collect();
            assert!(!sites.is_empty() && sites.len() <= 3);
            assert!(sites.windows(2).all(|w| w[0] < w[1]), "{sites:?}");
            for &Resonator {
                site,
                eps,
                kappa,
                p,
                length: _,
            } in &layout.resonators
            {
                assert!((0..=4).contains(&site));
                assert!((0.1..=100.0).contains(&eps) && (1.0..=2.0).contains(&kappa));
                assert!(p == 1 || p == 3);
            }
        }
        assert_eq!((s.eps.at(0.0), s.eps.at(1.0)), (0.1, 100.0));
        assert!((s.eps.at(0.5) - 10f64.powf(0.5)).abs() < 1e-12);
    }

    /// A random space, drawn with `rng`: counts, sites of every form, ranges and lists.
    fn random_space(rng: &mut SplitMix64) -> Space {
        let mut int = |lo: i64, hi: i64| lo + (rng.uniform() * (hi - lo + 1) as f64) as i64;
        let sites = match int(0, 2) {
            0 => {
                let first = int(-10, 10);
                Sites::Range(first, first + int(0, 8))
            }
            1 => Sites::Among((0..int(3, 6)).map(|_| int(-20, 20)).collect()),
            _ => Sites::Fixed(vec![-4, 0, 3, 9][..int(1, 4) as usize].to_vec()),
        };
        let distinct = {
            let mut list = match &sites {
                Sites::Range(a, b) => (*a..=*b).collect(),
                Sites::Among(l) | Sites::Fixed(l) => l.clone(),
            };
            list.sort_unstable();
            list.dedup();
            list.len()
        };
        let resonators = match &sites {
            Sites::Fixed(list) => (list.len(), list.len()),
            _ => {
                let lo = int(0, distinct.min(3) as i64) as usize;
                (lo, (lo + int(0, 4) as usize).max(1))
            }
        };
        let eps = match int(0, 1) {
            0 => Values::List(vec![0.5, 2.0, 8.0]),
            _ => Values::Range(Range {
                min: 0.1,
                max: 100.0,
                log: true,
            }),
        };
        Space {
            resonators,
            sites,
            eps,
            max_total_eps: (int(0, 1) == 0).then_some(50.0),
            ..space()
        }
    }

    /// Every genome of every space decodes inside the space, with the count it asks for: a
    /// resonator on a taken site moves to a free one instead of being dropped (with three
    /// resonators on three sites, designs of one or two were evaluated).
    #[test]
    fn every_genome_of_every_space_decodes_inside_it() {
        let mut rng = SplitMix64(2026);
        for _ in 0..300 {
            let space = random_space(&mut rng);
            for _ in 0..50 {
                let g: Vec<f64> = (0..space.dimension()).map(|_| rng.uniform()).collect();
                let layout = space.decode(&g);
                let asked =
                    space.resonators.0 + pick(g[0], space.resonators.1 - space.resonators.0 + 1);
                let within_bound = space.max_total_eps.is_none_or(|b| layout.total_eps() <= b);
                let unbounded = Space {
                    max_total_eps: None,
                    ..space.clone()
                };
                assert!(unbounded.contains(&layout), "{space:?}\n{layout:?}");
                assert_eq!(space.contains(&layout), within_bound);
                assert_eq!(
                    layout.resonators.len(),
                    asked.min(unbounded.site_list().len()),
                    "{space:?}"
                );
            }
        }
        let three = Space {
            resonators: (3, 3),
            sites: Sites::Among(vec![0, 5, 10]),
            ..space()
        };
        for u in [0.0, 0.3, 0.99] {
            let layout = three.decode(&vec![u; three.dimension()]);
            assert_eq!(layout.list(|r| r.site), "0, 5, 10");
        }
    }

    /// Fixed sites get one resonator each, whatever the genome; listed sites and listed eps
    /// values are the only ones chosen.
    #[test]
    fn fixed_and_listed_sites_and_listed_eps_are_respected() {
        let mut rng = SplitMix64(11);
        let fixed = Space {
            resonators: (3, 3),
            sites: Sites::Fixed(vec![0, 10, 20]),
            eps: Values::List(vec![0.5, 2.0, 8.0]),
            ..space()
        };
        let among = Space {
            resonators: (1, 2),
            sites: Sites::Among(vec![-3, 7, 9]),
            ..space()
        };
        for _ in 0..300 {
            let g: Vec<f64> = (0..fixed.dimension()).map(|_| rng.uniform()).collect();
            let layout = fixed.decode(&g);
            let sites: Vec<i64> = layout.resonators.iter().map(|r| r.site).collect();
            assert_eq!(sites, [0, 10, 20]);
            assert!(layout
                .resonators
                .iter()
                .all(|r| [0.5, 2.0, 8.0].contains(&r.eps)));
            let g: Vec<f64> = (0..among.dimension()).map(|_| rng.uniform()).collect();
            assert!(among
                .decode(&g)
                .resonators
                .iter()
                .all(|r| [-3, 7, 9].contains(&r.site)));
        }
    }
}
