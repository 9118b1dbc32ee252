//! `woodpile run --set STAGE.key=value`: a variant of a stage without editing its file. The
//! variant is the stage file with the keys set, loaded as a stage of its own named
//! `<stage>--<key>-<value>`: it has its own key and its own output
//! (`results/<stage>--<key>-<value>.parquet`), reads the same inputs, and leaves the stage,
//! its output and everything downstream as they were.

use std::path::Path;

use crate::error::{PipelineError, Result};
use crate::kind::Registry;
use crate::stage::Stage;

/// One `STAGE.key=value`.
#[derive(Debug, Clone, PartialEq)]
pub struct Set {
    /// The stage.
    pub stage: String,
    /// The dotted key inside its file (`at`, `scene.run.tolerance`).
    pub key: String,
    /// The value, as TOML.
    pub value: toml::Value,
}

impl Set {
    /// Parses `STAGE.key=value`; the value is TOML (`120.0`, `[1, 2]`, `"auto"`), or else a
    /// string.
    pub fn parse(text: &str) -> std::result::Result<Set, String> {
        const FORM: &str = "expected STAGE.key=value, e.g. f4_fractions.at=120.0";
        let (path, value) = text.split_once('=').ok_or(FORM)?;
        let (stage, key) = path.trim().split_once('.').ok_or(FORM)?;
        if stage.is_empty() || key.is_empty() || key.split('.').any(str::is_empty) {
            return Err(FORM.into());
        }
        let value = value.trim();
        let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(value.to_string()));
        Ok(Set {
            stage: stage.to_string(),
            key: key.to_string(),
            value: parsed,
        })
    }

    /// `key-value` in the characters a stage name allows.
    fn slug(&self) -> String {
        let value = match &self.value {
            toml::Value::String(s) => s.clone(),
            toml::Value::Float(x) => format!("{x:?}"),
            other => other.to_string(),
        };
        format!("{}-{value}", self.key)
            .chars()
            .map(|c| match c {
                'a'..='z' | '0'..='9' | '-' | '_' => c,
                'A'..='Z' => c.to_ascii_lowercase(),
                _ => '_',
            })
            .collect()
    }
}

/// The name of the variant of `stage` that `sets` (those naming it) make.
pub fn variant_name(stage: &str, sets: &[Set]) -> String {
    let slugs: Vec<String> = sets
        .iter()
        .filter(|s| s.stage == stage)
        .map(Set::slug)
        .collect();
    format!("{stage}--{}", slugs.join("--"))
}

/// The variants `sets` make of `stages`, one per stage named.
pub fn variants(
    stages: &[Stage],
    sets: &[Set],
    root: &Path,
    kinds: &'static Registry,
    defaults: &crate::stage::Defaults,
) -> Result<Vec<Stage>> {
    let mut names: Vec<&str> = sets.iter().map(|s| s.stage.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    names
        .into_iter()
        .map(|name| {
            let stage = stages.iter().find(|s| s.name == name).ok_or_else(|| {
                PipelineError::UnknownStage {
                    name: name.to_string(),
                    known: stages
                        .iter()
                        .map(|s| s.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                }
            })?;
            let mut table =
                crate::stage::parse_table(&crate::stage::read_text(&stage.file)?, &stage.file)?;
            for set in sets.iter().filter(|s| s.stage == name) {
                assign(&mut table, &set.key, set.value.clone()).map_err(|reason| {
                    PipelineError::Definition {
                        file: stage.file.clone(),
                        key: set.key.clone(),
                        reason: format!("--set {}.{}: {reason}", set.stage, set.key),
                        source: None,
                    }
                })?;
            }
            let file = stage
                .file
                .with_file_name(format!("{}.toml", variant_name(name, sets)));
            let text = toml::to_string(&table).map_err(|e| PipelineError::Syntax {
                file: file.clone(),
                reason: e.to_string(),
                source: None,
            })?;
            Stage::parse_in(&text, &file, root, kinds, defaults)
        })
        .collect()
}

/// Sets dotted `key` of `table` to `value`, creating tables on the way.
fn assign(
    table: &mut toml::Table,
    key: &str,
    value: toml::Value,
) -> std::result::Result<(), String> {
    let (head, rest) = match key.split_once('.') {
        Some((head, rest)) => (head, Some(rest)),
        None => (key, None),
    };
    match rest {
        None => {
            table.insert(head.to_string(), value);
            Ok(())
        }
        Some(rest) => {
            let entry = table
                .entry(head.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            match entry {
                toml::Value::Table(inner) => assign(inner, rest, value),
                _ => Err(format!("`{head}` is not a table")),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_parse_values_as_toml_and_name_their_variant() {
        let set = Set::parse("f4_fractions.at=120.0").unwrap();
        assert_eq!(set.value, toml::Value::Float(120.0));
        assert_eq!(
            variant_name("f4_fractions", &[set]),
            "f4_fractions--at-120_0"
        );
        let tight = Set::parse("s.scene.run.tolerance=1e-7").unwrap();
        assert_eq!(variant_name("s", &[tight]), "s--scene_run_tolerance-1e-7");
        let set = Set::parse("s.scene.run.method=rk4").unwrap();
        assert_eq!(set.value, toml::Value::String("rk4".into()));
        assert!(Set::parse("nokey=1").is_err());
        assert!(Set::parse("s.=1").is_err());
        let mut table = toml::Table::new();
        assign(&mut table, "scene.run.tolerance", toml::Value::Float(1e-6)).unwrap();
        assert_eq!(table["scene"]["run"]["tolerance"].as_float(), Some(1e-6));
        assert!(assign(&mut table, "scene.run.tolerance.x", toml::Value::Integer(1)).is_err());
    }
}
