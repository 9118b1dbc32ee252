//! Where everything a run writes lives, in one place: every path under a results tree or a
//! figures folder is made here, so that the engine, the kinds and the tools that read the tree
//! (diff, status, the Python package) agree on it.
//!
//! ```text
//! results/<stage>.parquet                          a stage's table (with its manifest)
//! results/<stage>.best.toml                        an optimum as a scene file (optimize, design)
//! results/points/<key[..2]>/<key>.wppt             one cached scene (points.rs)
//! results/parts/<stage>/<key>.shard-I-of-N.parquet one shard of a sweep
//! results/.lock                                    held by the run writing the tree
//! figures/<stage>.png, figures/<stage>.svg         a render stage's figure
//! <project>/<markdown>                             a report's Markdown, beside results/
//! ```

use std::path::{Path, PathBuf};

/// The table of stage `name`.
pub fn output_path(results: &Path, name: &str) -> PathBuf {
    results.join(format!("{name}.parquet"))
}

/// The point cache of a results tree.
pub fn points_dir(results: &Path) -> PathBuf {
    results.join("points")
}

/// The directory of stage `stage`'s shard parts.
pub fn parts_dir(results: &Path, stage: &str) -> PathBuf {
    results.join("parts").join(stage)
}

/// The part file of shard `index` of `count` of `stage`, for the definition with key `key`.
pub fn part_path(results: &Path, stage: &str, key: &str, index: usize, count: usize) -> PathBuf {
    parts_dir(results, stage).join(format!("{key}.shard-{index}-of-{count}.parquet"))
}

/// The best scene an optimizing stage `name` found, as a scene file.
pub fn best_path(results: &Path, name: &str) -> PathBuf {
    results.join(format!("{name}.best.toml"))
}

/// The figure files of stage `name`: PNG, then SVG.
pub fn figure_paths(figures: &Path, name: &str) -> [PathBuf; 2] {
    [
        figures.join(format!("{name}.png")),
        figures.join(format!("{name}.svg")),
    ]
}

/// A report's Markdown file `markdown` (relative to the project) for the results tree `results`:
/// it lives beside the tree, so a scratch tree's report goes beside the scratch tree.
pub fn markdown_path(results: &Path, markdown: &str) -> PathBuf {
    results
        .parent()
        .unwrap_or_else(|| Path::new(""))
        .join(markdown)
}

/// The lock file's name inside a results tree.
pub const LOCK_FILE: &str = ".woodpile.lock";

/// The lock file of a results tree.
pub fn lock_path(results: &Path) -> PathBuf {
    results.join(LOCK_FILE)
}

/// Whether `reference` is a relative path of plain names (`.` allowed, no `..`, not absolute,
/// at least one name): the form of every path a stage file may name inside the project.
pub fn is_plain_relative(reference: &str) -> bool {
    let path = Path::new(reference);
    let plain = path.components().all(|c| {
        matches!(
            c,
            std::path::Component::Normal(_) | std::path::Component::CurDir
        )
    });
    plain
        && path
            .components()
            .any(|c| matches!(c, std::path::Component::Normal(_)))
}

/// The file a stage file names as `reference`, inside the project at `root`: a plain relative
/// path ([`is_plain_relative`]) with no symbolic link on the way, so a cloned project cannot
/// make woodpile read `/proc/self/environ` or `../../etc/passwd`. The error is the reason.
pub fn contained(root: &Path, reference: &str) -> Result<PathBuf, String> {
    if !is_plain_relative(reference) {
        return Err(format!(
            "`{reference}` must be a relative path inside the project (no `..`, not absolute)"
        ));
    }
    let mut path = root.to_path_buf();
    for part in Path::new(reference).components() {
        path.push(part);
        let linked = std::fs::symlink_metadata(&path).is_ok_and(|m| m.file_type().is_symlink());
        if linked {
            return Err(format!(
                "`{reference}` passes through a symbolic link ({}): it must stay inside the project",
                path.display()
            ));
        }
    }
    Ok(path)
}

/// Refuses a folder of the results tree (`points/`, `parts/`, a stage's parts) that is a
/// symbolic link or not a folder: what woodpile writes there, and the stale-temporary sweep's
/// deletions, would land outside the tree. A folder not yet made is fine. The error is the
/// reason.
pub fn check_tree_folder(folder: &Path) -> Result<(), String> {
    match std::fs::symlink_metadata(folder) {
        Ok(m) if m.file_type().is_symlink() => Err(
            "a symbolic link; the results tree's own folders must be real folders inside it (remove it and run again)".into(),
        ),
        Ok(m) if !m.is_dir() => Err("not a folder; remove it and run again".into()),
        _ => Ok(()),
    }
}
