//! One stage file: `pipeline/<figure>/<name>.toml` (any folder under `pipeline/`; the name is
//! the file stem). Top-level keys common to every kind:
//!
//! ```toml
//! kind = "sweep"               # one of KINDS (docs/stage-kinds.md lists each with its keys)
//! description = "F4: ..."      # free text, not part of the cache key
//! inputs = ["f4_sweep"]        # upstream stages (by file name), read by this one
//! ```
//!
//! The remaining keys belong to the kind (its module documents them); unknown keys anywhere
//! are errors naming the file and key.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::approximate::Approximate;
use crate::canonical::toml_to_json;
use crate::design::Design;
use crate::error::{PipelineError, Result};
use crate::fields::Fields;
use crate::fit::FitStage;
use crate::optimize::Optimize;
use crate::reduce::Reduce;
use crate::render::Render;
use crate::report::Report;
use crate::spacetime::SpaceTime;
use crate::stability::Stability;
use crate::sweep::Sweep;
use crate::workprecision::WorkPrecision;

/// The kinds of stage, in pipeline order; each is documented by its module (`src/<kind>.rs`),
/// from which `docs/stage-kinds.md` is generated (and tested current).
pub const KINDS: &[&str] = &[
    "sweep",
    "spacetime",
    "reduce",
    "optimize",
    "fit",
    "approximate",
    "render",
    "report",
    "workprecision",
    "stability",
    "design",
];

/// What a stage does, with its kind-specific parameters.
#[derive(Debug, Clone)]
pub enum Spec {
    /// Simulate a grid of scenes; output their fraction time series.
    Sweep(Sweep),
    /// Record site velocities over time for a few scenes.
    SpaceTime(SpaceTime),
    /// Read the fractions of a sweep at a time, optionally maximised over axes.
    Reduce(Reduce),
    /// Refine a grid maximum with a continuous search.
    Optimize(Optimize),
    /// Fit the paper's forms to columns of a table.
    Fit(FitStage),
    /// The product approximation of two-defect trapping from single-defect fits.
    Approximate(Approximate),
    /// Draw a table as a figure.
    Render(Render),
    /// The reproduction report: the paper's numbers against ours.
    Report(Report),
    /// Speed against accuracy for every method on a few scenes.
    WorkPrecision(WorkPrecision),
    /// Where each fixed-step method blows up or misses the tolerance.
    Stability(Stability),
    /// Search resonator layouts for the best trap (inverse design).
    Design(Design),
}

impl Spec {
    /// The kind's name.
    pub fn kind(&self) -> &'static str {
        match self {
            Spec::Sweep(_) => "sweep",
            Spec::SpaceTime(_) => "spacetime",
            Spec::Reduce(_) => "reduce",
            Spec::Optimize(_) => "optimize",
            Spec::Fit(_) => "fit",
            Spec::Approximate(_) => "approximate",
            Spec::Render(_) => "render",
            Spec::Report(_) => "report",
            Spec::WorkPrecision(_) => "workprecision",
            Spec::Stability(_) => "stability",
            Spec::Design(_) => "design",
        }
    }
}

/// A parsed stage file.
#[derive(Debug, Clone)]
pub struct Stage {
    /// The name: the file stem.
    pub name: String,
    /// The file it came from.
    pub file: PathBuf,
    /// Free text for `woodpile status` and the README.
    pub description: String,
    /// Upstream stages, in the order given.
    pub inputs: Vec<String>,
    /// What it does.
    pub spec: Spec,
    /// The file's content without `description`, as canonical JSON: what the key hashes.
    pub params: Value,
}

impl Stage {
    /// Reads and parses the stage file at `file`.
    pub fn load(file: &Path) -> Result<Stage> {
        let text = woodpile_scene::read_input(file).map_err(|e| PipelineError::Syntax {
            file: file.to_path_buf(),
            reason: format!("cannot read: {e}"),
        })?;
        Stage::parse(&text, file)
    }

    /// Parses stage TOML `text`; `file` names it (and gives the stage its name).
    pub fn parse(text: &str, file: &Path) -> Result<Stage> {
        let table: toml::Table = toml::from_str(text).map_err(|e| PipelineError::Syntax {
            file: file.to_path_buf(),
            reason: e.to_string().trim_end().to_string(),
        })?;
        let name = stage_name(file)?;
        let mut params = toml_to_json(&toml::Value::Table(table.clone()));
        if let Value::Object(map) = &mut params {
            map.remove("description");
        }
        let mut fields = Fields::new(file, "", table);
        let kind: String = fields.required("kind")?;
        let description: String = fields.optional("description")?.unwrap_or_default();
        let inputs: Vec<String> = fields.optional("inputs")?.unwrap_or_default();
        let spec = match kind.as_str() {
            "sweep" => Spec::Sweep(Sweep::parse(&mut fields)?),
            "spacetime" => Spec::SpaceTime(SpaceTime::parse(&mut fields)?),
            "reduce" => Spec::Reduce(Reduce::parse(&mut fields)?),
            "optimize" => Spec::Optimize(Optimize::parse(&mut fields)?),
            "fit" => Spec::Fit(FitStage::parse(&mut fields)?),
            "approximate" => Spec::Approximate(Approximate::parse(&mut fields)?),
            "render" => Spec::Render(Render::parse(&mut fields, &inputs)?),
            "report" => Spec::Report(Report::parse(&mut fields)?),
            "workprecision" => Spec::WorkPrecision(WorkPrecision::parse(&mut fields)?),
            "stability" => Spec::Stability(Stability::parse(&mut fields)?),
            "design" => Spec::Design(Design::parse(&mut fields)?),
            other => {
                return Err(fields.error(
                    "kind",
                    format!("unknown kind `{other}` (kinds: {})", KINDS.join(", ")),
                ))
            }
        };
        fields.finish()?;
        Ok(Stage {
            name,
            file: file.to_path_buf(),
            description,
            inputs,
            spec,
            params,
        })
    }
}

fn stage_name(file: &Path) -> Result<String> {
    let name = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ok = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' || c == '-');
    if ok {
        Ok(name)
    } else {
        Err(PipelineError::Syntax {
            file: file.to_path_buf(),
            reason: "a stage file's name must be lowercase letters, digits, `_` or `-`".into(),
        })
    }
}
