//! Known-answer cases, fixtures and reference helpers shared by tests, surveys and
//! benchmarks; compiled only for them (`cfg(test)` or the `testing` feature). The fixtures
//! are small and explicit (the standard scene below is the one every speed claim uses); scenes
//! drawn from the paper's grids come from the stage files themselves
//! (`woodpile_stages::sampling`), never from copies of them.
//!
//! The known answers are exact: a host–resonator pair is a linear oscillator with
//! omega^2 = kappa (1/m + 1/eps); a head-on Hertz collision of two equal free beads exchanges
//! their velocities and conserves energy and momentum.

use crate::energy::{Fractions, Region};
use crate::error::SimError;
use crate::integrate::{Accuracy, Method, MethodChoice};
use crate::model::{Boundary, Coupling, Model, Resonator};
use crate::simulation::{simulate, Scenario};

mod audit_kinds;
mod lanes;
pub use crate::integrate::rk6_contact::{run_fixed_step, Rk6Contact};
pub use audit_kinds::{
    chain_audit_scene, damped_audit_scene, gap_audit_scene, gravity_audit_scene,
    linear_losses_audit_scene,
};
pub use lanes::{
    by_lanes_and_alone, lane_neighbours, with_resonator_masses_scaled, RecordedRun,
    THIRD_RUN_POINTS,
};

/// Half-width N of the paper's chains (sites -N..N).
pub const PAPER_N: usize = 100;
/// The paper's impact site n_S in Sections IV–V.
pub const PAPER_IMPULSE_SITE: i64 = -25;

/// Internal index of paper site `n` in a chain of sites -half_width..half_width.
pub fn paper_site(n: i64, half_width: usize) -> usize {
    (n + half_width as i64) as usize
}

/// One site carrying one linear resonator, free ends: a two-body linear oscillator. The state
/// starts with the resonator displaced by `x0` and everything at rest. Returns the model, the
/// state, and the angular frequency of the relative coordinate u - v.
pub fn linear_oscillator(eps: f64, kappa: f64, x0: f64) -> (Model, Vec<f64>, f64) {
    let res = vec![Resonator::constant(0, eps, kappa, 1)];
    let model = Model::new(1, Boundary::Free, res).expect("valid oscillator");
    let mut y = model.rest_state();
    y[1] = x0;
    let omega = (kappa * (1.0 + 1.0 / eps)).sqrt();
    (model, y, omega)
}

/// Two equal free beads, the first moving at velocity 1 towards the second at rest.
pub fn two_bead_collision() -> (Model, Vec<f64>) {
    let model = Model::new(2, Boundary::Free, vec![]).expect("valid chain");
    let mut y = model.rest_state();
    y[2] = 1.0;
    (model, y)
}

/// A defect of the paper's dimensionless scenes, in paper numbering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperDefect {
    /// Paper site n.
    pub site: i64,
    /// Mass ratio.
    pub eps: f64,
    /// Coupling.
    pub coupling: Coupling,
    /// Exponent.
    pub p: u32,
}

impl PaperDefect {
    /// A linear defect with constant kappa.
    pub fn linear(site: i64, eps: f64, kappa: f64) -> Self {
        Self::with_exponent(site, eps, kappa, 1)
    }

    /// A defect coupled by kappa (u - v)^p with constant kappa.
    pub fn with_exponent(site: i64, eps: f64, kappa: f64, p: u32) -> Self {
        Self {
            site,
            eps,
            coupling: Coupling::Constant(kappa),
            p,
        }
    }
}

/// The paper's standard scene: N = 100, fixed walls, n_S = -25, V = 1, t_end = 150, region
/// [min defect - 1, max defect + 1], with the given method and accuracy.
pub fn paper_scene(defects: &[PaperDefect], method: MethodChoice, accuracy: Accuracy) -> Scenario {
    let n_sites = 2 * PAPER_N + 1;
    let resonators = defects
        .iter()
        .map(|d| Resonator {
            site: paper_site(d.site, PAPER_N),
            eps: d.eps,
            coupling: d.coupling,
            p: d.p,
        })
        .collect();
    let model = Model::new(n_sites, Boundary::Fixed, resonators).expect("valid paper scene");
    let lo = defects.iter().map(|d| d.site).min().unwrap_or(0) - 1;
    let hi = defects.iter().map(|d| d.site).max().unwrap_or(0) + 1;
    let region = Region::new(
        paper_site(lo, PAPER_N) as i64,
        paper_site(hi, PAPER_N) as i64,
        n_sites,
    )
    .expect("region inside the chain");
    Scenario {
        model,
        impulse_site: paper_site(PAPER_IMPULSE_SITE, PAPER_N),
        impulse_velocity: 1.0,
        t_end: 150.0,
        region,
        method,
        accuracy,
        sample_every: 1.0,
    }
}

