//! The fixed-step time loop of four runs in lanes: [`drive`](crate::integrate::drive)'s
//! loop, with each lane's bookkeeping (its active window, counts, failure checks, samples and
//! observer) kept by the scalar driver's own [`Stepping`], and the steps taken together.

use super::step::LaneRkn6;
use super::{LaneChain, Lanes, LANES, ZERO};
use crate::chain_force::Width;
use crate::error::SimError;
use crate::integrate::driver::{check_finite_in, intervals, sample_time, validate, Stepping};
use crate::integrate::{DriveConfig, Method, Observer, Stats, StepControl};
use crate::model::{Model, Window};

/// Integrates four states `ys` (`[q, q']` each, of `models`, one per lane) from t = 0 to
/// `cfg.t_end` by `method` (`rkn6-contact` or `erkn6-contact`) at `cfg`'s fixed step, calling
/// each lane's observer at the samples, and leaves each lane's final state in `ys`. Each lane's result is its scalar run's
/// ([`crate::integrate::drive`] with [`crate::integrate::Plan::stepper`]) bit for bit: its
/// statistics, or the error that stopped it (which stops that lane only).
///
/// `None` when the models do not share a chain ([`LaneChain::of`]), the step is not fixed, or
/// the method is another.
pub fn drive_lanes(
    method: Method,
    models: [&Model; LANES],
    ys: &mut [Vec<f64>; LANES],
    cfg: &DriveConfig,
    observers: [&mut dyn Observer; LANES],
) -> Option<[Result<Stats, SimError>; LANES]> {
    let chain = LaneChain::of(&models)?;
    let StepControl::Fixed { dt } = cfg.control else {
        return None;
    };
    let exact = match method {
        Method::Rkn6Contact => false,
        Method::Erkn6Contact => true,
        _ => return None,
    };
    if let Err(e) = validate(cfg) {
        return Some(std::array::from_fn(|_| Err(e.clone())));
    }
    let mut batch = LaneBatch::new(LaneRkn6::new(chain, &models, exact), &models, ys);
    let mut runs: [Option<Stepping<'_>>; LANES] = std::array::from_fn(|_| None);
    let mut results: [Option<Result<Stats, SimError>>; LANES] = std::array::from_fn(|_| None);
    for l in 0..LANES {
        let start = Stepping::start(models[l], cfg, &ys[l], (super::S, dt), &mut *observers[l]);
        match start {
            Ok(run) => runs[l] = Some(run),
            Err(e) => batch.stop(l, &mut results, e),
        }
    }
    let n_intervals = intervals(cfg.t_end, cfg.sample_every);
    for k in 1..=n_intervals {
        let target = sample_time(cfg, k, n_intervals);
        batch.cover((&mut runs, &mut results), (target, dt), &observers);
        for l in 0..LANES {
            let Some(run) = runs[l].as_mut() else {
                continue;
            };
            batch.lane_state(l, &mut ys[l]);
            if let Err(e) = run.sample(&ys[l], &mut *observers[l]) {
                runs[l] = None;
                batch.stop(l, &mut results, e);
            }
        }
    }
    for l in 0..LANES {
        if let Some(mut run) = runs[l].take() {
            run.stats.rhs_evals = batch.stepper.evals[l];
            results[l] = Some(Ok(run.stats));
        }
    }
    Some(results.map(|r| r.expect("every lane ends with a result")))
}

/// Each lane's run under way and, once it has ended, its outcome.
type LaneRuns<'a, 's> = (
    &'a mut [Option<Stepping<'s>>; LANES],
    &'a mut [Option<Result<Stats, SimError>>; LANES],
);

/// The lanes' shared state and stepper.
struct LaneBatch<'m> {
    models: [&'m Model; LANES],
    stepper: LaneRkn6,
    q: Vec<Lanes>,
    v: Vec<Lanes>,
}

