//! Global searches over the unit cube [0, 1]^d, for objectives that are expensive, noisy and
//! evaluated in batches (a generation of scenes simulated in parallel): differential evolution
//! and its baseline, random search of the same budget, both driven by a seeded
//! [`SplitMix64`] so a search is the same numbers on every machine.
//!
//! The caller owns evaluation: [`DifferentialEvolution`] proposes a generation
//! ([`DifferentialEvolution::trials`]), the caller scores it however it likes (a failed
//! evaluation scores `-inf`), and hands the scores back ([`DifferentialEvolution::select`]).

/// splitmix64 (Steele, Lea and Flood 2014): a small, fast, seeded generator whose streams for
/// nearby seeds are independent enough for a search.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1), on the 2^-53 grid.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in 0..n (0 when n is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.uniform() * n as f64) as usize % n.max(1)
    }

    /// A point of [0, 1)^dimension.
    pub fn point(&mut self, dimension: usize) -> Vec<f64> {
        (0..dimension).map(|_| self.uniform()).collect()
    }
}

/// `count` points drawn uniformly from [0, 1)^dimension: random search, the baseline any
/// optimiser must beat at the same budget.
pub fn random_points(dimension: usize, count: usize, rng: &mut SplitMix64) -> Vec<Vec<f64>> {
    (0..count).map(|_| rng.point(dimension)).collect()
}

/// Differential evolution, DE/rand/1/bin (Storn and Price 1997), maximising, in [0, 1]^d: a
/// trial takes each coordinate (and one forced coordinate) from a + F (b - c) with probability
/// CR, else from its parent, reflected into the cube; it replaces its parent when it scores at
/// least as well.
#[derive(Debug, Clone)]
pub struct DifferentialEvolution {
    rng: SplitMix64,
    dimension: usize,
    population: Vec<Vec<f64>>,
    scores: Vec<f64>,
}

impl DifferentialEvolution {
    /// Members of the population.
    pub const POPULATION: usize = 20;
    /// The differential weight F.
    pub const STEP: f64 = 0.6;
    /// The crossover rate CR.
    pub const CROSSOVER: f64 = 0.9;

    /// A search in `dimension` dimensions whose first generation is drawn from `rng`: score
    /// [`DifferentialEvolution::population`] and pass the scores to
    /// [`DifferentialEvolution::start`].
    pub fn new(dimension: usize, mut rng: SplitMix64) -> Self {
        let population = random_points(dimension, Self::POPULATION, &mut rng);
        Self {
            rng,
            dimension,
            population,
            scores: Vec::new(),
        }
    }

    /// The current population.
    pub fn population(&self) -> &[Vec<f64>] {
        &self.population
    }

    /// The first generation's scores, in population order.
    pub fn start(&mut self, scores: Vec<f64>) {
        assert_eq!(scores.len(), self.population.len(), "one score per member");
        self.scores = scores;
    }

