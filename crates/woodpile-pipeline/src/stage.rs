//! One stage file: `pipeline/<figure>/<name>.toml` (any folder under `pipeline/`; the name is
//! the file stem). Top-level keys common to every kind:
//!
//! ```toml
//! kind = "sweep"               # one of the kinds below
//! description = "F4: ..."      # free text, not part of the cache key
//! inputs = ["f4_sweep"]        # upstream stages (by file name), read by this one
//! ```
//!
//! The remaining keys belong to the kind (its module documents them); unknown keys anywhere
//! are errors naming the file and key.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use serde_json::Value;

use crate::error::{PipelineError, Result};
use crate::fields::Fields;
use crate::kind::Registry;
use crate::params::{own_params, Params};
use woodpile_files::key::toml_to_json;

pub use crate::kind::Stage;

impl Stage {
    /// Reads and parses the stage file at `file` of the project rooted at `root` (where a
    /// `scene = "scenes/x.toml"` reference is found), with the kinds of `kinds` and the
    /// project's `defaults` ([`Defaults`]).
    pub fn load(
        file: &Path,
        root: &Path,
        kinds: &'static Registry,
        defaults: &Defaults,
    ) -> Result<Stage> {
        let text = read_text(file)?;
        Stage::parse_in(&text, file, root, kinds, defaults)
    }

    /// Parses stage TOML `text`; `file` names it (and gives the stage its name); scene files
    /// are found relative to the current directory.
    pub fn parse(text: &str, file: &Path, kinds: &'static Registry) -> Result<Stage> {
        Stage::parse_in(text, file, Path::new("."), kinds, &Defaults::default())
    }

    /// [`Stage::parse`] in the project rooted at `root`.
    pub fn parse_in(
        text: &str,
        file: &Path,
        root: &Path,
        kinds: &'static Registry,
        defaults: &Defaults,
    ) -> Result<Stage> {
        let mut table = parse_table(text, file)?;
        include_scene_file(&mut table, file, root)?;
        include_data_digest(&mut table, file, root)?;
        let own = own_params(&table);
        // The kind parses its defaults with its own keys, from a copy dropped once it is
        // parsed; the stage keeps only its own keys and the one shared copy of the defaults.
        let params = Params {
            own,
            defaults: defaults.lay_under(&mut table),
        };
        Stage::from_parts(table, file, kinds, params)
    }

    /// A stage from its parsed table (scene files already included, no defaults).
    pub fn from_table(table: toml::Table, file: &Path, kinds: &'static Registry) -> Result<Stage> {
        let params = Params {
            own: own_params(&table),
            defaults: None,
        };
        Stage::from_parts(table, file, kinds, params)
    }

    /// A stage from `table` (its defaults laid under it), whose parameters are `params`.
    fn from_parts(
        table: toml::Table,
        file: &Path,
        kinds: &'static Registry,
        params: Params,
    ) -> Result<Stage> {
        let name = stage_name(file)?;
        let mut fields = Fields::new(file, "", table);
        let kind: String = fields.required("kind")?;
        let description: String = fields.optional("description")?.unwrap_or_default();
        let inputs: Vec<String> = fields.optional("inputs")?.unwrap_or_default();
        let Some(&(kind, parse)) = kinds.iter().find(|(name, _)| *name == kind) else {
            let names: Vec<&str> = kinds.iter().map(|(name, _)| *name).collect();
            return Err(fields.error(
                "kind",
                format!("unknown kind `{kind}` (kinds: {})", names.join(", ")),
            ));
        };
        let spec = parse(&mut fields, &inputs)?;
        fields.finish()?;
        Ok(Stage {
            name,
            file: file.to_path_buf(),
            description,
            inputs,
            kind,
            spec,
            params,
        })
    }
}

