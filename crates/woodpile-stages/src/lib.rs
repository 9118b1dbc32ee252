//! The stage kinds of the figure pipeline, one module each: its parameters (`parse`), its
//! documentation (`docs/stage-kinds.md` is generated from each module's first comment) and its
//! `impl Kind`. The engine (`woodpile-pipeline`: the DAG, keys, status, runs, the point cache,
//! tables) knows none of them: it is handed [`KINDS`].
//!
//! A new kind is one module here and one line in [`KINDS`]: docs/adding-a-kind.md walks through
//! one.
#![warn(missing_docs)]

use std::sync::Arc;

use woodpile_pipeline::kind::Registry;

pub mod approximate;
pub mod calibrate;
pub mod design;
pub mod fit;
pub mod grid;
pub mod optimize;
pub mod reduce;
pub mod render;
pub mod report;
#[cfg(feature = "testing")]
pub mod sampling;
pub mod schema;
pub mod spacetime;
pub mod spectrum;
pub mod stability;
pub mod sweep;
pub mod table;
mod table_units;
pub mod vary;
pub mod workprecision;

/// Every kind, in pipeline order: its name in stage files, and its parser.
pub static KINDS: &Registry = &[
    ("sweep", |f, _| Ok(Arc::new(sweep::Sweep::parse_stage(f)?))),
    ("spacetime", |f, _| {
        Ok(Arc::new(spacetime::SpaceTime::parse(f)?))
    }),
    ("reduce", |f, _| Ok(Arc::new(reduce::Reduce::parse(f)?))),
    ("optimize", |f, _| {
        Ok(Arc::new(optimize::Optimize::parse(f)?))
    }),
    ("fit", |f, _| Ok(Arc::new(fit::FitStage::parse(f)?))),
    ("approximate", |f, _| {
        Ok(Arc::new(approximate::Approximate::parse(f)?))
    }),
    ("render", |f, i| Ok(Arc::new(render::Render::parse(f, i)?))),
    ("report", |f, _| Ok(Arc::new(report::Report::parse(f)?))),
    ("workprecision", |f, _| {
        Ok(Arc::new(workprecision::WorkPrecision::parse(f)?))
    }),
    ("stability", |f, _| {
        Ok(Arc::new(stability::Stability::parse(f)?))
    }),
    ("design", |f, _| Ok(Arc::new(design::Design::parse(f)?))),
    ("table", |f, _| Ok(Arc::new(table::Table::parse(f)?))),
    ("vary", |f, _| Ok(Arc::new(vary::Vary::parse(f)?))),
    ("spectrum", |f, _| {
        Ok(Arc::new(spectrum::Spectrum::parse(f)?))
    }),
    ("calibrate", |f, _| {
        Ok(Arc::new(calibrate::Calibrate::parse(f)?))
    }),
];

/// The name of every kind, in pipeline order.
pub fn names() -> impl Iterator<Item = &'static str> {
    KINDS.iter().map(|(name, _)| *name)
}
