//! [`simulate`](super::simulate) of many scenes, four at a time in lanes where they allow it: `auto`'s first
//! pair of runs (2 dt, then dt) made for four scenes together
//! ([`crate::integrate::lanes`]), then each later rung's fine run made for four ladders at the
//! same step together, whichever scenes of the batch they verify. Every result is its scene's
//! [`simulate`](super::simulate) result bit for bit; only the time differs.
//!
//! Four scenes take lanes together when each asks for `auto`, plans the same method
//! (`rkn6-contact`, or `erkn6-contact` for light harmonic resonators) at the same first step,
//! runs for as long with the same samples, and all share a chain that takes lanes
//! ([`crate::integrate::lanes::takes_lanes`]). A sweep's neighbouring points mostly do; any
//! other group runs scene by scene. The ladders that need another rung wait for three others
//! at their step: a sweep's points that need a third run cluster (the F7 grids' light
//! resonators near ω = 1.5), so most of those runs take lanes too; the few left over run alone.

use super::ladder::{FirstPair, Ladder};
use super::{
    auto_first_step, budget, check_shares, outcome_of, simulate_unchecked, Outcome, Scenario,
};
use crate::energy::total_energy;
use crate::error::SimError;
use crate::integrate::lanes::{drive_lanes, enabled, shares_a_chain, LANES};
use crate::integrate::{
    CancelOnly, MethodChoice, Observer, Plan, AUTO_METHOD, BLOW_UP_DRIFT, HARMONIC_AUTO_METHOD,
};

/// How many of `n` scenes to hand [`simulate_batch`] at a time: whole groups of four, up to
/// sixteen groups, so that the ladders needing a later rung find three others at their step
/// (on F7's grids one in five or six of the points need one); but no more than leaves about
/// 32 batches, so that the cores finish together. A stopped run loses the batches under way.
pub fn batch_size(n: usize) -> usize {
    LANES * (n / (32 * LANES)).clamp(1, 16)
}

/// Simulates each of `scenarios` as [`simulate`](super::simulate) does, showing the samples of each one's
/// reported run to its own of `observers` (as many), with groups of four consecutive scenes
/// that allow it stepped together in lanes, and their ladders' later rungs four at a time.
pub fn simulate_batch<O: Observer>(
    scenarios: &[&Scenario],
    observers: &mut [O],
) -> Vec<Result<Outcome, SimError>> {
    assert_eq!(
        scenarios.len(),
        observers.len(),
        "one observer per scenario"
    );
    let mut results: Vec<Option<Result<Outcome, SimError>>> =
        scenarios.iter().map(|_| None).collect();
    let mut waiting = first_rungs(scenarios, observers, &mut results);
    while !waiting.is_empty() {
        waiting = next_rungs(waiting, observers, &mut results);
    }
    results
        .into_iter()
        .zip(scenarios)
        .map(|(r, s)| {
            r.expect("every scene ends with a result")
                .and_then(|out| check_shares(s, out))
        })
        .collect()
}

/// The first rung of each of `scenarios` (shown to `observers[k]`): each group of four that
/// can take lanes makes its first pairs there and judges them, any other scene runs
/// [`simulate`](super::simulate) whole. Each scene's result goes to `results[k]`; returns the ladders that go on.
fn first_rungs<'s, O: Observer>(
    scenarios: &[&'s Scenario],
    observers: &mut [O],
    results: &mut [Option<Result<Outcome, SimError>>],
) -> Vec<(usize, Ladder<'s>)> {
    let mut waiting = Vec::new();
    for start in (0..scenarios.len()).step_by(LANES) {
        let end = (start + LANES).min(scenarios.len());
        let group = &scenarios[start..end];
        let pairs = match (
            <&[&Scenario; LANES]>::try_from(group),
            <&mut [O; LANES]>::try_from(&mut observers[start..end]),
        ) {
            (Ok(group), Ok(observers)) => first_pairs(group, observers),
            _ => None,
        };
        let Some((plan, pairs)) = pairs else {
            for k in start..end {
                results[k] = Some(simulate_unchecked(scenarios[k], &mut observers[k]));
            }
            continue;
        };
        for (k, pair) in (start..end).zip(pairs) {
            let observer = &mut observers[k];
            let judged =
                Ladder::start(scenarios[k], plan, observer, Some(pair)).map(|mut ladder| {
                    let fine = ladder.fine_run(observer);
                    (ladder.judge(fine, observer), ladder)
                });
            match judged {
                Err(e) => results[k] = Some(Err(e)),
                Ok((Some(done), _)) => results[k] = Some(done),
                Ok((None, ladder)) => waiting.push((k, ladder)),
            }
        }
    }
    waiting
}