/// Keys every stage of a kind starts from: `defaults.toml` in the stage folder, one table per
/// kind (`[render.style]`, say). A stage's own keys override them, tables merging key by key;
/// they are laid in before parsing, so they are part of each stage's key and manifest, and
/// editing them makes exactly the stages of that kind stale. The engine reads the file without
/// knowing any kind: it only matches table names against each stage's `kind`. Each kind's
/// table is also kept as JSON, shared by every stage of the kind ([`Params`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Defaults {
    table: toml::Table,
    json: BTreeMap<String, Arc<Value>>,
}

impl Defaults {
    /// The name of the defaults file in a stage folder; it is not a stage.
    pub const FILE: &'static str = "defaults.toml";

    /// The largest defaults file: a few dozen keys take a kilobyte. Its tables are shared
    /// by the stages of their kind, but each kind still parses them once per stage.
    pub const MAX_BYTES: usize = 64 * 1024;

    /// The defaults in `dir` (none when it has no defaults file), read and parsed once.
    pub fn load(dir: &Path) -> Result<Defaults> {
        let file = dir.join(Defaults::FILE);
        let Ok(meta) = std::fs::symlink_metadata(&file) else {
            return Ok(Defaults::default());
        };
        if meta.file_type().is_symlink() {
            return Err(PipelineError::Syntax {
                file,
                reason: "a symbolic link: the defaults must be a file of the pipeline folder"
                    .into(),
                source: None,
            });
        }
        let text = read_text(&file)?;
        if text.len() > Defaults::MAX_BYTES {
            return Err(PipelineError::Syntax {
                file,
                reason: format!(
                    "{} bytes, more than the {} a defaults file may have: every stage of a kind parses its table",
                    text.len(),
                    Defaults::MAX_BYTES
                ),
                source: None,
            });
        }
        let table = parse_table(&text, &file)?;
        if let Some((key, _)) = table.iter().find(|(_, v)| !v.is_table()) {
            return Err(definition(
                &file,
                key,
                "expected a table of defaults named after a kind ([render], say)",
            ));
        }
        let json = table
            .iter()
            .map(|(kind, value)| (kind.clone(), Arc::new(toml_to_json(value))))
            .collect();
        Ok(Defaults { table, json })
    }

    /// Lays the defaults of `table`'s kind under it (its own keys win), and returns them as
    /// the shared JSON its parameters refer to.
    fn lay_under(&self, table: &mut toml::Table) -> Option<Arc<Value>> {
        let kind = table.get("kind").and_then(|k| k.as_str())?;
        let (toml::Value::Table(defaults), Some(json)) =
            (self.table.get(kind)?, self.json.get(kind))
        else {
            return None;
        };
        let own = std::mem::replace(table, defaults.clone());
        merge(table, own);
        Some(Arc::clone(json))
    }
}

/// The text of the TOML file at `file`, or a syntax error naming it.
pub(crate) fn read_text(file: &Path) -> Result<String> {
    woodpile_files::input::read_input(file).map_err(|e| PipelineError::Syntax {
        file: file.to_path_buf(),
        reason: format!("cannot read: {e}"),
        source: None,
    })
}

/// `text` (of `file`) parsed as a TOML table, or a syntax error naming the file.
pub(crate) fn parse_table(text: &str, file: &Path) -> Result<toml::Table> {
    toml::from_str(text).map_err(|e| PipelineError::Syntax {
        file: file.to_path_buf(),
        reason: woodpile_files::input::syntax_reason(&e, text),
        source: None,
    })
}

fn stage_name(file: &Path) -> Result<String> {
    let name = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    // It starts with a letter or digit: a name such as `--dry-run` would be read as a flag
    // wherever it is passed on (scripts, `woodpile run NAME`).
    let ok = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_lowercase() || c.is_ascii_digit())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' || c == '-');
    if ok {
        Ok(name)
    } else {
        Err(PipelineError::Syntax {
            file: file.to_path_buf(),
            reason: "a stage file's name must be lowercase letters, digits, `_` or `-`, starting with a letter or digit".into(),
            source: None,
        })
    }
}

