//! Where a project's folders are: `--pipeline`, `--results` and `--figures`, else the
//! environment (`WOODPILE_PIPELINE`, `WOODPILE_RESULTS`, `WOODPILE_FIGURES`), else a
//! `woodpile.toml` in the current folder or the nearest one above it (keys `pipeline`,
//! `results`, `figures`, relative to that file's folder), else `pipeline/`, `results/` and
//! `figures/` beside the `woodpile.toml`, or in the nearest folder holding `pipeline/`, or in
//! the current folder. So a study in its own folder, or any folder inside it, needs no flags.
//! The upward search stops at the first folder holding `pipeline/`, and a `woodpile.toml`
//! owned by another user or in a folder everyone may write is ignored.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context};

/// The `woodpile.toml` file name.
pub(crate) const PROJECT_FILE: &str = "woodpile.toml";

/// A project's three folders, resolved.
#[derive(Debug, Clone)]
pub(crate) struct Dirs {
    pub(crate) pipeline: PathBuf,
    pub(crate) results: PathBuf,
    pub(crate) figures: PathBuf,
}

/// The folders for the given flags (each `None` when not given).
pub(crate) fn resolve(
    pipeline: Option<&Path>,
    results: Option<&Path>,
    figures: Option<&Path>,
) -> anyhow::Result<Dirs> {
    let (root, file) = match find_project_file()? {
        Some((root, table)) => (root, table),
        None => (PathBuf::from("."), toml::Table::new()),
    };
    // `results`, not `./results`: paths are shown in messages and written into files.
    let under = |rel: &str| {
        if root == Path::new(".") {
            PathBuf::from(rel)
        } else {
            root.join(rel)
        }
    };
    let pick = |flag: Option<&Path>, env: &str, key: &str| -> anyhow::Result<PathBuf> {
        if let Some(path) = flag {
            return Ok(path.to_path_buf());
        }
        if let Some(path) = std::env::var_os(env).filter(|v| !v.is_empty()) {
            return Ok(PathBuf::from(path));
        }
        match file.get(key) {
            None => Ok(under(key)),
            Some(toml::Value::String(s)) => Ok(under(s)),
            Some(_) => Err(anyhow!(
                "{}: key `{key}`: expected a folder path (a string)",
                root.join(PROJECT_FILE).display()
            )),
        }
    };
    Ok(Dirs {
        pipeline: pick(pipeline, "WOODPILE_PIPELINE", "pipeline")?,
        results: pick(results, "WOODPILE_RESULTS", "results")?,
        figures: pick(figures, "WOODPILE_FIGURES", "figures")?,
    })
}

/// The project the current folder is in: the nearest folder at or above it that holds a
/// trusted `woodpile.toml` (its folder and table) or a `pipeline/` folder (its folder, no
/// table). The search stops at the first `pipeline/`: a `woodpile.toml` further up (say a
/// world-writable `/tmp/woodpile.toml`) cannot take over a project that has none of its own.
fn find_project_file() -> anyhow::Result<Option<(PathBuf, toml::Table)>> {
    let here = std::env::current_dir().context("the current folder")?;
    // Relative to the current folder when it is the project's own, else absolute.
    let root_of = |folder: &Path| match folder == here {
        true => PathBuf::from("."),
        false => folder.to_path_buf(),
    };
    for folder in here.ancestors() {
        let path = folder.join(PROJECT_FILE);
        if path.is_file() {
            match untrusted(&path) {
                None => return Ok(Some((root_of(folder), read_project_file(&path)?))),
                Some(why) => eprintln!(
                    "warning: ignoring {}: {why}",
                    woodpile_files::input::escape_controls(&path.display().to_string())
                ),
            }
        }
        let stages = folder.join("pipeline");
        if stages.is_dir() {
            // The current folder's own pipeline/ is the default a bare run has always used;
            // one further up is adopted only when it could not have been planted there.
            if folder == here || untrusted(&stages).is_none() {
                return Ok(Some((root_of(folder), toml::Table::new())));
            }
            return Ok(None);
        }
    }
    Ok(None)
}

/// Why a `woodpile.toml` or a `pipeline/` folder may not direct this run: owned by another
/// user, or in a folder everyone may write to (a shared `/tmp`). `None` when it may.
fn untrusted(path: &Path) -> Option<&'static str> {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let folder = path.parent().unwrap_or(Path::new("."));
    let (Ok(meta), Ok(dir)) = (std::fs::metadata(path), std::fs::metadata(folder)) else {
        return Some("it cannot be read");
    };
    if meta.uid() != rustix::process::geteuid().as_raw() {
        Some("it belongs to another user")
    } else if dir.permissions().mode() & 0o002 != 0 {
        Some("it is in a folder everyone may write to")
    } else {
        None
    }
}

/// The table of the `woodpile.toml` at `path`, its keys checked.
fn read_project_file(path: &Path) -> anyhow::Result<toml::Table> {
    let text = woodpile_files::input::read_input(path)
        .map_err(|e| anyhow!("{}: cannot read: {e}", path.display()))?;
    let table: toml::Table = toml::from_str(&text).map_err(|e| {
        anyhow!(
            "{}: {}",
            path.display(),
            woodpile_files::input::syntax_reason(&e, &text)
        )
    })?;
    if let Some(key) = table
        .keys()
        .find(|k| !["pipeline", "results", "figures"].contains(&k.as_str()))
    {
        return Err(anyhow!(
            "{}: key `{key}`: unknown (woodpile.toml has pipeline, results, figures)",
            path.display()
        ));
    }
    Ok(table)
}