/// One more rung of each of the `waiting` ladders (of scene `k`, shown to `observers[k]`):
/// the fine runs of four ladders at one step and plan in lanes, the rest alone. Each
/// ladder's result goes to `results[k]`; returns the ladders that go on.
fn next_rungs<'s, O: Observer>(
    waiting: Vec<(usize, Ladder<'s>)>,
    observers: &mut [O],
    results: &mut [Option<Result<Outcome, SimError>>],
) -> Vec<(usize, Ladder<'s>)> {
    // Grouped by plan alone: four ladders on different chains fill a group that then runs
    // alone (a sweep's ladders share one chain).
    let mut open: Vec<Vec<(usize, Ladder<'s>)>> = Vec::new();
    let mut full = Vec::new();
    for (k, ladder) in waiting {
        let plan = ladder.next_plan();
        match open.iter().position(|g| g[0].1.next_plan() == plan) {
            Some(i) => {
                open[i].push((k, ladder));
                if open[i].len() == LANES {
                    full.push(open.swap_remove(i));
                }
            }
            None => open.push(vec![(k, ladder)]),
        }
    }
    let mut going_on = Vec::new();
    let mut judge =
        |k: usize, mut ladder: Ladder<'s>, fine, observer: &O| match ladder.judge(fine, observer) {
            Some(done) => results[k] = Some(done),
            None => going_on.push((k, ladder)),
        };
    for group in full {
        let group: [(usize, Ladder<'s>); LANES] = match group.try_into() {
            Ok(group) => group,
            Err(_) => unreachable!("a full group has four ladders"),
        };
        let scenes = group.each_ref().map(|(_, ladder)| ladder.scenario());
        let plan = group[0].1.next_plan();
        let dt = plan.dt().expect("a ladder's runs have a fixed step");
        let lanes = LaneGroup::with(&scenes, plan, dt).filter(|_| enabled());
        let Ok(mut shown) = observers.get_disjoint_mut(group.each_ref().map(|(k, _)| *k)) else {
            unreachable!("a ladder per scene");
        };
        match lanes {
            Some(lanes) => {
                shown.iter_mut().for_each(|o| o.reset());
                let runs = lanes.run(&plan, shown.each_mut().map(|o| *o as &mut dyn Observer));
                for (((k, ladder), fine), observer) in group.into_iter().zip(runs).zip(shown) {
                    judge(k, ladder, fine, observer);
                }
            }
            None => {
                for ((k, mut ladder), observer) in group.into_iter().zip(shown) {
                    let fine = ladder.fine_run(observer);
                    judge(k, ladder, fine, observer);
                }
            }
        }
    }
    for (k, mut ladder) in open.into_iter().flatten() {
        let fine = ladder.fine_run(&mut observers[k]);
        judge(k, ladder, fine, &observers[k]);
    }
    going_on
}

/// Four scenes that can take lanes, their shared plan and first step, and their initial
/// states; `None` when they cannot.
struct LaneGroup<'s> {
    scenarios: &'s [&'s Scenario; LANES],
    plan: Plan,
    dt: f64,
    starts: [(Vec<f64>, f64); LANES],
}

