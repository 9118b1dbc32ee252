//! `kind = "design"`: inverse design. Search a space of resonator layouts — how many
//! resonators, on which sites, with which eps, kappa and p — for the scene that maximises (or
//! minimises) a fraction at the read-out time `run.t_end`, around a scene template that fixes
//! the chain, the impulse, the run and the fractions' region.
//!
//! ```toml
//! kind = "design"
//! seed = 2026                         # the search is a function of the seed, for any thread count
//! budget = 1500                       # evaluations for the optimiser, and again for random search
//! refine = 150                        # Nelder–Mead evaluations polishing the best candidate
//! objective = "E_tr"                  # E_tr, R or T
//! goal = "max"                        # or "min"
//! verify_tolerance = 1e-8             # the best design is simulated again at this tolerance
//! robustness = { samples = 200, spreads = [0.01, 0.05] }   # optional: every eps and kappa off by ±spread
//! each_resonator = { quality_factor = 300.0 }   # optional: defect keys every placed resonator gets
//! [scene]                             # a scene file without defects; its fractions region is required
//! chain = { n = 100, boundary = "fixed" }
//! impulse = { site = -25, velocity = 1.0 }
//! run = { t_end = 150.0, method = "auto", tolerance = 1e-6 }
//! fractions = { region = [-1, 21] }
//! [space]
//! resonators = [1, 4]                 # how many, inclusive
//! sites = [0, 20]                     # paper sites they may occupy (one resonator per site)
//! # sites = [0, 10, 20]               # or: only these sites (also { among = [0, 10] })
//! # sites = { fixed = [0, 10, 20] }   # or: one resonator on each of these (then `resonators` may go)
//! eps = { min = 0.1, max = 100.0, log = true }   # or a list of the values allowed: [0.5, 1.0, 2.0]
//! kappa = { min = 0.1, max = 10.0, log = true }
//! p = [1]                             # allowed coupling exponents
//! max_total_eps = 200.0               # optional: a bound on the added mass, sum of eps
//! ```
//!
//! In a `[physical]` scene the design cuts defect rods instead: `[space] length = { min =
//! "20 mm", max = "80 mm" }` (or a list of the lengths at hand, `["20 mm", "40 mm"]`; bare
//! numbers are metres) in place of `eps`, `kappa` and `p`. Each placed resonator is then a
//! `defect.rod` of that length, of the regular rods' diameter and material, whose host and
//! resonator masses and spring follow from its bending mode (`each_resonator` may add a
//! `quality_factor`); the table adds each design's `length` (m) and lists the eps and kappa
//! the rods derive, and the summary's `bill_of_rods` gives the best design's rods as a lab
//! cuts them: site, length, masses, spring and bending frequency.
//!
//! The optimiser is differential evolution (DE/rand/1/bin, population 20, F = 0.6, CR = 0.9)
//! on a genome in [0, 1]^(1 + 4 K) (the count, then site, eps, kappa, p for K slots), decoded
//! to a scene with its defects sorted by site, so equal designs share one cached point. Random
//! search of the same budget is the baseline it must beat. The best candidate of each search
//! is refined by Nelder–Mead, the robustness study samples around the best of the searches, and
//! the best design any evaluation found (a robustness sample included) is verified and written:
//! when the baseline's beats the optimiser's, the summary says so (`best_search`,
//! `baseline_beat_optimiser`). Every evaluation is a scene through
//! the point cache: an interrupted or extended search repeats no simulation. A generation's
//! scenes are simulated in parallel and used in a fixed order, so the result depends on the
//! seed alone.
//!
//! Output: one row per evaluation (`search`: differential evolution, random, refinement,
//! verification, robustness ±s), with the design (`resonators`, and `sites`, `eps`, `kappa`
//! and `p` as list columns, `total_eps`), the fractions, the error estimate, `best_so_far` within its search,
//! `quantile` (a robustness sample's rank among its spread's samples) and `failure`; and `results/<stage>.best.toml`, the best design as a scene file that
//! `woodpile simulate` runs as it is.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde_json::json;
use woodpile_analysis::search::{random_points, DifferentialEvolution, SplitMix64};

use woodpile_files::layout::best_path;
use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::kind::{Context, Kind, PointsAt};
use woodpile_pipeline::Output;
use woodpile_points::PointResult;

use crate::schema::Fraction;

mod evaluate;
mod keys;
mod search;
mod space;
mod trials;

pub use space::{Layout, Range, Resonator, Sites, Space, Values};

pub use search::Search;

use space::{round_sig, GENES};

/// Differential evolution's population: a design's budget is at least one generation.
const POPULATION: usize = DifferentialEvolution::POPULATION;

