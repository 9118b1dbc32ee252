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
        Ok(Set {
            stage: stage.to_string(),
            key: key.to_string(),
            value: value_of(value.trim()),
        })
    }

    /// `key-value` in the characters a stage name allows, readable, and one to one: when the
    /// readable form loses anything (a `.`, a capital, a space, a float's point, a string that
    /// reads as a number) or is long, a hash of the exact key and value follows it, so `a.b`
    /// and `a b` never share a variant (and an output file).
    fn slug(&self) -> String {
        let (value, exact) = match &self.value {
            toml::Value::Integer(i) => (i.to_string(), true),
            toml::Value::String(s) => (s.clone(), value_of(s) == self.value),
            toml::Value::Float(x) => (format!("{x:?}"), false),
            other => (other.to_string(), false),
        };
        let raw = format!("{}-{value}", self.key);
        let readable: String = raw
            .chars()
            .map(|c| match c {
                'a'..='z' | '0'..='9' | '-' | '_' => c,
                'A'..='Z' => c.to_ascii_lowercase(),
                _ => '_',
            })
            .take(MAX_SLUG)
            .collect();
        // A `-` in the key or value could pass for the separator of two sets.
        if exact && readable == raw && !self.key.contains('-') && !value.contains('-') {
            return readable;
        }
        let exact_text = format!("{}={}", self.key, self.value);
        let hash = blake3::hash(exact_text.as_bytes()).to_hex();
        format!("{readable}-{}", &hash[..8])
    }
}

/// The longest readable part of a variant's name for one set: file names stay far below the
/// system's 255 bytes (a longer value is told apart by its hash).
const MAX_SLUG: usize = 60;

/// A `--set` value: TOML (`120.0`, `[1, 2]`, `"auto"`), or else the text as a string.
fn value_of(text: &str) -> toml::Value {
    toml::from_str::<toml::Table>(&format!("v = {text}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(text.to_string()))
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
            // A key set twice would name the variant after both values and run the last.
            let mine: Vec<&Set> = sets.iter().filter(|s| s.stage == name).collect();
            if let Some(twice) = mine
                .iter()
                .enumerate()
                .find(|(i, set)| mine[..*i].iter().any(|s| s.key == set.key))
            {
                return Err(PipelineError::Definition {
                    file: stage.file.clone(),
                    key: twice.1.key.clone(),
                    reason: format!(
                        "--set {}.{} given twice; give each key once",
                        name, twice.1.key
                    ),
                    source: None,
                });
            }
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
        let name = variant_name("f4_fractions", &[set]);
        assert!(
            name.starts_with("f4_fractions--at-120_0-") && name.len() == 31,
            "{name}"
        );
        assert_eq!(
            variant_name("s", &[Set::parse("s.at=40").unwrap()]),
            "s--at-40"
        );
        assert_eq!(
            variant_name("s", &[Set::parse("s.method=rk4").unwrap()]),
            "s--method-rk4"
        );
        let tight = Set::parse("s.scene.run.tolerance=1e-7").unwrap();
        assert!(variant_name("s", &[tight]).starts_with("s--scene_run_tolerance-1e-7-"));
        let set = Set::parse("s.scene.run.method=rk4").unwrap();
        assert_eq!(set.value, toml::Value::String("rk4".into()));
        assert!(Set::parse("nokey=1").is_err());
        assert!(Set::parse("s.=1").is_err());
        let mut table = toml::Table::new();
        assign(&mut table, "scene.run.tolerance", toml::Value::Float(1e-6)).unwrap();
        assert_eq!(table["scene"]["run"]["tolerance"].as_float(), Some(1e-6));
        assert!(assign(&mut table, "scene.run.tolerance.x", toml::Value::Integer(1)).is_err());
    }

    /// Names are one to one: values that read alike get different names, and a long value a
    /// short one.
    #[test]
    fn variant_names_never_collide_and_stay_short() {
        let name = |text: &str| variant_name("s", &[Set::parse(text).unwrap()]);
        assert_ne!(name("s.m=a.b"), name("s.m=a b"));
        assert_ne!(name("s.m=A"), name("s.m=a"));
        assert_ne!(name("s.at=40"), name("s.at=\"40\""));
        assert_ne!(name("s.at=120.0"), name("s.at=120_0"));
        let two = variant_name(
            "s",
            &[Set::parse("s.x=1").unwrap(), Set::parse("s.y=2").unwrap()],
        );
        assert_ne!(name("s.x=1--y-2"), two);
        let long = name(&format!("s.m={}", "x".repeat(5000)));
        assert!(long.len() < 80, "{}", long.len());
        assert_ne!(long, name(&format!("s.m={}", "x".repeat(5001))));
    }
}