impl<'s> LaneGroup<'s> {
    /// Four scenes whose ladders start alike: the same plan at the same first step.
    fn of(scenarios: &'s [&'s Scenario; LANES]) -> Option<Self> {
        let plan_of = |s: &Scenario| {
            let auto = s.method == MethodChoice::Auto;
            let plan = Plan::choose(&s.model, s.method, s.accuracy).ok()?;
            let method = plan.method == AUTO_METHOD || plan.method == HARMONIC_AUTO_METHOD;
            // A zero impulse (even -0.0) leaves its lane at rest, where the scalar run never
            // writes its struck site's velocity and the lanes would write +0.0 over it.
            let struck = s.impulse_velocity != 0.0;
            (auto && method && struck && budget::check(s).is_ok()).then_some(plan)
        };
        let first = scenarios[0];
        let plan = plan_of(first)?;
        let dt = auto_first_step(first, &plan);
        let alike = |s: &&Scenario| plan_of(s) == Some(plan) && auto_first_step(s, &plan) == dt;
        if !scenarios.iter().all(alike) {
            return None;
        }
        Self::with(scenarios, plan, dt)
    }

    /// Four scenes to be run by `plan` (at step `dt`) together: `None` unless they run for as
    /// long with the same samples and share a chain. The caller has checked the rest of what
    /// [`LaneGroup::of`] checks (`auto`, its method, a nonzero impulse, the budget): a later
    /// rung's ladders all started in a group that passed it.
    fn with(scenarios: &'s [&'s Scenario; LANES], plan: Plan, dt: f64) -> Option<Self> {
        let first = scenarios[0];
        let alike = |s: &&Scenario| s.t_end == first.t_end && s.sample_every == first.sample_every;
        if !scenarios.iter().all(alike) || !shares_a_chain(&scenarios.map(|s| &s.model)) {
            return None;
        }
        let start = |s: &Scenario| {
            let mut y = s.model.rest_state();
            s.model
                .apply_impulse(&mut y, s.impulse_site, s.impulse_velocity)
                .ok()?;
            let e_initial = total_energy(&s.model, 0.0, &y);
            Some((y, e_initial))
        };
        let starts: Vec<(Vec<f64>, f64)> =
            scenarios.iter().map(|s| start(s)).collect::<Option<_>>()?;
        Some(LaneGroup {
            scenarios,
            plan,
            dt,
            starts: starts.try_into().ok()?,
        })
    }

    /// The four scenes' runs by `plan`, each sample shown to its lane's observer.
    fn run(
        &self,
        plan: &Plan,
        observers: [&mut dyn Observer; LANES],
    ) -> [Result<Outcome, SimError>; LANES] {
        let first = self.scenarios[0];
        let cfg = plan.drive_config((first.t_end, first.sample_every), true);
        let mut ys = self.starts.clone().map(|(y, _)| y);
        let models = self.scenarios.map(|s| &s.model);
        let stats = drive_lanes(plan.method, models, &mut ys, &cfg, observers)
            .expect("a lane group shares a chain and a fixed step");
        let mut outcomes = stats
            .into_iter()
            .zip(ys)
            .enumerate()
            .map(|(l, (stats, y))| {
                let start = (y, self.starts[l].1);
                stats.map(|stats| outcome_of(self.scenarios[l], plan, start, stats))
            });
        std::array::from_fn(|_| outcomes.next().expect("one outcome per lane"))
    }
}

/// The first pairs of `auto`'s ladders on four scenes, made in lanes, with the plan they
/// share; `None` when the scenes cannot take lanes.
fn first_pairs<O: Observer>(
    scenarios: &[&Scenario; LANES],
    observers: &mut [O; LANES],
) -> Option<(Plan, [FirstPair; LANES])> {
    let group = LaneGroup::of(scenarios).filter(|_| enabled())?;
    // The ladder's first pair, as `Ladder::start` and its first rung make it: verification
    // runs are guarded against blow-up only.
    let guarded = Plan {
        drift_limit: BLOW_UP_DRIFT,
        ..group.plan
    };
    let mut cancel_only = observers.each_ref().map(CancelOnly);
    let coarse = group.run(
        &guarded.with_dt(2.0 * group.dt),
        cancel_only.each_mut().map(|o| o as &mut dyn Observer),
    );
    // A lane whose coarse run failed for good (not by blowing up) ends there, as its ladder
    // would before making the fine run: its observer sees no more.
    let mut each = observers.iter_mut();
    let mut shown: [FineObserver<'_, O>; LANES] = std::array::from_fn(|l| {
        let observer = each.next().expect("an observer per lane");
        match &coarse[l] {
            Err(e) if !blew_up(e) => FineObserver::Hidden(observer),
            _ => {
                observer.reset();
                FineObserver::Shown(observer)
            }
        }
    });
    let fine = group.run(
        &guarded.with_dt(group.dt),
        shown.each_mut().map(|o| o as &mut dyn Observer),
    );
    let mut pairs = coarse.into_iter().zip(fine);
    Some((
        group.plan,
        std::array::from_fn(|_| {
            let (coarse, fine) = pairs.next().expect("a pair per lane");
            FirstPair { coarse, fine }
        }),
    ))
}