/// A parsed design stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// Seed of every random choice.
    pub seed: u64,
    /// Evaluations for each of the optimiser and the random baseline.
    pub budget: usize,
    /// Nelder–Mead evaluations on the best candidate.
    pub refine: usize,
    /// Which fraction.
    pub objective: Fraction,
    /// Maximise (true) or minimise.
    pub maximise: bool,
    /// Tolerance of the best design's verification run.
    pub verify_tolerance: f64,
    /// Perturbation study of the best design: samples per spread, and the spreads.
    pub robustness: Option<(usize, Vec<f64>)>,
    /// The search space.
    pub space: Space,
    template: toml::Table,
    /// Defect keys laid on every resonator the design places (a `damping` or
    /// `quality_factor`: designing under the losses a real rod has).
    each_resonator: toml::Table,
    file: PathBuf,
}

/// One evaluated design.
#[derive(Debug, Clone)]
struct Evaluated {
    search: Search,
    layout: Layout,
    result: PointResult,
    score: f64,
    key: String,
    /// Whether it was simulated now (not read from the point cache).
    simulated: bool,
}

/// Where a refinement starts: the search it refines, its genome and its score.
type Start = (Search, Vec<f64>, f64);

impl Design {
    /// The stage: the searches, their refinement, the robustness study around the best design,
    /// then the best design inside the space verified and written as a scene file.
    pub(crate) fn compute(&self, ctx: &Context<'_>) -> Result<Output> {
        let (stage, points, events) = (ctx.name(), ctx.points, ctx.events);
        let robust: usize = self
            .robustness
            .as_ref()
            .map_or(0, |(samples, spreads)| samples * spreads.len());
        let total = 2 * self.budget + self.refine + 1 + robust;
        events.simulating(stage, total, 0);
        let at = PointsAt {
            stage,
            points,
            events,
        };
        let (mut rows, starts) = self.search(at)?;
        // Each refinement is a sequence of single evaluations; the two (from the evolution's
        // best and from the random search's) are independent, so they run side by side.
        let refined: Vec<Result<Vec<Evaluated>>> = starts
            .par_iter()
            .map(|(label, start, score)| self.refine_from(at, *label, start, *score))
            .collect();
        for refinement in refined {
            rows.extend(refinement?);
        }
        // The best design of the searches; the robustness study is around it.
        let best = rows
            .iter()
            .max_by(|a, b| a.score.total_cmp(&b.score))
            .cloned()
            .ok_or_else(|| PipelineError::stage(stage, "no design was evaluated"))?;
        if !best.score.is_finite() {
            return Err(PipelineError::stage(stage, "every design failed"));
        }
        rows.extend(self.robustness_around(at, &best)?);
        let (best, verified, best_file) = self.verify_and_write(ctx, at, &mut rows, best)?;
        // Distinct points: the two refinements, side by side, may both simulate a point that
        // run one after the other they would have simulated once.
        let simulated = rows
            .iter()
            .filter(|r| r.simulated)
            .map(|r| r.key.as_str())
            .collect::<std::collections::HashSet<_>>()
            .len();
        Ok(Output::table(
            self.frame(&rows)?,
            self.summary(&rows, &best, &verified, &best_file),
        )
        .with_simulated(simulated))
    }

    /// Differential evolution a generation at a time, then random search of the same budget
    /// (the baseline): their rows, and where each search's refinement starts (the best genome
    /// of each, with its score).
    fn search(&self, at: PointsAt<'_>) -> Result<(Vec<Evaluated>, Vec<Start>)> {
        let d = self.space.dimension();
        let mut rows = Vec::new();
        let mut de = DifferentialEvolution::new(d, SplitMix64(self.seed ^ 0xde));
        let layouts = de
            .population()
            .iter()
            .map(|g| self.space.decode(g))
            .collect();
        let first = self.evaluate(Search::DifferentialEvolution, layouts, None, at)?;
        de.start(first.iter().map(|e| e.score).collect());
        rows.extend(first);
        let mut spent = POPULATION;
        while spent < self.budget {
            let trials = de.trials(POPULATION.min(self.budget - spent));
            let layouts = trials.iter().map(|g| self.space.decode(g)).collect();
            let evaluated = self.evaluate(Search::DifferentialEvolution, layouts, None, at)?;
            let scores: Vec<f64> = evaluated.iter().map(|e| e.score).collect();
            spent += trials.len();
            de.select(trials, &scores);
            rows.extend(evaluated);
        }

        let random_genomes = random_points(d, self.budget, &mut SplitMix64(self.seed ^ 0x5eed));
        let layouts = random_genomes
            .iter()
            .map(|g| self.space.decode(g))
            .collect();
        let random_rows = self.evaluate(Search::Random, layouts, None, at)?;
        let random_best = (0..random_rows.len())
            .max_by(|&a, &b| random_rows[a].score.total_cmp(&random_rows[b].score));
        rows.extend(random_rows.iter().cloned());

        // Refinement: Nelder–Mead on the eps and kappa genes of each search's best candidate,
        // its count and sites fixed.
        let mut starts = Vec::new();
        if let Some((genome, score)) = de.best() {
            starts.push((Search::Refinement, genome.to_vec(), score));
        }
        if let Some(i) = random_best {
            starts.push((
                Search::RefinementOfRandom,
                random_genomes[i].clone(),
                random_rows[i].score,
            ));
        }
        Ok((rows, starts))
    }

