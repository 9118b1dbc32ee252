//! Splitting a sweep across machines: `woodpile run STAGE --shard I/N` computes shard I of N
//! (points with index ≡ I mod N, so every shard gets a fair mix of cheap and expensive scenes)
//! into a part file; `woodpile merge STAGE` joins a complete set of parts into the stage's
//! output, identical to what one machine would have written.
//!
//! Parts live in `results/parts/<stage>/<key>.shard-<I>-of-<N>.parquet`. The key in the name
//! ties a part to one definition of the stage: editing the stage orphans old parts instead of
//! mixing them in. Points go through the shared [`PointsDir`], so a shard re-run after a crash
//! skips every point it had finished.

use std::path::{Path, PathBuf};

use polars::prelude::{DataFrame, IdxCa, IdxSize};
use serde_json::json;

use crate::error::{PipelineError, Result};
use crate::events::Events;
use crate::kind::{PointGrid, PointsAt};
use crate::manifest::Manifest;
use crate::pipeline::Pipeline;
use crate::run::manifest_for;
use crate::stage::Stage;
use crate::table::{self, f64_column};
use woodpile_files::layout::{output_path, parts_dir, points_dir};
use woodpile_files::{PointStats, PointsDir};

/// Shard `index` of `count` (0 <= index < count).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which shard, from 0.
    pub index: usize,
    /// How many shards.
    pub count: usize,
}

impl Shard {
    /// Parses `I/N`.
    pub fn parse(text: &str) -> std::result::Result<Shard, String> {
        let (i, n) = text.split_once('/').ok_or("expected I/N, e.g. 0/4")?;
        let number = |s: &str| {
            s.trim()
                .parse::<usize>()
                .map_err(|_| format!("`{s}` is not a whole number"))
        };
        Shard::new(number(i)?, number(n)?)
    }

    /// Checks `index < count`.
    pub fn new(index: usize, count: usize) -> std::result::Result<Shard, String> {
        if count == 0 || index >= count {
            return Err(format!("shard {index}/{count}: need 0 <= I < N"));
        }
        Ok(Shard { index, count })
    }

    /// The shard of a SLURM array task, from `SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_COUNT`
    /// and (when the array does not start at 0) `SLURM_ARRAY_TASK_MIN`; `None` outside an
    /// array job. `get` reads a variable (the environment, or a map in tests).
    pub fn from_slurm(
        get: impl Fn(&str) -> Option<String>,
    ) -> std::result::Result<Option<Shard>, String> {
        let (Some(id), Some(count)) = (get("SLURM_ARRAY_TASK_ID"), get("SLURM_ARRAY_TASK_COUNT"))
        else {
            return Ok(None);
        };
        let number = |name: &str, s: &str| {
            s.trim()
                .parse::<usize>()
                .map_err(|_| format!("{name}=`{s}` is not a whole number"))
        };
        let id = number("SLURM_ARRAY_TASK_ID", &id)?;
        let count = number("SLURM_ARRAY_TASK_COUNT", &count)?;
        let min = match get("SLURM_ARRAY_TASK_MIN") {
            Some(m) => number("SLURM_ARRAY_TASK_MIN", &m)?,
            None => 0,
        };
        let index = id
            .checked_sub(min)
            .ok_or("SLURM_ARRAY_TASK_ID below SLURM_ARRAY_TASK_MIN")?;
        Shard::new(index, count).map(Some)
    }

