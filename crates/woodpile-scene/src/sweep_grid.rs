//! A grid of scenes: a scene template with `$axis` placeholders over its axes. The one type
//! behind a sweep stage (and the kinds built on it) and Python's `sweep`, so that both make
//! the same scene at every point, check the same corners and refuse the same memory; each
//! edge words the errors ([`GridError`]) in its own way.

use std::path::{Path, PathBuf};

use crate::grid::{at_point, check_sweep_memory, point, point_count, Axis, AxisValue};
use crate::template::Template;
use crate::{Scene, SceneError};

/// Why a grid, or one of its points, cannot be made.
#[derive(Debug)]
pub enum GridError {
    /// A placeholder could not be filled in at a point: the template's key (as a stage file
    /// writes it, `scene.defect.0.eps`) and the reason, which ends with the point's values.
    Template {
        /// The key.
        key: String,
        /// The reason, with ` (at eps = 1, L = 2)`.
        reason: String,
    },
    /// The scene at a point is refused.
    Scene {
        /// Why.
        error: SceneError,
        /// ` (at eps = 1, L = 2)`.
        at: String,
    },
    /// The whole grid would not fit in memory: the reason, with the estimate.
    Memory(String),
}

/// A scene template over its axes.
#[derive(Debug, Clone)]
pub struct SceneGrid {
    /// The axes (the last varies fastest).
    pub axes: Vec<Axis>,
    template: Template,
    /// What the scenes are named in messages (a stage file, or Python's `<dict>`).
    file: PathBuf,
}

impl SceneGrid {
    /// The grid of `template` over `axes`, its scenes named `file` in messages; checked at
    /// its corners (the extremes of every axis, so that a bad template fails now rather than
    /// mid-sweep) and for the memory its points will hold (its last point's scene is the
    /// largest). Returns the grid and its first scene.
    pub fn checked(
        axes: Vec<Axis>,
        template: Template,
        file: &Path,
    ) -> Result<(SceneGrid, Scene), GridError> {
        let grid = SceneGrid {
            axes,
            template,
            file: file.to_path_buf(),
        };
        let first = grid.scene_at(0)?;
        let last = grid.scene_at(grid.count() - 1)?;
        check_sweep_memory(grid.count(), &last).map_err(GridError::Memory)?;
        Ok((grid, first))
    }

    /// Number of grid points.
    pub fn count(&self) -> usize {
        point_count(&self.axes)
    }

    /// The axis values of point `index`.
    pub fn values(&self, index: usize) -> Vec<AxisValue> {
        point(&self.axes, index)
    }

    /// ` (at eps = 1, L = 2)` for messages about the point at `values`.
    pub fn at(&self, values: &[AxisValue]) -> String {
        at_point(&self.axes, values)
    }

    /// What its scenes are named in messages.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// The template.
    pub fn template(&self) -> &Template {
        &self.template
    }

    /// The validated scene of point `index`.
    pub fn scene_at(&self, index: usize) -> Result<Scene, GridError> {
        self.scene_with(&self.values(index), None)
    }

    /// The validated scene at arbitrary axis `values` (one per axis, in order), optionally
    /// with `run.tolerance` replaced (an optimiser's refinement runs between grid points,
    /// tighter).
    pub fn scene_with(
        &self,
        values: &[AxisValue],
        tolerance: Option<f64>,
    ) -> Result<Scene, GridError> {
        let table = self.table_with(values, tolerance)?;
        crate::from_table(table, &self.file).map_err(|error| GridError::Scene {
            error,
            at: self.at(values),
        })
    }

    /// The scene table at `values` (a scene file's content), before validation.
    pub fn table_with(
        &self,
        values: &[AxisValue],
        tolerance: Option<f64>,
    ) -> Result<toml::Table, GridError> {
        let mut table =
            self.template
                .instantiate(&self.axes, values)
                .map_err(|(key, reason)| GridError::Template {
                    key,
                    reason: reason + &self.at(values),
                })?;
        if let Some(tol) = tolerance {
            let run = table
                .entry("run")
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            if let toml::Value::Table(run) = run {
                run.insert("tolerance".into(), toml::Value::Float(tol));
            }
        }
        Ok(table)
    }
}