/// Accuracy by tolerance alone.
pub fn tolerance(tol: f64) -> Accuracy {
    Accuracy {
        tolerance: tol,
        tolerance_explicit: true,
        dt: None,
    }
}

/// Accuracy by a fixed step alone (drift bound: blow-up guard only).
pub fn fixed_dt(dt: f64) -> Accuracy {
    Accuracy {
        tolerance: 1e-8,
        tolerance_explicit: false,
        dt: Some(dt),
    }
}

/// Least-squares slope of log(error) against log(dt): the measured convergence order.
pub fn fitted_order(dts: &[f64], errors: &[f64]) -> f64 {
    let n = dts.len() as f64;
    let xs: Vec<f64> = dts.iter().map(|d| d.ln()).collect();
    let ys: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// A 64-bit linear congruential generator (Knuth's MMIX constants) for drawing survey scenes:
/// the same draws on every machine, without a dependency.
#[derive(Debug, Clone)]
pub struct Lcg(pub u64);

impl Lcg {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Log-uniform in [lo, hi).
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.uniform() * (hi.ln() - lo.ln())).exp()
    }

    /// A point of the grid lo, lo + step, ..., hi.
    pub fn grid(&mut self, lo: f64, hi: f64, step: f64) -> f64 {
        let n = ((hi - lo) / step).round();
        (self.uniform() * (n + 1.0)).floor().min(n) * step + lo
    }

    /// One element of `from`.
    pub fn pick<T: Copy>(&mut self, from: &[T]) -> T {
        from[((self.uniform() * from.len() as f64) as usize).min(from.len() - 1)]
    }
}

/// The step of the reference runs that accuracy checks compare with (`rk4-contact`): 0.001,
/// within about 1e-10 of RK4 at 0.001 and Yoshida-6 at 5e-4 on the linear scenes, and 0.00025
/// when a resonator is nonlinear (stiffer at its large stretches).
pub fn reference_dt(model: &Model) -> f64 {
    if model.resonators().iter().any(|r| r.p > 1) {
        0.00025
    } else {
        0.001
    }
}

/// `scenario`'s fractions by `rk4-contact` at the fixed step `dt`: the reference an accuracy
/// check measures a run of the same scene against.
pub fn reference_fractions(scenario: &Scenario, dt: f64) -> Result<Fractions, SimError> {
    let reference = Scenario {
        method: MethodChoice::Named(Method::Rk4Contact),
        accuracy: fixed_dt(dt),
        ..scenario.clone()
    };
    Ok(simulate(&reference, &mut ())?.fractions)
}

/// The step of the audit's reference (`rk4-contact`, checked by `rkn6-contact`): ten times
/// finer than `auto`'s finest steps at 1e-8 on the audit's chains.
pub const AUDIT_REFERENCE_DT: f64 = 2.5e-4;

/// The ranges a random survey scene is drawn from: a chain of `2 half + 1` sites, fixed or
/// free ends, defects near the centre, an impulse left of them. Each survey (the audit here,
/// `auto_wide` in `woodpile-bench`) is one value of it, so that both draw in the same order.
#[derive(Debug, Clone, Copy)]
pub struct SceneRanges {
    /// `half` is `half.0 + floor(u · half.1)`.
    pub half: (usize, f64),
    /// At most this many defects (one at least; those on the same site merge).
    pub defects: f64,
    /// A defect's site is `half + site.0 + floor(u · site.1)`.
    pub site: (i64, f64),
    /// Coupling exponents, equally likely.
    pub p: &'static [u32],
    /// Log-uniform range of kappa.
    pub kappa: (f64, f64),
    /// Log-uniform range of eps.
    pub eps: (f64, f64),
    /// The impulse's site is `half - 10 - floor(u · impulse_back)`.
    pub impulse_back: f64,
    /// The range of the impulse's velocity.
    pub velocity: (f64, f64),
    /// Whether that velocity is log-uniform (uniform otherwise).
    pub log_velocity: bool,
    /// `t_end` is `t_end.0 + u · t_end.1`.
    pub t_end: (f64, f64),
}

