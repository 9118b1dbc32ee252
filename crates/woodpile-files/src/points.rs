//! The point directory of a results tree, as the engine sees it: a place where points live,
//! and what a set of them reports. What a point holds, and how a scene becomes one, is
//! `woodpile_points`'.

use std::path::{Path, PathBuf};

use crate::atomic;
use crate::key::Key;

/// The directory of point files: one file per point, named by its key.
#[derive(Debug, Clone)]
pub struct PointsDir {
    dir: PathBuf,
}

impl PointsDir {
    /// The points rooted at `dir` (created on first write).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The root directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Where the point `key` lives: two-hex-digit fan-out keeps directories small.
    pub fn path(&self, key: &Key) -> PathBuf {
        self.dir
            .join(&key.as_str()[..2])
            .join(format!("{key}.wppt"))
    }

    /// Removes leftovers of killed writers from every fan-out directory; returns how many.
    pub fn sweep_stale_temps(&self) -> usize {
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return 0;
        };
        entries
            .flatten()
            .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
            .map(|e| atomic::sweep_stale_temps(&e.path()))
            .sum()
    }
}

/// Facts about a set of simulated points that combine exactly across shards (counts, sums of
/// integers, maxima), so a merged sweep reports what a single run would.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PointStats {
    /// Points.
    pub points: usize,
    /// Of which failed.
    pub failed: usize,
    /// Scenes this run simulated (the others came from the cache).
    #[serde(default)]
    pub simulated: usize,
    /// Right-hand-side evaluations of all successful points.
    pub rhs_evals: u64,
    /// Largest `auto` error estimate.
    pub max_error_estimate: Option<f64>,
    /// Largest relative energy drift.
    pub max_energy_drift: Option<f64>,
}

impl PointStats {
    /// Only a count of scenes simulated: what a kind that simulates outside a grid (a map, a
    /// survey, an optimiser) reports.
    pub fn simulated(count: usize) -> Self {
        Self {
            simulated: count,
            ..Self::default()
        }
    }

    /// The statistics of the union of two disjoint point sets.
    pub fn merge(self, other: PointStats) -> PointStats {
        let max = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(x), Some(y)) => Some(x.max(y)),
            (x, y) => x.or(y),
        };
        PointStats {
            points: self.points + other.points,
            failed: self.failed + other.failed,
            simulated: self.simulated + other.simulated,
            rhs_evals: self.rhs_evals + other.rhs_evals,
            max_error_estimate: max(self.max_error_estimate, other.max_error_estimate),
            max_energy_drift: max(self.max_energy_drift, other.max_energy_drift),
        }
    }
}
