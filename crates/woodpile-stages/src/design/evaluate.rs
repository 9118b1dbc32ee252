//! A layout made a scene and simulated through the point cache, and its result scored.

use rayon::prelude::*;
use woodpile_scene::Scene;

use woodpile_files::Key;
use woodpile_pipeline::error::Result;
use woodpile_pipeline::events::Events;
use woodpile_pipeline::kind::PointsAt;
use woodpile_points::{point_key, PointResult, PointStore, Shares};
use woodpile_sim::integrate::lanes::LANES;

use super::space::round_sig;
use super::{Design, Evaluated, Layout, Search};
use crate::schema::Fraction;

/// `layout` with each rod's eps and kappa as its scene derived them (a layout of eps and
/// kappa as it is).
fn with_derived(layout: &Layout, scene: &Scene) -> Layout {
    let Some(physical) = &scene.physical else {
        return layout.clone();
    };
    let resonators = layout
        .resonators
        .iter()
        .map(
            |r| match (r.length, physical.defects.iter().find(|d| d.site == r.site)) {
                (Some(_), Some(derived)) => super::Resonator {
                    eps: round_sig(derived.eps),
                    kappa: round_sig(derived.kappa),
                    ..*r
                },
                _ => *r,
            },
        )
        .collect();
    Layout { resonators }
}

impl Design {
    /// The scene table of `layout` (with `run.tolerance` replaced when given).
    pub(super) fn table(&self, layout: &Layout, tolerance: Option<f64>) -> toml::Table {
        let mut table = self.template.clone();
        let defects = layout
            .resonators
            .iter()
            .map(|r| {
                let mut d = toml::Table::new();
                d.insert("site".into(), toml::Value::Integer(r.site));
                match r.length {
                    Some(length) => {
                        let mut rod = toml::Table::new();
                        rod.insert("length".into(), toml::Value::Float(length));
                        d.insert("rod".into(), toml::Value::Table(rod));
                    }
                    None => {
                        d.insert("eps".into(), toml::Value::Float(r.eps));
                        d.insert("kappa".into(), toml::Value::Float(r.kappa));
                        d.insert("p".into(), toml::Value::Integer(r.p));
                    }
                }
                d.extend(self.each_resonator.clone());
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

    pub(super) fn scene(&self, layout: &Layout, tolerance: Option<f64>) -> Result<Scene> {
        woodpile_scene::from_table(self.table(layout, tolerance), &self.file)
            .map_err(|e| crate::grid::scene_error(&self.file, "scene", e, ""))
    }

    /// The objective of a result, as a score to maximise (failures and infeasible designs
    /// score -inf, so any working design beats them).
    pub(super) fn score(&self, result: &PointResult) -> f64 {
        let Ok(data) = result else {
            return f64::NEG_INFINITY;
        };
        let series = match self.objective {
            Fraction::Reflected => &data.reflected,
            Fraction::Transmitted => &data.transmitted,
            Fraction::Trapped => &data.trapped,
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

    /// Evaluates `layouts` in parallel through `at`'s point cache, in order, four neighbours
    /// at a time (the robustness samples of one design share a chain, and take SIMD lanes).
    pub(super) fn evaluate(
        &self,
        search: Search,
        layouts: Vec<Layout>,
        tolerance: Option<f64>,
        at: PointsAt<'_>,
    ) -> Result<Vec<Evaluated>> {
        let store = &PointStore::from(at.points);
        let events = at.events;
        let groups: Vec<Vec<Evaluated>> = layouts
            .par_chunks(LANES)
            .map(|group| self.evaluate_group(search, group, tolerance, (store, events)))
            .collect::<Result<_>>()?;
        Ok(groups.into_iter().flatten().collect())
    }

    /// [`Design::evaluate`] of a few layouts, simulated together.
    fn evaluate_group(
        &self,
        search: Search,
        layouts: &[Layout],
        tolerance: Option<f64>,
        (store, events): (&PointStore, &dyn Events),
    ) -> Result<Vec<Evaluated>> {
        let over_bound = |layout: &Layout| {
            let bound = self.space.max_total_eps?;
            (layout.total_eps() > bound)
                .then(|| format!("total eps {} above the bound {bound}", layout.total_eps()))
        };
        let feasible: Vec<&Layout> = layouts.iter().filter(|l| over_bound(l).is_none()).collect();
        let scenes: Vec<Scene> = feasible
            .iter()
            .map(|layout| self.scene(layout, tolerance))
            .collect::<Result<_>>()?;
        let keys: Vec<Key> = scenes
            .iter()
            .map(|s| point_key(s, Shares::Energy))
            .collect();
        let points = (
            &keys.iter().collect::<Vec<_>>()[..],
            &scenes.iter().collect::<Vec<_>>()[..],
        );
        let fetched = store.get_or_simulate_all(points, Shares::Energy)?;
        let mut simulated = keys.into_iter().zip(fetched).zip(&scenes);
        let evaluated = layouts.iter().map(|layout| {
            if let Some(reason) = over_bound(layout) {
                return Evaluated {
                    search,
                    layout: layout.clone(),
                    result: Err(reason),
                    score: f64::NEG_INFINITY,
                    key: String::new(),
                    simulated: false,
                };
            }
            let ((key, fetched), scene) = simulated.next().expect("a result per feasible layout");
            events.point_done();
            let score = self.score(&fetched.result);
            Evaluated {
                search,
                layout: with_derived(layout, scene),
                result: fetched.result,
                score,
                key: key.to_string(),
                simulated: fetched.simulated,
            }
        });
        Ok(evaluated.collect())
    }
}
