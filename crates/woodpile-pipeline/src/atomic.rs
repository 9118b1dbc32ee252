//! Atomic file writes: a result is either complete on disk or absent, never half written.
//!
//! Every write goes to a hidden temporary file in the destination's directory (same file
//! system, so the rename is atomic), is flushed and synced, then renamed over the destination.
//! A process killed mid-write leaves only a `.{name}.{pid}.tmp` file, which readers never look
//! at and [`sweep_stale_temps`] removes once its writer is gone.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{PipelineError, Result};

/// Writes `bytes` to `path` atomically, creating parent directories.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |file| file.write_all(bytes))
}

/// Writes `path` atomically with `fill`, which receives the temporary file.
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut fs::File) -> std::io::Result<()>,
) -> Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    fs::create_dir_all(dir).map_err(|e| PipelineError::io(dir, e))?;
    let tmp = temp_path(path);
    let result = (|| {
        let mut file = fs::File::create(&tmp)?;
        fill(&mut file)?;
        file.flush()?;
        file.sync_all()?;
        drop(file);
        fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        // Best effort: a failed write must not leave its temporary behind.
        let _ = fs::remove_file(&tmp);
        PipelineError::io(path, e)
    })
}

/// `dir/.name.PID.tmp` for `dir/name`.
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// The writer's process id, if `name` is one of [`temp_path`]'s temporaries.
fn temp_owner(name: &str) -> Option<u32> {
    let rest = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    rest.rsplit_once('.')?.1.parse().ok()
}

/// Removes temporaries in `dir` (not recursive) whose writing process no longer runs: the
/// leftovers of a killed run. Temporaries of live processes (another shard writing into the
/// same directory) are left alone. Returns how many were removed.
pub fn sweep_stale_temps(dir: &Path) -> usize {
    let Ok(entries) = fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if let Some(pid) = temp_owner(&name) {
            if !process_alive(pid) && fs::remove_file(entry.path()).is_ok() {
                removed += 1;
            }
        }
    }
    removed
}

fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc_root = Path::new("/proc");
    // Without /proc we cannot tell: keep the file rather than risk a live writer's.
    !proc_root.is_dir() || proc_root.join(pid.to_string()).exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_replaces_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/out.bin");
        write(&path, b"first").unwrap();
        write(&path, b"second").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"second");
        let names: Vec<_> = fs::read_dir(path.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("out.bin")]);
    }

    #[test]
    fn stale_temporaries_of_dead_writers_are_swept_live_ones_kept() {
        let dir = tempfile::tempdir().unwrap();
        // pid 0 is never a user process; our own pid is alive.
        let dead = dir.path().join(".out.bin.0.tmp");
        let live = dir
            .path()
            .join(format!(".out.bin.{}.tmp", std::process::id()));
        let other = dir.path().join("keep.tmp");
        for p in [&dead, &live, &other] {
            fs::write(p, b"x").unwrap();
        }
        assert_eq!(sweep_stale_temps(dir.path()), 1);
        assert!(!dead.exists() && live.exists() && other.exists());
    }

    #[test]
    fn temp_owner_parses_only_our_names() {
        assert_eq!(temp_owner(".a.parquet.123.tmp"), Some(123));
        assert_eq!(temp_owner("a.parquet"), None);
        assert_eq!(temp_owner(".a.tmp"), None);
    }
}