    /// Trials for the first `n` members (n at most the population): the next generation to
    /// score.
    pub fn trials(&mut self, n: usize) -> Vec<Vec<f64>> {
        let d = self.dimension;
        let size = self.population.len();
        (0..n.min(size))
            .map(|i| {
                let rng = &mut self.rng;
                let mut pick = |not: &[usize]| loop {
                    let k = rng.below(size);
                    if !not.contains(&k) {
                        return k;
                    }
                };
                let a = pick(&[i]);
                let b = pick(&[i, a]);
                let c = pick(&[i, a, b]);
                let forced = self.rng.below(d);
                let p = &self.population;
                (0..d)
                    .map(|j| {
                        if j == forced || self.rng.uniform() < Self::CROSSOVER {
                            reflect(p[a][j] + Self::STEP * (p[b][j] - p[c][j]))
                        } else {
                            p[i][j]
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// Each trial (of member i, in order) replaces its parent when its score is at least the
    /// parent's.
    pub fn select(&mut self, trials: Vec<Vec<f64>>, scores: &[f64]) {
        for (i, (trial, &score)) in trials.into_iter().zip(scores).enumerate() {
            if score >= self.scores[i] {
                self.population[i] = trial;
                self.scores[i] = score;
            }
        }
    }

    /// The best member and its score (the last of equals, as `Iterator::max_by` gives);
    /// `None` before [`DifferentialEvolution::start`].
    pub fn best(&self) -> Option<(&[f64], f64)> {
        (0..self.scores.len())
            .max_by(|&a, &b| self.scores[a].total_cmp(&self.scores[b]))
            .map(|i| (self.population[i].as_slice(), self.scores[i]))
    }
}

/// Into [0, 1] by reflection at the faces, rather than piling up on them.
fn reflect(v: f64) -> f64 {
    let v = if v < 0.0 {
        -v
    } else if v > 1.0 {
        2.0 - v
    } else {
        v
    };
    v.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix_is_seeded_and_uniform() {
        let (mut a, mut b) = (SplitMix64(7), SplitMix64(7));
        assert_eq!(a.next_u64(), b.next_u64());
        let mut rng = SplitMix64(1);
        let n = 20_000;
        let xs: Vec<f64> = (0..n).map(|_| rng.uniform()).collect();
        assert!(xs.iter().all(|&x| (0.0..1.0).contains(&x)));
        let mean = xs.iter().sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 0.01, "mean {mean}");
        let mut counts = [0usize; 10];
        (0..n).for_each(|_| counts[rng.below(10)] += 1);
        assert!(
            counts.iter().all(|&c| (1_800..2_200).contains(&c)),
            "{counts:?}"
        );
    }

    /// -(distance to `centre`)^2: the one maximum is 0 at the centre.
    fn bowl(centre: &[f64]) -> impl Fn(&[f64]) -> f64 + '_ {
        move |x| {
            -x.iter()
                .zip(centre)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
        }
    }

    fn run_de(f: &dyn Fn(&[f64]) -> f64, d: usize, generations: usize, seed: u64) -> f64 {
        let mut de = DifferentialEvolution::new(d, SplitMix64(seed));
        let scores = de.population().iter().map(|x| f(x)).collect();
        de.start(scores);
        for _ in 0..generations {
            let trials = de.trials(DifferentialEvolution::POPULATION);
            let scores: Vec<f64> = trials.iter().map(|x| f(x)).collect();
            de.select(trials, &scores);
        }
        de.best().map(|(_, s)| s).unwrap_or(f64::NEG_INFINITY)
    }

    #[test]
    fn differential_evolution_finds_the_bottom_of_a_bowl() {
        let centre = [0.3, 0.7, 0.55, 0.1];
        let best = run_de(&bowl(&centre), centre.len(), 100, 3);
        assert!(best > -1e-6, "best {best}");
    }

    #[test]
    fn differential_evolution_beats_random_search_on_rastrigin() {
        // Rastrigin in [0, 1]^3 mapped to [-2, 2]^3: many local maxima, one global at 0.
        let f = |x: &[f64]| {
            -x.iter()
                .map(|&u| {
                    let z = 4.0 * u - 2.0;
                    z * z - 10.0 * (2.0 * std::f64::consts::PI * z).cos() + 10.0
                })
                .sum::<f64>()
        };
        let generations = 150;
        let de = run_de(&f, 3, generations, 11);
        let budget = DifferentialEvolution::POPULATION * (generations + 1);
        let random = random_points(3, budget, &mut SplitMix64(11))
            .iter()
            .map(|x| f(x))
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(de > random, "DE {de} against random {random}");
        assert!(de > -0.01, "DE {de} (random {random})");
    }

    #[test]
    fn trials_stay_in_the_cube_and_failures_never_win() {
        let mut de = DifferentialEvolution::new(3, SplitMix64(5));
        let n = DifferentialEvolution::POPULATION;
        de.start(vec![0.0; n]);
        let trials = de.trials(n);
        assert!(trials.iter().flatten().all(|&v| (0.0..=1.0).contains(&v)));
        let before = de.population().to_vec();
        de.select(trials, &vec![f64::NEG_INFINITY; n]);
        assert_eq!(de.population(), &before[..]);
    }
}