impl<'m> LaneBatch<'m> {
    /// The lanes of `stepper` at the states `ys` (one per lane, `[q, q']`).
    fn new(stepper: LaneRkn6, models: &[&'m Model; LANES], ys: &[Vec<f64>; LANES]) -> Self {
        let n = stepper.chain.n_dof();
        let q = (0..n).map(|k| std::array::from_fn(|l| ys[l][k])).collect();
        let v = (0..n)
            .map(|k| std::array::from_fn(|l| ys[l][n + k]))
            .collect();
        LaneBatch {
            models: *models,
            stepper,
            q,
            v,
        }
    }

    /// Stops lane `l` (whose run the caller has dropped) with `error`: its state and its
    /// stepper's forces are set to rest, so that it costs nothing more (no drift into huge or
    /// subnormal values).
    fn stop(
        &mut self,
        l: usize,
        results: &mut [Option<Result<Stats, SimError>>; LANES],
        error: SimError,
    ) {
        results[l] = Some(Err(error));
        for x in self.q.iter_mut().chain(self.v.iter_mut()) {
            x[l] = 0.0;
        }
        self.stepper.retire(l);
    }

    /// Lane `l`'s state, `[q, q']`, into `y`.
    fn lane_state(&self, l: usize, y: &mut [f64]) {
        let n = self.q.len();
        for k in 0..n {
            y[k] = self.q[k][l];
            y[n + k] = self.v[k][l];
        }
    }

    /// Advances every live lane to `target` by equal steps of at most `dt` (the same for all
    /// lanes: they started together and take the same tiling), each lane asking its observer
    /// now and then whether to stop ([`Stepping::poll`]).
    fn cover(
        &mut self,
        (runs, results): LaneRuns<'_, '_>,
        (target, dt): (f64, f64),
        observers: &[&mut dyn Observer; LANES],
    ) {
        let Some(lead) = runs.iter().flatten().next() else {
            return;
        };
        let (n_steps, h_eq) = lead.tiling(target, dt);
        for i in 0..n_steps {
            let mut windows = [None; LANES];
            for (l, run) in runs.iter_mut().enumerate() {
                if let Some(run) = run {
                    let window = run.active.window();
                    run.stats.site_steps += window.len() as u64;
                    windows[l] = Some(window);
                }
            }
            let Some(union) = union(&windows) else { return };
            let live = windows.map(|w| w.is_some());
            self.stepper.step(
                &self.models,
                (&mut self.q, &mut self.v),
                h_eq,
                (union, live),
            );
            let sums = self.finite_sums(union);
            for l in 0..LANES {
                let (Some(run), Some(window)) = (runs[l].as_mut(), windows[l]) else {
                    continue;
                };
                let (q, v) = (&self.q, &self.v);
                run.active
                    .update_by(window, |k| q[k][l] != 0.0 || v[k][l] != 0.0);
                let counted = run.count_fixed_step(i + 1 == n_steps, target, h_eq);
                let checked = counted
                    .and_then(|()| self.check_finite(l, sums[l], (run.t(), window)))
                    .and_then(|()| run.poll(&*observers[l]));
                if let Err(e) = checked {
                    runs[l] = None;
                    self.stop(l, results, e);
                }
            }
        }
    }

    /// Per lane, the sum of x − x over the state on `union`: 0 exactly when every entry is
    /// finite (one pass for all lanes, as [`check_finite_in`] makes for one).
    #[allow(clippy::eq_op)] // x - x is the point: it is NaN exactly when x is not finite
    fn finite_sums(&self, union: Window) -> Lanes {
        let n_sites = self.stepper.chain.n_sites;
        let mut sum = ZERO;
        for r in [union.lo..union.hi + 1, n_sites..self.q.len()] {
            for x in self.q[r.clone()].iter().chain(&self.v[r]) {
                sum = sum.zip(*x, |s, x| s + (x - x));
            }
        }
        sum
    }

    /// Lane `l`'s failure when its `sum` ([`LaneBatch::finite_sums`]) says a value is not
    /// finite: the scalar run's error at time `t` on its `window`, from [`check_finite_in`].
    fn check_finite(&self, l: usize, sum: f64, (t, window): (f64, Window)) -> Result<(), SimError> {
        if sum == 0.0 {
            return Ok(());
        }
        let model = self.models[l];
        let mut y = vec![0.0; model.state_len()];
        self.lane_state(l, &mut y);
        check_finite_in(&y, t, &window.state_ranges(model))
    }
}

/// The smallest window that holds every lane's (`None` when no lane runs).
fn union(windows: &[Option<Window>; LANES]) -> Option<Window> {
    windows.iter().flatten().copied().reduce(|a, b| Window {
        lo: a.lo.min(b.lo),
        hi: a.hi.max(b.hi),
    })
}
