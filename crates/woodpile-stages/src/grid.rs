//! The grids of scenes a kind declares, in a stage file's terms: a sweep's `[axes]`, as
//! `woodpile_scene::grid` defines them (axes, ranges rounded to 12 significant digits, the
//! product's order), and an embedded scene's errors, each naming the stage file and the dotted
//! key.

use std::path::Path;

use woodpile_pipeline::fields::Fields;
use woodpile_pipeline::PipelineError;
pub use woodpile_scene::grid::{point, point_count, Axis, AxisValue, MAX_POINTS, RESERVED};
use woodpile_scene::SceneError;

/// Parses the `[axes]` table.
pub fn parse_axes(mut fields: Fields<'_>) -> Result<Vec<Axis>, PipelineError> {
    let mut table = toml::Table::new();
    for key in fields.keys() {
        if let Some(value) = fields.take(&key) {
            table.insert(key, value);
        }
    }
    woodpile_scene::grid::parse_axes(table).map_err(|(key, reason)| {
        if key.is_empty() {
            fields.error_here(reason)
        } else {
            fields.error(&key, reason)
        }
    })
}

/// A scene embedded in stage `file` under key `prefix` (`scene`, `scene[2]`) that
/// woodpile-scene rejects: the scene's own key is appended to the prefix, and `context` (say,
/// the grid point) to the reason. One mapping for every kind that embeds scenes.
pub fn scene_error(file: &Path, prefix: &str, e: SceneError, context: &str) -> PipelineError {
    let (key, reason) = match &e {
        SceneError::Invalid { key, reason, .. } => (format!("{prefix}.{key}"), reason.clone()),
        SceneError::Syntax { reason, .. } | SceneError::Read { reason, .. } => {
            (prefix.to_string(), reason.clone())
        }
    };
    PipelineError::Definition {
        file: file.to_path_buf(),
        key,
        reason: reason + context,
        source: Some(Box::new(e)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes(text: &str) -> Result<Vec<Axis>, PipelineError> {
        let table: toml::Table = toml::from_str(text).unwrap();
        parse_axes(Fields::new(Path::new("s.toml"), "axes", table))
    }

    #[test]
    fn errors_name_the_file_and_the_dotted_key() {
        let msg = |t: &str| axes(t).unwrap_err().to_string();
        assert!(msg("eps = { from = 0.1, to = 1.05, step = 0.1 }")
            .contains("s.toml: key `axes.eps.to`"));
        assert!(msg("eps = { from = 1, to = 2, step = 1, by = 3 }").contains("axes.eps.by"));
        assert!(msg("t = [1.0]").contains("axes.t"));
        assert!(msg("a = [1, 2]\nb = { from = 1, to = 1000000, step = 1 }").contains("key `axes`"));
        assert_eq!(axes("eps = [0.5, 1]").unwrap()[0].values.len(), 2);
    }
}