    /// The points of a sweep of `total` points that belong to this shard.
    pub fn points(&self, total: usize) -> Vec<usize> {
        (self.index..total).step_by(self.count).collect()
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

fn part_path(results: &Path, stage: &str, key: &str, shard: Shard) -> PathBuf {
    woodpile_files::layout::part_path(results, stage, key, shard.index, shard.count)
}

/// `(key, shard)` from a part file name.
fn parse_part_name(name: &str) -> Option<(String, Shard)> {
    let stem = name.strip_suffix(".parquet")?;
    let (key, rest) = stem.split_once(".shard-")?;
    let (i, n) = rest.split_once("-of-")?;
    Some((
        key.to_string(),
        Shard::new(i.parse().ok()?, n.parse().ok()?).ok()?,
    ))
}

fn sweep_of<'p>(pipeline: &'p Pipeline, name: &str) -> Result<(&'p Stage, &'p dyn PointGrid)> {
    let stage = pipeline.stage(name)?;
    match stage.spec.points() {
        Some(sweep) => Ok((stage, sweep)),
        None => Err(PipelineError::stage(
            name,
            format!(
                "only sweeps are sharded; `{name}` is a {} stage (run it after `woodpile merge`)",
                stage.kind
            ),
        )),
    }
}

/// What a shard run did.
#[derive(Debug, Clone, PartialEq)]
pub struct ShardRun {
    /// The part file.
    pub part: PathBuf,
    /// Points in the shard.
    pub points: usize,
    /// Whether the part already existed for this definition (nothing ran).
    pub already_done: bool,
}

/// Computes shard `shard` of sweep `name` into its part file.
pub fn run_shard(
    pipeline: &Pipeline,
    name: &str,
    shard: Shard,
    results: &Path,
    events: &dyn Events,
) -> Result<ShardRun> {
    let (stage, sweep) = sweep_of(pipeline, name)?;
    let key = pipeline.key(name).to_string();
    if shard.count > sweep.count() {
        return Err(PipelineError::Definition {
            file: stage.file.clone(),
            key: "--shard".into(),
            reason: format!(
                "--shard {shard}: {} shards for a sweep of {} points; use at most one shard per point",
                shard.count,
                sweep.count()
            ),
            source: None,
        });
    }
    let part = part_path(results, name, &key, shard);
    let indices = shard.points(sweep.count());
    // Done only if the part is for this definition and intact: a damaged part is recomputed.
    let done = table::read_checked(&part).is_ok_and(|c| {
        c.integrity == table::Integrity::Intact && c.manifest.is_some_and(|m| m.key == key)
    });
    if done {
        return Ok(ShardRun {
            part,
            points: indices.len(),
            already_done: true,
        });
    }
    for folder in [
        points_dir(results),
        results.join("parts"),
        parts_dir(results, name),
    ] {
        woodpile_files::layout::check_tree_folder(&folder)
            .map_err(|e| PipelineError::refused(&folder, e))?;
    }
    let points = PointsDir::new(points_dir(results));
    points.sweep_stale_temps();
    woodpile_files::atomic::sweep_stale_temps(&parts_dir(results, name));
    events.stage_started(name, &format!("shard {shard}"));
    let at = PointsAt {
        stage: name,
        points: &points,
        events,
    };
    let (frame, stats) = sweep.run_points(at, &indices)?;
    let manifest = manifest_for(
        pipeline,
        stage,
        json!({"shard": shard.index, "shards": shard.count, "stats": stats}),
    );
    table::write(&part, frame, &manifest)?;
    events.stage_finished(name, &format!("shard {shard}: {} points", indices.len()));
    Ok(ShardRun {
        part,
        points: indices.len(),
        already_done: false,
    })
}

/// Joins the complete set of parts of sweep `name` (for its current definition) into
/// `results/<name>.parquet`. Returns the number of parts merged.
pub fn merge(
    pipeline: &Pipeline,
    name: &str,
    results: &Path,
    events: &dyn Events,
) -> Result<usize> {
    let _lock = crate::lock::lock_results(results, events)?;
    let (stage, sweep) = sweep_of(pipeline, name)?;
    let key = pipeline.key(name).to_string();
    let dir = parts_dir(results, name);
    let (mut current, orphans) = parts_of(&dir, &key);
    let orphan_note = if orphans > 0 {
        format!(" ({orphans} part(s) of an older definition of the stage are ignored)")
    } else {
        String::new()
    };
    let fail = |reason: String| PipelineError::stage(name, reason + &orphan_note);
    if current.is_empty() {
        return Err(fail(format!(
            "no parts for the current definition (key {}) in {}: run `woodpile run {name} --shard I/N` for every I first",
            &key[..12],
            dir.display()
        )));
    }
    current.sort_by_key(|(s, _)| s.index);
    check_complete(&current, sweep.count(), name).map_err(fail)?;
    let mut frame: Option<DataFrame> = None;
    let mut stats = PointStats::default();
    for (shard, path) in &current {
        let (part, part_stats) = read_part(path, shard, &key, sweep.count())?.map_err(fail)?;
        stats = stats.merge(part_stats);
        frame = Some(match frame {
            None => part,
            Some(f) => f.vstack(&part).map_err(|e| PipelineError::io(path, e))?,
        });
    }
    let Some(frame) = frame else {
        return Err(fail("no parts".into()));
    };
    let frame = in_point_order(frame, sweep.count())
        .map_err(|reason| PipelineError::stage(name, reason))?;
    let manifest = manifest_for(pipeline, stage, sweep.summary(&stats)?);
    table::write(&output_path(results, name), frame, &manifest)?;
    Ok(current.len())
}

/// The parts in `dir` made for the definition with key `key`, and how many were made for
/// another (older) one.
fn parts_of(dir: &Path, key: &str) -> (Vec<(Shard, PathBuf)>, usize) {
    let mut current = Vec::new();
    let mut orphans = 0;
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            let file = entry.file_name().to_string_lossy().into_owned();
            match parse_part_name(&file) {
                Some((k, shard)) if k == key => current.push((shard, entry.path())),
                Some(_) => orphans += 1,
                None => {}
            }
        }
    }
    (current, orphans)
}