/// Whether a run failed by blowing up or losing its energy: a step too coarse, which the
/// ladder halves, rather than a failure of the scene.
fn blew_up(e: &SimError) -> bool {
    matches!(e, SimError::NonFinite { .. } | SimError::EnergyDrift { .. })
}

/// A lane's observer of the fine run: its own, or, for a lane whose ladder ended at its
/// coarse run, one that records nothing (and still passes on a wish to stop).
enum FineObserver<'a, O> {
    Shown(&'a mut O),
    Hidden(&'a O),
}

impl<O: Observer> Observer for FineObserver<'_, O> {
    fn observe(&mut self, model: &crate::model::Model, t: f64, y: &[f64]) {
        if let FineObserver::Shown(o) = self {
            o.observe(model, t, y);
        }
    }
    fn reset(&mut self) {
        if let FineObserver::Shown(o) = self {
            o.reset();
        }
    }
    fn cancelled(&self) -> bool {
        match self {
            FineObserver::Shown(o) => o.cancelled(),
            FineObserver::Hidden(o) => o.cancelled(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{paper_scene, tolerance, PaperDefect, THIRD_RUN_POINTS};

    /// Neighbouring F7 points take lanes; a point of another chain keeps its group out.
    #[test]
    fn neighbouring_sweep_points_form_a_lane_group() {
        let scene = |eps1: f64, site: i64| {
            let defects = [
                PaperDefect::linear(0, eps1, 1.0),
                PaperDefect::linear(site, 7.0, 1.0),
            ];
            paper_scene(&defects, MethodChoice::Auto, tolerance(1e-5))
        };
        let scenes: Vec<Scenario> = (0..LANES).map(|k| scene(3.0 + k as f64, 20)).collect();
        let group: [&Scenario; LANES] = std::array::from_fn(|l| &scenes[l]);
        assert!(LaneGroup::of(&group).is_some());
        let other = scene(4.0, 21);
        let mixed: [&Scenario; LANES] = [&scenes[0], &scenes[1], &other, &scenes[3]];
        assert!(LaneGroup::of(&mixed).is_none());
    }

    /// The F7 fine points whose first pairs do not pass, from two groups of four, wait for
    /// their third run at one plan and form a lane group for it (`tests/lanes.rs` holds their
    /// results to `simulate` alone).
    #[test]
    fn waiting_ladders_from_two_groups_form_a_lane_group() {
        let scene = |(eps1, eps2): (f64, f64)| {
            let defects = [
                PaperDefect::linear(0, eps1, 1.0),
                PaperDefect::linear(20, eps2, 1.0),
            ];
            paper_scene(&defects, MethodChoice::Auto, tolerance(1e-5))
        };
        let scenes: Vec<Scenario> = THIRD_RUN_POINTS.into_iter().map(scene).collect();
        let refs: Vec<&Scenario> = scenes.iter().collect();
        let mut observers = vec![(); scenes.len()];
        let mut results: Vec<Option<Result<Outcome, SimError>>> = vec![None; scenes.len()];
        let waiting = first_rungs(&refs, &mut observers, &mut results);
        let waiting_at: Vec<usize> = waiting.iter().map(|(k, _)| *k).collect();
        assert_eq!(waiting_at, [0, 2, 4, 6, 7]);
        let plan = waiting[0].1.next_plan();
        assert!(waiting.iter().all(|(_, ladder)| ladder.next_plan() == plan));
        let four: [&Scenario; LANES] = std::array::from_fn(|l| waiting[l].1.scenario());
        assert!(LaneGroup::with(&four, plan, plan.dt().unwrap()).is_some());
    }
}