    /// The robustness study: `best` with every eps and kappa off by up to ±spread, `samples`
    /// times per spread, each spread's rows in order of the objective (the table then reads
    /// as the distribution's quantiles).
    fn robustness_around(&self, at: PointsAt<'_>, best: &Evaluated) -> Result<Vec<Evaluated>> {
        let mut rows = Vec::new();
        let Some((samples, spreads)) = &self.robustness else {
            return Ok(rows);
        };
        for (k, &spread) in spreads.iter().enumerate() {
            let mut rng = SplitMix64(self.seed ^ (0x7000 + k as u64));
            let layouts = (0..*samples)
                .map(|_| Layout {
                    resonators: best
                        .layout
                        .resonators
                        .iter()
                        .map(|r| {
                            let mut wobble = |x: f64| {
                                round_sig(x * (1.0 + spread * (2.0 * rng.uniform() - 1.0)))
                            };
                            match r.length {
                                Some(length) => Resonator {
                                    length: Some(wobble(length)),
                                    ..*r
                                },
                                None => Resonator {
                                    eps: wobble(r.eps),
                                    kappa: wobble(r.kappa),
                                    ..*r
                                },
                            }
                        })
                        .collect(),
                })
                .collect();
            let label = Search::robustness(spread);
            let mut samples = self.evaluate(label, layouts, None, at)?;
            samples.sort_by(|a, b| a.score.total_cmp(&b.score));
            rows.extend(samples);
        }
        Ok(rows)
    }

    /// The best design any evaluation found inside the space (a robustness sample may beat the
    /// searches', but one whose eps or kappa left its range is not a design of this space),
    /// verified at the tight tolerance and written as `<stage>.best.toml`: the best row, the
    /// verification's row (also added to `rows`) and the file.
    fn verify_and_write(
        &self,
        ctx: &Context<'_>,
        at: PointsAt<'_>,
        rows: &mut Vec<Evaluated>,
        searched_best: Evaluated,
    ) -> Result<(Evaluated, Evaluated, std::path::PathBuf)> {
        let stage = at.stage;
        let best = rows
            .iter()
            .filter(|r| self.space.contains(&r.layout))
            .max_by(|a, b| a.score.total_cmp(&b.score))
            .cloned()
            .unwrap_or(searched_best);
        let verified = self
            .evaluate(
                Search::Verification,
                vec![best.layout.clone()],
                Some(self.verify_tolerance),
                at,
            )?
            .remove(0);
        rows.push(verified.clone());

        let best_file = best_path(ctx.results, stage);
        let text = toml::to_string(&self.table(&verified.layout, Some(self.verify_tolerance)))
            .map_err(|e| PipelineError::stage(stage, e.to_string()))?;
        let header = format!(
            "# The best design found by stage `{stage}` (woodpile run {stage}): {} = {} at t_end,\n# verified at tolerance {:e}. Run it with: woodpile simulate {}\n",
            self.objective_name(),
            self.fraction_of(verified.score),
            self.verify_tolerance,
            best_file.display()
        );
        ctx.write_file(&best_file, (header + &text).as_bytes())?;
        Ok((best, verified, best_file))
    }

    /// The manifest's summary: the verified best design, each search's best, and whether the
    /// baseline beat the optimiser.
    fn summary(
        &self,
        rows: &[Evaluated],
        best: &Evaluated,
        verified: &Evaluated,
        best_file: &Path,
    ) -> serde_json::Value {
        let de_best = self.best_of(rows, Search::DifferentialEvolution);
        let random_best = self.best_of(rows, Search::Random);
        let refined = self.best_of(rows, Search::Refinement);
        let refined_random = self.best_of(rows, Search::RefinementOfRandom);
        let mut summary = json!({
            "objective": self.objective_name(),
            "goal": if self.maximise { "max" } else { "min" },
            "evaluations": rows.len(),
            "best": self.fraction_of(verified.score),
            "best_error_estimate": verified.result.as_ref().ok().and_then(|p| p.error_estimate),
            "best_sites": verified.layout.list(|r| r.site),
            "best_eps": verified.layout.list(|r| r.eps),
            "best_kappa": verified.layout.list(|r| r.kappa),
            "differential_evolution_best": self.fraction_of(de_best),
            "random_best": self.fraction_of(random_best),
            "refined_best": self.fraction_of(refined.max(de_best)),
            "refined_random_best": self.fraction_of(refined_random.max(random_best)),
            "best_search": best.search.label(),
            "baseline_beat_optimiser": refined_random.max(random_best) > refined.max(de_best),
            "verify_tolerance": self.verify_tolerance,
            "best_file": best_file.file_name().map(|n| n.to_string_lossy().into_owned()),
        });
        if let Some(rods) = self.bill_of_rods(&verified.layout) {
            summary["bill_of_rods"] = rods;
        }
        summary
    }

