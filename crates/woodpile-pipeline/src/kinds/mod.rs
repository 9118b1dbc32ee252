//! The stage kinds, one module each: its parameters (`parse`), its documentation (the
//! reference in `docs/stage-kinds.md` is generated from each module's first comment) and its
//! `impl Kind`. Everything they share (the DAG, keys, the point cache, tables, status) is the
//! engine, in the crate root; `crate::kind::KINDS` lists them.

pub mod approximate;
pub mod design;
pub mod fit;
pub mod optimize;
pub mod reduce;
pub mod render;
pub mod report;
pub mod spacetime;
pub mod stability;
pub mod sweep;
pub mod workprecision;