/// The audit's ranges: n from 50 to 150, 1 to 5 defects near the centre (eps 0.05 to 100,
/// kappa 0.1 to 10, p in {1, 3, 5, 7}), an impulse of velocity 0.5 to 2 left of centre, t_end
/// from 100 to 200.
pub const AUDIT_RANGES: SceneRanges = SceneRanges {
    half: (50, 101.0),
    defects: 5.0,
    site: (-5, 26.0),
    p: &[1, 3, 5, 7],
    kappa: (0.1, 10.0),
    eps: (0.05, 100.0),
    impulse_back: 30.0,
    velocity: (0.5, 2.0),
    log_velocity: false,
    t_end: (100.0, 100.0),
};

/// A random scene drawn from `ranges`, `auto` at tolerance `tol`. A fifth of the defects are
/// switched on by a tanh ramp.
pub fn random_scene(rng: &mut Lcg, ranges: &SceneRanges, tol: f64) -> Scenario {
    let half = ranges.half.0 + (rng.uniform() * ranges.half.1) as usize;
    let n_sites = 2 * half + 1;
    let boundary = if rng.uniform() < 0.5 {
        Boundary::Fixed
    } else {
        Boundary::Free
    };
    let count = 1 + (rng.uniform() * ranges.defects) as usize;
    let mut resonators: Vec<Resonator> = (0..count)
        .map(|_| {
            let site =
                (half as i64 + ranges.site.0) as usize + (rng.uniform() * ranges.site.1) as usize;
            let choices = ranges.p.len();
            let p = ranges.p[(rng.uniform() * choices as f64) as usize % choices];
            let kappa = rng.log_uniform(ranges.kappa.0, ranges.kappa.1);
            let coupling = if rng.uniform() < 0.2 {
                Coupling::Ramp {
                    k1: 0.0,
                    k2: kappa,
                    t0: rng.uniform() * 60.0,
                    tau: rng.log_uniform(0.1, 5.0),
                }
            } else {
                Coupling::Constant(kappa)
            };
            Resonator {
                site,
                eps: rng.log_uniform(ranges.eps.0, ranges.eps.1),
                coupling,
                p,
            }
        })
        .collect();
    resonators.sort_by_key(|r| r.site);
    resonators.dedup_by_key(|r| r.site);
    let lo = resonators[0].site as i64 - 1;
    let hi = resonators[resonators.len() - 1].site as i64 + 1;
    let impulse_site = half - 10 - (rng.uniform() * ranges.impulse_back) as usize;
    let (v_lo, v_hi) = ranges.velocity;
    let impulse_velocity = if ranges.log_velocity {
        rng.log_uniform(v_lo, v_hi)
    } else {
        rng.uniform() * (v_hi - v_lo) + v_lo
    };
    Scenario {
        model: Model::new(n_sites, boundary, resonators).expect("a valid survey model"),
        impulse_site,
        impulse_velocity,
        t_end: ranges.t_end.0 + rng.uniform() * ranges.t_end.1,
        region: Region::new(lo, hi, n_sites).expect("a valid survey region"),
        method: MethodChoice::Auto,
        accuracy: tolerance(tol),
        sample_every: 1.0,
    }
}

/// One scene of `auto`'s audit (`woodpile-bench`'s `auto_audit`), drawn wider than any stage
/// file from [`AUDIT_RANGES`]; `auto` at tolerance 1e-8.
pub fn audit_scene(rng: &mut Lcg) -> Scenario {
    random_scene(rng, &AUDIT_RANGES, 1e-8)
}

/// One scene of the audit of linear resonators (`auto_audit --linear`): an audit scene
/// ([`audit_scene`], the same draws) with every resonator linear (p = 1) and its coupling
/// constant at the ramp's final value. These are the paper's kind of scene, which `auto`
/// judges by its first pair at half the tolerance, without the stricter rules a nonlinear
/// or ramped resonator brings; the plain audit rarely draws such a scene.
pub fn linear_audit_scene(rng: &mut Lcg) -> Scenario {
    let base = audit_scene(rng);
    let resonators = base
        .model
        .resonators()
        .iter()
        .map(|r| Resonator::constant(r.site, r.eps, r.coupling.at(f64::INFINITY), 1))
        .collect();
    let (n_sites, boundary) = (base.model.n_sites(), base.model.boundary());
    Scenario {
        model: Model::new(n_sites, boundary, resonators).expect("a valid survey model"),
        ..base
    }
}

/// Scene `k` of the audit drawn with `seed` (the scenes before it are drawn and dropped).
pub fn audit_scene_at(seed: u64, k: usize) -> Scenario {
    let mut rng = Lcg(seed);
    for _ in 0..k {
        audit_scene(&mut rng);
    }
    audit_scene(&mut rng)
}
