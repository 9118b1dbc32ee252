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

use polars::prelude::DataFrame;
use rayon::prelude::*;
use serde_json::json;
use woodpile_scene::Scene;

use woodpile_pipeline::error::{PipelineError, Result};
use woodpile_pipeline::events::Events;
use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::kind::{no_inputs, Context, Inputs, Kind, KindCheck};
use woodpile_pipeline::layout::best_path;
use woodpile_pipeline::points::{point_key, PointData, PointResult, PointStore, Series};
use woodpile_pipeline::stage::Stage;
use woodpile_pipeline::table::{rows_frame, Cell, Row};
use woodpile_pipeline::Output;

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
    pub objective: Objective,
    /// Maximise (true) or minimise.
    pub maximise: bool,
    /// Tolerance of the best design's verification run.
    pub verify_tolerance: f64,
    /// Perturbation study of the best design: samples per spread, and the spreads.
    pub robustness: Option<(usize, Vec<f64>)>,
    /// The search space.
    pub space: Space,
    template: toml::Table,
    file: PathBuf,
}

/// The fraction a design optimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Objective {
    /// Reflected.
    R,
    /// Transmitted.
    T,
    /// Trapped.
    ETr,
}

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
    fn at(&self, u: f64) -> f64 {
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
    fn at(&self, u: f64) -> f64 {
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
    fn count(&self) -> usize {
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
}

/// One decoded design: resonators sorted by site.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// (paper site, eps, kappa, p) per resonator.
    pub resonators: Vec<(i64, f64, f64, i64)>,
}

impl Layout {
    fn total_eps(&self) -> f64 {
        self.resonators.iter().map(|r| r.1).sum()
    }

    fn list<T: std::fmt::Display>(&self, pick: impl Fn(&(i64, f64, f64, i64)) -> T) -> String {
        self.resonators
            .iter()
            .map(|r| pick(r).to_string())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Genes per resonator slot: site, eps, kappa, p.
const GENES: usize = 4;
/// Differential evolution's population, step and crossover rate.
const POPULATION: usize = 20;
const STEP: f64 = 0.6;
const CROSSOVER: f64 = 0.9;

impl Space {
    fn dimension(&self) -> usize {
        1 + GENES * self.resonators.1
    }

    /// The layout a genome in [0, 1]^d stands for: a resonator on a site already taken is
    /// dropped, so every layout is valid and equal layouts come out equal.
    fn decode(&self, genome: &[f64]) -> Layout {
        let (lo, hi) = self.resonators;
        let count = lo + pick(genome[0], hi - lo + 1);
        let mut resonators: Vec<(i64, f64, f64, i64)> = Vec::with_capacity(count);
        for slot in 0..count {
            let g = &genome[1 + GENES * slot..1 + GENES * (slot + 1)];
            let site = match &self.sites {
                Sites::Range(first, last) => first + pick(g[0], (last - first + 1) as usize) as i64,
                Sites::Among(list) => list[pick(g[0], list.len())],
                Sites::Fixed(list) => list[slot],
            };
            if resonators.iter().any(|r| r.0 == site) {
                continue;
            }
            let eps = round_sig(self.eps.at(g[1]));
            let kappa = round_sig(self.kappa.at(g[2]));
            resonators.push((site, eps, kappa, self.p[pick(g[3], self.p.len())]));
        }
        resonators.sort_by_key(|r| r.0);
        Layout { resonators }
    }
}

/// 10 significant digits: a design file states its numbers exactly as they were simulated,
/// and nearby genomes share cached points.
fn round_sig(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let digits = 9 - x.abs().log10().floor() as i32;
    let scale = 10f64.powi(digits);
    (x * scale).round() / scale
}

/// splitmix64: a small seeded generator; each search has its own stream.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn uniform(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn below(&mut self, n: usize) -> usize {
        (self.uniform() * n as f64) as usize % n.max(1)
    }
}

/// One evaluated design.
#[derive(Debug, Clone)]
struct Evaluated {
    search: &'static str,
    layout: Layout,
    result: PointResult,
    score: f64,
    key: String,
}

impl Design {
    pub(crate) fn parse(fields: &mut Fields<'_>) -> Result<Design> {
        let positive_int = |fields: &mut Fields<'_>, key: &str, default: Option<i64>| {
            let value = match (fields.optional::<i64>(key)?, default) {
                (Some(v), _) => v,
                (None, Some(d)) => d,
                (None, None) => return Err(fields.error(key, "is required")),
            };
            if !(0..=1_000_000).contains(&value) {
                return Err(fields.error(key, "expected an integer from 0 to 1000000"));
            }
            Ok(value as usize)
        };
        let seed = fields.required::<i64>("seed")? as u64;
        let budget = positive_int(fields, "budget", None)?;
        if budget < POPULATION {
            return Err(fields.error("budget", format!("at least {POPULATION} evaluations")));
        }
        let refine = positive_int(fields, "refine", Some(0))?;
        let objective = match fields.required::<String>("objective")?.as_str() {
            "E_tr" => Objective::ETr,
            "R" => Objective::R,
            "T" => Objective::T,
            other => {
                return Err(fields.error(
                    "objective",
                    format!("expected \"E_tr\", \"R\" or \"T\", got \"{other}\""),
                ))
            }
        };
        let maximise = match fields.optional::<String>("goal")?.as_deref() {
            None | Some("max") => true,
            Some("min") => false,
            Some(other) => {
                return Err(fields.error(
                    "goal",
                    format!("expected \"max\" or \"min\", got \"{other}\""),
                ))
            }
        };
        let verify_tolerance = fields.optional::<f64>("verify_tolerance")?.unwrap_or(1e-8);
        let robustness = match fields.optional::<toml::Table>("robustness")? {
            None => None,
            Some(table) => {
                let mut f = fields.nested("robustness", table);
                let samples = positive_int(&mut f, "samples", None)?;
                let spreads: Vec<f64> = f.required("spreads")?;
                if spreads.iter().any(|s| !(0.0..1.0).contains(s)) {
                    return Err(f.error("spreads", "expected fractions in [0, 1)"));
                }
                f.finish()?;
                Some((samples, spreads))
            }
        };
        let Some(space) = fields.optional::<toml::Table>("space")? else {
            return Err(fields.error("space", "is required"));
        };
        let space = parse_space(fields.nested("space", space))?;
        let template: toml::Table = fields.required("scene")?;
        if template.contains_key("defect") {
            return Err(fields.error(
                "scene.defect",
                "the design places the defects: leave them out",
            ));
        }
        let region = template
            .get("fractions")
            .and_then(|f| f.get("region"))
            .is_some();
        if !region {
            return Err(fields.error(
                "scene.fractions.region",
                "is required: the trap's region must not move with the design",
            ));
        }
        let design = Design {
            seed,
            budget,
            refine,
            objective,
            maximise,
            verify_tolerance,
            robustness,
            space,
            template,
            file: fields.file().to_path_buf(),
        };
        // The extremes of the space must make valid scenes: catch a bad template now.
        let dimension = design.space.dimension();
        for corner in [0.0, 1.0 - 1e-12] {
            design.scene(&design.space.decode(&vec![corner; dimension]), None)?;
        }
        Ok(design)
    }

    /// The scene table of `layout` (with `run.tolerance` replaced when given).
    fn table(&self, layout: &Layout, tolerance: Option<f64>) -> toml::Table {
        let mut table = self.template.clone();
        let defects = layout
            .resonators
            .iter()
            .map(|&(site, eps, kappa, p)| {
                let mut d = toml::Table::new();
                d.insert("site".into(), toml::Value::Integer(site));
                d.insert("eps".into(), toml::Value::Float(eps));
                d.insert("kappa".into(), toml::Value::Float(kappa));
                d.insert("p".into(), toml::Value::Integer(p));
                toml::Value::Table(d)
            })
            .collect();
        table.insert("defect".into(), toml::Value::Array(defects));
        if let Some(tol) = tolerance {
            if let Some(toml::Value::Table(run)) = table.get_mut("run") {
                run.insert("tolerance".into(), toml::Value::Float(tol));
            }
        }
        table
    }

    fn scene(&self, layout: &Layout, tolerance: Option<f64>) -> Result<Scene> {
        woodpile_scene::from_table(self.table(layout, tolerance), &self.file)
            .map_err(|e| PipelineError::scene(&self.file, "scene", e, ""))
    }

    /// The objective of a result, as a score to maximise (failures and infeasible designs
    /// score -inf, so any working design beats them).
    fn score(&self, result: &PointResult) -> f64 {
        let Ok(data) = result else {
            return f64::NEG_INFINITY;
        };
        let series = match self.objective {
            Objective::R => &data.reflected,
            Objective::T => &data.transmitted,
            Objective::ETr => &data.trapped,
        };
        match series.last() {
            Some(&v) if v.is_finite() => {
                if self.maximise {
                    v
                } else {
                    -v
                }
            }
            _ => f64::NEG_INFINITY,
        }
    }

    /// Evaluates `layouts` in parallel through the point cache, in order.
    fn evaluate(
        &self,
        search: &'static str,
        layouts: Vec<Layout>,
        tolerance: Option<f64>,
        store: &PointStore,
        events: &dyn Events,
    ) -> Result<Vec<Evaluated>> {
        layouts
            .into_par_iter()
            .map(|layout| {
                if let Some(bound) = self.space.max_total_eps {
                    if layout.total_eps() > bound {
                        let reason =
                            format!("total eps {} above the bound {bound}", layout.total_eps());
                        return Ok(Evaluated {
                            search,
                            layout,
                            result: Err(reason),
                            score: f64::NEG_INFINITY,
                            key: String::new(),
                        });
                    }
                }
                let scene = self.scene(&layout, tolerance)?;
                let key = point_key(&scene, Series::Energy);
                let result = store.get_or_simulate(&key, &scene, Series::Energy)?;
                events.point_done();
                let score = self.score(&result);
                Ok(Evaluated {
                    search,
                    layout,
                    result,
                    score,
                    key: key.to_string(),
                })
            })
            .collect()
    }

    pub(crate) fn run(
        &self,
        stage: &str,
        store: &PointStore,
        results: &Path,
        events: &dyn Events,
    ) -> Result<Output> {
        let d = self.space.dimension();
        let robust: usize = self
            .robustness
            .as_ref()
            .map_or(0, |(samples, spreads)| samples * spreads.len());
        let total = 2 * self.budget + self.refine + 1 + robust;
        events.simulating(stage, total, 0);
        let mut rows: Vec<Evaluated> = Vec::with_capacity(total);

        // Differential evolution.
        let mut rng = Rng(self.seed ^ 0xde);
        let genome = |rng: &mut Rng| (0..d).map(|_| rng.uniform()).collect::<Vec<f64>>();
        let mut population: Vec<Vec<f64>> = (0..POPULATION).map(|_| genome(&mut rng)).collect();
        let layouts = population.iter().map(|g| self.space.decode(g)).collect();
        let mut scores: Vec<f64> = Vec::with_capacity(POPULATION);
        for e in self.evaluate("differential evolution", layouts, None, store, events)? {
            scores.push(e.score);
            rows.push(e);
        }
        let mut spent = POPULATION;
        while spent < self.budget {
            let n = POPULATION.min(self.budget - spent);
            let trials: Vec<Vec<f64>> = (0..n)
                .map(|i| {
                    let mut pick = |not: &[usize]| loop {
                        let k = rng.below(POPULATION);
                        if !not.contains(&k) {
                            return k;
                        }
                    };
                    let a = pick(&[i]);
                    let b = pick(&[i, a]);
                    let c = pick(&[i, a, b]);
                    let forced = rng.below(d);
                    (0..d)
                        .map(|j| {
                            if j == forced || rng.uniform() < CROSSOVER {
                                let v =
                                    population[a][j] + STEP * (population[b][j] - population[c][j]);
                                // Reflect into [0, 1] rather than pile up on the bounds.
                                let v = if v < 0.0 {
                                    -v
                                } else if v > 1.0 {
                                    2.0 - v
                                } else {
                                    v
                                };
                                v.clamp(0.0, 1.0)
                            } else {
                                population[i][j]
                            }
                        })
                        .collect()
                })
                .collect();
            let layouts = trials.iter().map(|g| self.space.decode(g)).collect();
            let evaluated =
                self.evaluate("differential evolution", layouts, None, store, events)?;
            for (i, (trial, e)) in trials.into_iter().zip(evaluated).enumerate() {
                if e.score >= scores[i] {
                    population[i] = trial;
                    scores[i] = e.score;
                }
                rows.push(e);
            }
            spent += n;
        }

        // Random search of the same budget: the baseline.
        let mut rng = Rng(self.seed ^ 0x5eed);
        let random_genomes: Vec<Vec<f64>> = (0..self.budget).map(|_| genome(&mut rng)).collect();
        let layouts = random_genomes
            .iter()
            .map(|g| self.space.decode(g))
            .collect();
        let random_rows = self.evaluate("random", layouts, None, store, events)?;
        let random_best = (0..random_rows.len())
            .max_by(|&a, &b| random_rows[a].score.total_cmp(&random_rows[b].score));
        rows.extend(random_rows.iter().cloned());

        // Refinement: Nelder–Mead on the eps and kappa genes of each search's best candidate,
        // its count and sites fixed.
        let de_best = (0..POPULATION)
            .max_by(|&a, &b| scores[a].total_cmp(&scores[b]))
            .unwrap_or(0);
        let mut starts = vec![("refinement", population[de_best].clone(), scores[de_best])];
        if let Some(i) = random_best {
            starts.push((
                "refinement of random",
                random_genomes[i].clone(),
                random_rows[i].score,
            ));
        }
        for (label, start, score) in starts {
            rows.extend(self.refine_from(stage, label, &start, score, store, events)?);
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

        // Robustness: the best design with every eps and kappa off by up to ±spread.
        if let Some((samples, spreads)) = &self.robustness {
            for (k, &spread) in spreads.iter().enumerate() {
                let mut rng = Rng(self.seed ^ (0x7000 + k as u64));
                let layouts = (0..*samples)
                    .map(|_| Layout {
                        resonators: best
                            .layout
                            .resonators
                            .iter()
                            .map(|&(site, eps, kappa, p)| {
                                let mut wobble = |x: f64| {
                                    round_sig(x * (1.0 + spread * (2.0 * rng.uniform() - 1.0)))
                                };
                                (site, wobble(eps), wobble(kappa), p)
                            })
                            .collect(),
                    })
                    .collect();
                let label: &'static str = match spread {
                    0.01 => "robustness ±1%",
                    0.05 => "robustness ±5%",
                    _ => "robustness",
                };
                // In order of E_tr: the table then reads as the distribution's quantiles.
                let mut samples = self.evaluate(label, layouts, None, store, events)?;
                samples.sort_by(|a, b| a.score.total_cmp(&b.score));
                rows.extend(samples);
            }
        }

        // The best design any evaluation found (a robustness sample may beat the searches'),
        // verified at the tight tolerance: what the best file holds.
        let best = rows
            .iter()
            .max_by(|a, b| a.score.total_cmp(&b.score))
            .cloned()
            .unwrap_or(best);
        let verified = self
            .evaluate(
                "verification",
                vec![best.layout.clone()],
                Some(self.verify_tolerance),
                store,
                events,
            )?
            .remove(0);
        let verified_score = verified.score;
        rows.push(verified.clone());

        let best_file = best_path(results, stage);
        let text = toml::to_string(&self.table(&verified.layout, Some(self.verify_tolerance)))
            .map_err(|e| PipelineError::stage(stage, e.to_string()))?;
        let header = format!(
            "# The best design found by stage `{stage}` (woodpile run {stage}): {} = {} at t_end,\n# verified at tolerance {:e}. Run it with: woodpile simulate {}\n",
            self.objective_name(),
            self.shown(verified_score),
            self.verify_tolerance,
            best_file.display()
        );
        woodpile_pipeline::atomic::write(&best_file, (header + &text).as_bytes())?;

        let de_best = self.best_of(&rows, "differential evolution");
        let random_best = self.best_of(&rows, "random");
        let refined = self.best_of(&rows, "refinement");
        let refined_random = self.best_of(&rows, "refinement of random");
        let frame = self.frame(&rows)?;
        Ok(Output {
            frame,
            summary: json!({
                "objective": self.objective_name(),
                "goal": if self.maximise { "max" } else { "min" },
                "evaluations": rows.len(),
                "best": self.shown(verified_score),
                "best_error_estimate": verified.result.as_ref().ok().and_then(|p| p.error_estimate),
                "best_sites": verified.layout.list(|r| r.0),
                "best_eps": verified.layout.list(|r| r.1),
                "best_kappa": verified.layout.list(|r| r.2),
                "differential_evolution_best": self.shown(de_best),
                "random_best": self.shown(random_best),
                "refined_best": self.shown(refined.max(de_best)),
                "refined_random_best": self.shown(refined_random.max(random_best)),
                "best_search": best.search,
                "baseline_beat_optimiser": refined_random.max(random_best) > refined.max(de_best),
                "verify_tolerance": self.verify_tolerance,
                "best_file": best_file.file_name().map(|n| n.to_string_lossy().into_owned()),
            }),
            failures: Vec::new(),
        })
    }

    /// Nelder–Mead from `start` (score `score`) on the eps and kappa genes of its resonators,
    /// within the `refine` budget; every trial a row labelled `label`.
    fn refine_from(
        &self,
        stage: &str,
        label: &'static str,
        start: &[f64],
        score: f64,
        store: &PointStore,
        events: &dyn Events,
    ) -> Result<Vec<Evaluated>> {
        if self.refine == 0 || !score.is_finite() {
            return Ok(Vec::new());
        }
        let layout = self.space.decode(start);
        let slots: Vec<usize> = (1..self.space.dimension())
            .filter(|j| {
                let gene = (j - 1) % GENES;
                let slot = (j - 1) / GENES;
                (gene == 1 || gene == 2) && slot < layout.resonators.len()
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
            match self.evaluate(label, vec![layout], None, store, events) {
                Ok(mut e) => {
                    let e = e.remove(0);
                    let score = e.score;
                    refined.push(e);
                    Ok(score)
                }
                Err(err) => {
                    failure = Some(PipelineError::stage(stage, err.to_string()));
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
        match self.objective {
            Objective::R => "R",
            Objective::T => "T",
            Objective::ETr => "E_tr",
        }
    }

    /// A score back as the fraction.
    fn shown(&self, score: f64) -> f64 {
        if self.maximise {
            score
        } else {
            -score
        }
    }

    fn best_of(&self, rows: &[Evaluated], search: &str) -> f64 {
        rows.iter()
            .filter(|e| e.search == search)
            .map(|e| e.score)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    fn frame(&self, rows: &[Evaluated]) -> Result<DataFrame> {
        let mut counters = [0i64; SEARCHES.len()];
        let mut bests = [f64::NEG_INFINITY; SEARCHES.len()];
        let mut out: Vec<TrialRow> = rows
            .iter()
            .map(|e| {
                let s = search_index(e.search);
                counters[s] += 1;
                bests[s] = bests[s].max(e.score);
                TrialRow {
                    trial: e,
                    search_index: s,
                    evaluation: counters[s],
                    best_so_far: bests[s].is_finite().then(|| self.shown(bests[s])),
                    quantile: None,
                }
            })
            .collect();
        // Robustness samples: each one's rank among its spread's samples, as a quantile, so
        // that E_tr against `quantile` draws the distribution.
        for search in SEARCHES.iter().filter(|s| s.starts_with("robustness")) {
            let mut members: Vec<usize> = (0..rows.len())
                .filter(|&i| rows[i].search == *search)
                .collect();
            members.sort_by(|&a, &b| rows[a].score.total_cmp(&rows[b].score).then(a.cmp(&b)));
            let n = members.len();
            for (rank, &i) in members.iter().enumerate() {
                out[i].quantile = Some(if n > 1 {
                    rank as f64 / (n - 1) as f64
                } else {
                    0.5
                });
            }
        }
        rows_frame(&out)
    }
}

/// The searches a design table holds, in `search_index` order.
const SEARCHES: [&str; 8] = [
    "differential evolution",
    "random",
    "refinement",
    "verification",
    "robustness ±1%",
    "robustness ±5%",
    "refinement of random",
    "robustness",
];

fn search_index(search: &str) -> usize {
    SEARCHES
        .iter()
        .position(|s| *s == search)
        .unwrap_or(SEARCHES.len() - 1)
}

/// One row of the design table: an evaluated design and where it stands in its search.
struct TrialRow<'a> {
    trial: &'a Evaluated,
    search_index: usize,
    evaluation: i64,
    best_so_far: Option<f64>,
    quantile: Option<f64>,
}

impl Row for TrialRow<'_> {
    fn cells(&self) -> Vec<(&str, Cell)> {
        let e = self.trial;
        let ok = e.result.as_ref().ok();
        let last = |pick: fn(&PointData) -> &Vec<f64>| ok.and_then(|p| pick(p).last().copied());
        vec![
            ("search", e.search.into()),
            ("search_index", Cell::from(self.search_index as i64)),
            ("evaluation", Cell::from(self.evaluation)),
            ("resonators", Cell::from(e.layout.resonators.len() as i64)),
            (
                "sites",
                Cell::I64List(e.layout.resonators.iter().map(|r| r.0).collect()),
            ),
            (
                "eps",
                Cell::F64List(e.layout.resonators.iter().map(|r| r.1).collect()),
            ),
            (
                "kappa",
                Cell::F64List(e.layout.resonators.iter().map(|r| r.2).collect()),
            ),
            (
                "p",
                Cell::I64List(e.layout.resonators.iter().map(|r| r.3).collect()),
            ),
            ("total_eps", Cell::from(e.layout.total_eps())),
            ("R", last(|p| &p.reflected).into()),
            ("T", last(|p| &p.transmitted).into()),
            ("E_tr", last(|p| &p.trapped).into()),
            ("error_estimate", ok.and_then(|p| p.error_estimate).into()),
            ("best_so_far", self.best_so_far.into()),
            ("quantile", self.quantile.into()),
            ("failure", e.result.as_ref().err().cloned().into()),
            (
                "scene_key",
                (!e.key.is_empty()).then(|| e.key.clone()).into(),
            ),
        ]
    }
}

fn parse_space(mut f: Fields<'_>) -> Result<Space> {
    let sites = parse_sites(&mut f)?;
    let (lo, hi) = match (&sites, f.optional::<toml::Value>("resonators")?) {
        (Sites::Fixed(list), None) => (list.len() as i64, list.len() as i64),
        (_, None) => return Err(f.error("resonators", "is required: [fewest, most]")),
        (_, Some(toml::Value::Array(items))) => match items.as_slice() {
            [toml::Value::Integer(a), toml::Value::Integer(b)] if a <= b => (*a, *b),
            _ => {
                return Err(f.error(
                    "resonators",
                    "expected [fewest, most], integers with fewest <= most",
                ))
            }
        },
        (_, Some(_)) => return Err(f.error("resonators", "expected [fewest, most]")),
    };
    if lo < 0 || !(1..=64).contains(&hi) {
        return Err(f.error(
            "resonators",
            "expected counts from 0 to 64, at least one resonator possible",
        ));
    }
    if let Sites::Fixed(list) = &sites {
        if (lo, hi) != (list.len() as i64, list.len() as i64) {
            return Err(f.error(
                "resonators",
                format!(
                    "with fixed sites there is one resonator per site: [{0}, {0}] (or leave it out)",
                    list.len()
                ),
            ));
        }
    }
    if (sites.count() as i64) < lo {
        return Err(f.error("sites", "fewer sites than the fewest resonators"));
    }
    let eps = parse_values(&mut f, "eps")?;
    let kappa = parse_values(&mut f, "kappa")?;
    let p: Vec<i64> = match f.optional::<toml::Value>("p")? {
        None => vec![1],
        Some(toml::Value::Array(items)) if !items.is_empty() => items
            .iter()
            .map(|v| {
                v.as_integer()
                    .ok_or_else(|| f.error("p", "expected integers"))
            })
            .collect::<Result<_>>()?,
        Some(_) => return Err(f.error("p", "expected a list of exponents")),
    };
    let max_total_eps = f.optional::<f64>("max_total_eps")?;
    f.finish()?;
    Ok(Space {
        resonators: (lo as usize, hi as usize),
        sites,
        eps,
        kappa,
        p,
        max_total_eps,
    })
}

/// `sites`: `[first, last]`, a list of three or more sites, `{ among = [...] }` or
/// `{ fixed = [...] }` (paper sites, distinct).
fn parse_sites(f: &mut Fields<'_>) -> Result<Sites> {
    const FORMS: &str =
        "expected [first, last], a list of sites, { among = [...] } or { fixed = [...] }";
    let integers = |f: &Fields<'_>, key: &str, items: &[toml::Value]| -> Result<Vec<i64>> {
        let list: Vec<i64> = items
            .iter()
            .map(toml::Value::as_integer)
            .collect::<Option<_>>()
            .ok_or_else(|| f.error(key, "expected integer paper sites"))?;
        let mut sorted = list.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() != list.len() || list.is_empty() || list.len() > 64 {
            return Err(f.error(key, "expected 1 to 64 distinct sites"));
        }
        Ok(sorted)
    };
    match f.required::<toml::Value>("sites")? {
        toml::Value::Array(items) => match items.as_slice() {
            [toml::Value::Integer(a), toml::Value::Integer(b)] if a <= b => Ok(Sites::Range(*a, *b)),
            [_, _] => Err(f.error("sites", "expected [first, last] with first <= last (for two separate sites: { among = [a, b] })")),
            _ => Ok(Sites::Among(integers(f, "sites", &items)?)),
        },
        toml::Value::Table(table) => {
            let mut t = f.nested("sites", table);
            let form = match (t.take("among"), t.take("fixed")) {
                (Some(toml::Value::Array(items)), None) => Sites::Among(integers(&t, "among", &items)?),
                (None, Some(toml::Value::Array(items))) => Sites::Fixed(integers(&t, "fixed", &items)?),
                _ => return Err(f.error("sites", FORMS)),
            };
            t.finish()?;
            Ok(form)
        }
        _ => Err(f.error("sites", FORMS)),
    }
}

/// `eps` or `kappa`: `{ min, max, log }`, or a list of the values allowed.
fn parse_values(f: &mut Fields<'_>, key: &str) -> Result<Values> {
    match f.optional::<toml::Value>(key)? {
        Some(toml::Value::Array(items)) => {
            let list: Option<Vec<f64>> = items
                .iter()
                .map(|v| match v {
                    toml::Value::Float(x) if x.is_finite() && *x > 0.0 => Some(*x),
                    toml::Value::Integer(i) if *i > 0 => Some(*i as f64),
                    _ => None,
                })
                .collect();
            match list {
                Some(list) if !list.is_empty() => Ok(Values::List(list)),
                _ => Err(f.error(
                    key,
                    "expected a list of positive numbers, or { min, max, log }",
                )),
            }
        }
        Some(toml::Value::Table(table)) => {
            let mut r = f.nested(key, table);
            let min: f64 = r.required("min")?;
            let max: f64 = r.required("max")?;
            let log = match r.take("log") {
                None => false,
                Some(toml::Value::Boolean(b)) => b,
                Some(_) => return Err(r.error("log", "expected true or false")),
            };
            if !(min.is_finite() && max.is_finite() && min > 0.0 && min <= max) {
                return Err(r.error("min", "expected 0 < min <= max"));
            }
            r.finish()?;
            Ok(Values::Range(Range { min, max, log }))
        }
        Some(_) => Err(f.error(key, "expected { min, max, log } or a list of values")),
        None => Err(f.error(key, "is required: { min, max, log } or a list of values")),
    }
}

impl Kind for Design {
    fn sharing(&self) -> woodpile_pipeline::kind::Sharing {
        woodpile_pipeline::kind::Sharing::Parallel
    }

    fn check_inputs(&self, stage: &Stage, _: &Inputs<'_>) -> KindCheck {
        no_inputs(stage)
    }

    fn run(&self, ctx: &Context<'_>) -> Result<Output> {
        self.run(ctx.name(), ctx.store, ctx.results, ctx.events)
    }

    fn files(&self, stage: &str, results: &Path, _: &Path) -> Vec<PathBuf> {
        vec![best_path(results, stage)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        }
    }

    #[test]
    fn genomes_decode_to_sorted_distinct_sites_within_the_space() {
        let s = space();
        let mut rng = Rng(7);
        for _ in 0..500 {
            let g: Vec<f64> = (0..s.dimension()).map(|_| rng.uniform()).collect();
            let layout = s.decode(&g);
            let sites: Vec<i64> = layout.resonators.iter().map(|r| r.0).collect();
            assert!(!sites.is_empty() && sites.len() <= 3);
            assert!(sites.windows(2).all(|w| w[0] < w[1]), "{sites:?}");
            for &(site, eps, kappa, p) in &layout.resonators {
                assert!((0..=4).contains(&site));
                assert!((0.1..=100.0).contains(&eps) && (1.0..=2.0).contains(&kappa));
                assert!(p == 1 || p == 3);
            }
        }
        assert_eq!((s.eps.at(0.0), s.eps.at(1.0)), (0.1, 100.0));
        assert!((s.eps.at(0.5) - 10f64.powf(0.5)).abs() < 1e-12);
    }

    /// Fixed sites get one resonator each, whatever the genome; listed sites and listed eps
    /// values are the only ones chosen.
    #[test]
    fn fixed_and_listed_sites_and_listed_eps_are_respected() {
        let mut rng = Rng(11);
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
            let sites: Vec<i64> = layout.resonators.iter().map(|r| r.0).collect();
            assert_eq!(sites, [0, 10, 20]);
            assert!(layout
                .resonators
                .iter()
                .all(|r| [0.5, 2.0, 8.0].contains(&r.1)));
            let g: Vec<f64> = (0..among.dimension()).map(|_| rng.uniform()).collect();
            assert!(among
                .decode(&g)
                .resonators
                .iter()
                .all(|r| [-3, 7, 9].contains(&r.0)));
        }
    }
}