    /// A rod design's best layout as the lab cuts it: each rod's site, length (m), host and
    /// resonator masses (kg), spring (N/m) and bending frequency (Hz), as its scene derives
    /// them; none for a design of eps and kappa.
    fn bill_of_rods(&self, layout: &Layout) -> Option<serde_json::Value> {
        self.space.length.as_ref()?;
        let scene = self.scene(layout, Some(self.verify_tolerance)).ok()?;
        let derived = scene.physical.map(|p| p.defects).unwrap_or_default();
        let rods: Vec<serde_json::Value> = layout
            .resonators
            .iter()
            .map(|r| {
                let d = derived.iter().find(|d| d.site == r.site);
                json!({
                    "site": r.site,
                    "length_m": r.length,
                    "host_mass_kg": d.and_then(|d| d.host_mass_kg),
                    "resonator_mass_kg": d.and_then(|d| d.resonator_mass_kg),
                    "stiffness_n_per_m": d.and_then(|d| d.stiffness_n_per_m),
                    "bending_f1_hz": d.and_then(|d| d.bending_f1_hz),
                })
            })
            .collect();
        Some(json!(rods))
    }

    /// Nelder–Mead from `start` (score `score`) on the eps and kappa genes of its resonators,
    /// within the `refine` budget; every trial a row labelled `label`.
    fn refine_from(
        &self,
        at: PointsAt<'_>,
        label: Search,
        start: &[f64],
        score: f64,
    ) -> Result<Vec<Evaluated>> {
        if self.refine == 0 || !score.is_finite() {
            return Ok(Vec::new());
        }
        let layout = self.space.decode(start);
        let slots: Vec<usize> = (1..self.space.dimension())
            .filter(|j| {
                let gene = (j - 1) % GENES;
                let slot = (j - 1) / GENES;
                // eps and kappa, or a rod's length alone (its eps gene).
                let searched = gene == 1 || (gene == 2 && self.space.length.is_none());
                searched && slot < layout.resonators.len()
            })
            .collect();
        let mut refined: Vec<Evaluated> = Vec::new();
        let mut failure: Option<PipelineError> = None;
        let mut objective = |x: &[f64]| -> Result<f64> {
            let mut g = start.to_vec();
            for (k, &j) in slots.iter().enumerate() {
                g[j] = x[k].clamp(0.0, 1.0);
            }
            let layout = self.space.decode(&g);
            match self.evaluate(label, vec![layout], None, at) {
                Ok(mut e) => {
                    let e = e.remove(0);
                    let score = e.score;
                    refined.push(e);
                    Ok(score)
                }
                Err(err) => {
                    failure = Some(PipelineError::stage(at.stage, err.to_string()));
                    Ok(f64::NEG_INFINITY)
                }
            }
        };
        let x0: Vec<f64> = slots.iter().map(|&j| start[j]).collect();
        if !x0.is_empty() {
            let steps = vec![0.05; x0.len()];
            woodpile_analysis::nelder_mead::maximise(
                &mut objective,
                &x0,
                &steps,
                score,
                self.refine,
            )?;
        }
        match failure {
            Some(e) => Err(e),
            None => Ok(refined),
        }
    }

    fn objective_name(&self) -> &'static str {
        self.objective.column()
    }

    /// A score back as the fraction.
    fn fraction_of(&self, score: f64) -> f64 {
        if self.maximise {
            score
        } else {
            -score
        }
    }

    fn best_of(&self, rows: &[Evaluated], search: Search) -> f64 {
        rows.iter()
            .filter(|e| e.search == search)
            .map(|e| e.score)
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

impl Kind for Design {
    fn sharing(&self) -> woodpile_pipeline::kind::Sharing {
        woodpile_pipeline::kind::Sharing::Parallel
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        self.compute(ctx)
    }

    fn files(&self, stage: &str, results: &Path, _: &Path) -> Vec<PathBuf> {
        vec![best_path(results, stage)]
    }
}