/// A stage's scene by reference: `scene = "scenes/x.toml"`, or `[scene]` with `file =
/// "scenes/x.toml"` and keys that override the file's (tables merged key by key, anything else
/// replaced: `[[scene.defect]]` with `eps = "$eps"` replaces the file's defects). The file is
/// read relative to the project root and included by content, so the stage's key changes when
/// the file does, and its manifest shows the scene it ran.
fn include_scene_file(table: &mut toml::Table, file: &Path, root: &Path) -> Result<()> {
    let (reference, key, overrides) = match table.get("scene") {
        Some(toml::Value::String(path)) => (path.clone(), "scene", toml::Table::new()),
        Some(toml::Value::Table(t)) => match t.get("file") {
            Some(toml::Value::String(path)) => {
                let mut rest = t.clone();
                rest.remove("file");
                (path.clone(), "scene.file", rest)
            }
            Some(_) => {
                return Err(definition(
                    file,
                    "scene.file",
                    "expected the path of a scene file",
                ))
            }
            None => return Ok(()),
        },
        _ => return Ok(()),
    };
    let path = woodpile_files::layout::contained(root, &reference)
        .map_err(|reason| definition(file, key, &reason))?;
    let text = woodpile_files::input::read_input(&path)
        .map_err(|e| definition(file, key, &format!("{}: cannot read: {e}", path.display())))?;
    let mut scene: toml::Table = toml::from_str(&text).map_err(|e| {
        definition(
            file,
            key,
            &format!(
                "{}: {}",
                path.display(),
                woodpile_files::input::syntax_reason(&e, &text)
            ),
        )
    })?;
    merge(&mut scene, overrides);
    table.insert("scene".into(), toml::Value::Table(scene));
    Ok(())
}

/// The keys under which a stage may name a data file of the project (a measured trace).
pub const DATA_KEYS: [&str; 1] = ["trace"];

/// A data file by reference, `trace = "data/trace.csv"`: kept as `{ file, blake3 }`, the
/// path and the blake3 digest of its bytes, so that the stage's key changes when the file
/// does (as a scene file's content does). The kind reads the file and checks the digest.
fn include_data_digest(table: &mut toml::Table, file: &Path, root: &Path) -> Result<()> {
    for key in DATA_KEYS {
        let reference = match table.get(key) {
            Some(toml::Value::String(path)) => path.clone(),
            Some(toml::Value::Table(t)) => match t.get("file") {
                Some(toml::Value::String(path)) => path.clone(),
                _ => return Err(definition(file, key, "expected the path of a data file")),
            },
            Some(_) => return Err(definition(file, key, "expected the path of a data file")),
            None => continue,
        };
        let path = woodpile_files::layout::contained(root, &reference)
            .map_err(|reason| definition(file, key, &reason))?;
        let bytes = std::fs::read(&path)
            .map_err(|e| definition(file, key, &format!("{}: cannot read: {e}", path.display())))?;
        let mut data = toml::Table::new();
        data.insert("file".into(), toml::Value::String(reference));
        let digest = blake3::hash(&bytes).to_hex().to_string();
        data.insert("blake3".into(), toml::Value::String(digest));
        table.insert(key.into(), toml::Value::Table(data));
    }
    Ok(())
}

/// `overrides` laid over `base`: tables merge key by key, other values replace. How a scene
/// file's overrides, a kind's defaults and a `vary` stage's `[set]` all combine with a table.
pub fn merge(base: &mut toml::Table, overrides: toml::Table) {
    for (key, value) in overrides {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(inner)), toml::Value::Table(over)) => merge(inner, over),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

fn definition(file: &Path, key: &str, reason: &str) -> PipelineError {
    PipelineError::Definition {
        file: file.to_path_buf(),
        key: key.to_string(),
        reason: reason.to_string(),
        source: None,
    }
}
