//! The columns of a sweep's table: one row per sample of each point (or one row with the
//! reason for a point that failed), after the point's axis values under the axes' names. Named
//! here, beside the grid, so that no axis can take a column's name
//! ([`crate::grid::RESERVED`]), and written by `woodpile_points::rows` and Python's module.
//! The shares' names are [`Share`]'s.

use woodpile_sim::Share;

/// The point's index in the grid.
pub const POINT: &str = "point";
/// The sample time.
pub const TIME: &str = "t";
/// The reflected share R.
pub const REFLECTED: &str = Share::Reflected.name();
/// The transmitted share T.
pub const TRANSMITTED: &str = Share::Transmitted.name();
/// The trapped share E_tr.
pub const TRAPPED: &str = Share::Trapped.name();
/// The striker's share S (only in sweeps whose scenes have a `[striker]`).
pub const STRIKER: &str = Share::Striker.name();
/// The dissipated share D (sweeps of scenes with damping).
pub const DISSIPATED: &str = Share::Dissipated.name();
/// The total energy (or, for a kinetic series, the kinetic share of the impact energy).
pub const ENERGY: &str = "E";
/// The method of the reported run.
pub const METHOD: &str = "method";
/// Its fixed step, if any.
pub const DT: &str = "dt";
/// Its steps.
pub const STEPS: &str = "steps";
/// `auto`'s error estimate.
pub const ERROR_ESTIMATE: &str = "error_estimate";
/// The largest relative energy drift.
pub const ENERGY_DRIFT: &str = "energy_drift";
/// When the wave first reached an end of the chain (null: not before t_end).
pub const END_REACHED_AT: &str = "end_reached_at";
/// Why the point failed (null when it did not).
pub const FAILURE: &str = "failure";
/// The point's cache key.
pub const SCENE_KEY: &str = "scene_key";