/// Whether `current` (sorted by index) is one complete set of shards of a sweep of `points`
/// points, or why not.
fn check_complete(
    current: &[(Shard, PathBuf)],
    points: usize,
    name: &str,
) -> std::result::Result<(), String> {
    let mut counts: Vec<usize> = current.iter().map(|(s, _)| s.count).collect();
    counts.sort_unstable();
    counts.dedup();
    if counts.len() > 1 {
        return Err(format!(
            "parts were made with different shard counts {counts:?}: re-run them with one N"
        ));
    }
    let n = counts[0];
    if n > points {
        return Err(format!(
            "parts were made with {n} shards, more than the sweep's {points} points: re-run them with at most one shard per point"
        ));
    }
    let present: std::collections::HashSet<usize> = current.iter().map(|(s, _)| s.index).collect();
    let missing = (0..n).filter(|i| !present.contains(i));
    let examples: Vec<String> = missing.clone().take(5).map(|i| i.to_string()).collect();
    if examples.is_empty() {
        return Ok(());
    }
    let count = missing.count();
    let more = if count > examples.len() { ", ..." } else { "" };
    Err(format!(
        "incomplete: {count} of {n} shard(s) missing ({}{more}; run `woodpile run {name} --shard I/{n}` for each)",
        examples.join(", ")
    ))
}

/// The table and statistics of the part at `path`, checked against the definition's key and
/// its shard's point count (the inner error: why it does not belong).
fn read_part(
    path: &Path,
    shard: &Shard,
    key: &str,
    points: usize,
) -> Result<std::result::Result<(DataFrame, PointStats), String>> {
    let manifest: Manifest = table::read_manifest(path)?
        .ok_or_else(|| PipelineError::io(path, "part vanished while merging"))?;
    if manifest.key != key {
        return Ok(Err(format!(
            "{} was computed for another definition",
            path.display()
        )));
    }
    let part_stats: PointStats = serde_json::from_value(manifest.summary["stats"].clone())
        .map_err(|e| PipelineError::io(path, format!("bad shard statistics: {e}")))?;
    let expected = shard.points(points).len();
    if part_stats.points != expected {
        return Ok(Err(format!(
            "{} holds {} points, shard {shard} has {expected}",
            path.display(),
            part_stats.points,
        )));
    }
    Ok(Ok((table::read(path)?, part_stats)))
}

/// Rows reordered by point (stable, so each point's samples keep their time order); every
/// point 0..total must appear.
fn in_point_order(frame: DataFrame, total: usize) -> std::result::Result<DataFrame, String> {
    let point = f64_column(&frame, "point").map_err(|e| e.to_string())?;
    let mut order: Vec<(usize, IdxSize)> = Vec::with_capacity(point.len());
    for (row, p) in point.iter().enumerate() {
        let p = p.ok_or("a part has a row without a point index")? as usize;
        order.push((p, row as IdxSize));
    }
    order.sort_by_key(|&(p, _)| p);
    let mut seen = vec![false; total];
    for &(p, _) in &order {
        *seen
            .get_mut(p)
            .ok_or(format!("point {p} is outside the sweep's {total} points"))? = true;
    }
    if let Some(p) = seen.iter().position(|s| !s) {
        return Err(format!("point {p} is in no part"));
    }
    let idx = IdxCa::from_vec("idx".into(), order.into_iter().map(|(_, r)| r).collect());
    let mut out = frame.take(&idx).map_err(|e| e.to_string())?;
    out.rechunk_mut();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_partition_the_points() {
        assert_eq!(Shard::parse("1/4"), Ok(Shard { index: 1, count: 4 }));
        assert!(Shard::parse("4/4").is_err());
        assert!(Shard::parse("x/4").is_err());
        assert!(Shard::parse("3").is_err());
        let mut all: Vec<usize> = (0..3)
            .flat_map(|i| Shard::new(i, 3).unwrap().points(10))
            .collect();
        all.sort_unstable();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
        // More shards than points: some shards are empty, none overlap.
        assert!(Shard::new(7, 8).unwrap().points(5).is_empty());
    }

    #[test]
    fn slurm_variables_give_the_shard() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |k: &str| {
                pairs
                    .iter()
                    .find(|(n, _)| *n == k)
                    .map(|(_, v)| v.to_string())
            }
        };
        assert_eq!(Shard::from_slurm(env(&[])), Ok(None));
        assert_eq!(
            Shard::from_slurm(env(&[
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "4")
            ])),
            Ok(Some(Shard { index: 2, count: 4 }))
        );
        assert_eq!(
            Shard::from_slurm(env(&[
                ("SLURM_ARRAY_TASK_ID", "3"),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
                ("SLURM_ARRAY_TASK_MIN", "1")
            ])),
            Ok(Some(Shard { index: 2, count: 4 }))
        );
        assert!(Shard::from_slurm(env(&[
            ("SLURM_ARRAY_TASK_ID", "x"),
            ("SLURM_ARRAY_TASK_COUNT", "4")
        ]))
        .is_err());
    }

    #[test]
    fn part_names_round_trip() {
        let shard = Shard::new(3, 8).unwrap();
        let path = part_path(Path::new("r"), "s", "abc", shard);
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(parse_part_name(&name), Some(("abc".to_string(), shard)));
        assert_eq!(parse_part_name("abc.parquet"), None);
    }
}
