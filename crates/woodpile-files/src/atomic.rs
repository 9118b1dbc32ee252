//! Atomic file writes: a result is either complete on disk or absent, never half written.
//!
//! Every write goes to a hidden temporary file in the destination's directory (same file
//! system, so the rename is atomic), is flushed and synced, then renamed over the destination.
//! A process killed mid-write leaves only a `.{name}~{host}~{pid}~{token}.tmp` file, which
//! readers never look at and [`sweep_stale_temps`] removes once its writer is gone.

use std::fs;
use std::io::Write;
use std::path::Path;

use crate::error::{FileError, Result};

/// Writes `bytes` to `path` atomically, creating parent directories.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |file| file.write_all(bytes))
}

/// [`write()`] without syncing the file to the disk before the rename: atomic for every process
/// (a killed writer leaves the old file or the new one), but a power cut may leave the file
/// empty or partial. Only for files that carry their own checksum, whose reader then finds
/// the damage and recomputes: the point cache, where a sync per scene kept the sweep's
/// workers waiting on the disk (F7's coarse grid: 172% of two cores busy with a sync per
/// point, 196% without).
pub fn write_checksummed(path: &Path, bytes: &[u8]) -> Result<()> {
    write_impl(path, |file| file.write_all(bytes), false)
}

/// Writes `path` atomically with `fill`, which receives the temporary file. Temporaries of
/// `path` left by writers that are gone (an interrupted `simulate --field` leaves tens of MB)
/// are removed first.
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut fs::File) -> std::io::Result<()>,
) -> Result<()> {
    if let (Some(dir), Some(name)) = (path.parent(), path.file_name()) {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        sweep_stale(dir, Some(&name.to_string_lossy()));
    }
    write_impl(path, fill, true)
}

fn write_impl(
    path: &Path,
    fill: impl FnOnce(&mut fs::File) -> std::io::Result<()>,
    sync: bool,
) -> Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    fs::create_dir_all(dir).map_err(|e| FileError::io(dir, e))?;
    let result = (|| {
        // Dropped on any error before `persist`: the temporary is removed with it.
        let mut tmp = temp_file(path, dir)?;
        // tempfile creates its files private (0600); a result is as readable as any file.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            tmp.as_file()
                .set_permissions(fs::Permissions::from_mode(0o644))?;
        }
        fill(tmp.as_file_mut())?;
        tmp.as_file_mut().flush()?;
        if sync {
            tmp.as_file().sync_all()?;
        }
        tmp.persist(path).map(|_| ()).map_err(|e| e.error)
    })();
    result.map_err(|e| FileError::io(path, e))
}

/// A new temporary beside `path` in `dir`, named `.{name}~{host}~{pid}~{random}.tmp`: unique
/// across threads, processes and machines sharing a file system, and saying who wrote it.
/// Two writers of the same file (two threads simulating one point, two cluster nodes whose
/// processes have the same PID) thus never write into each other's temporary; each renames
/// its own complete file, and the last rename leaves a complete file.
fn temp_file(path: &Path, dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    tempfile::Builder::new()
        .prefix(&format!(".{name}~{}~{}~", host(), std::process::id()))
        .suffix(".tmp")
        .rand_bytes(TEMP_RANDOM)
        .tempfile_in(dir)
}

/// This machine's name, as it appears in temporary names (no separators in it).
fn host() -> &'static str {
    static HOST: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    HOST.get_or_init(|| {
        let name = fs::read_to_string("/proc/sys/kernel/hostname")
            .or_else(|_| fs::read_to_string("/etc/hostname"))
            .unwrap_or_default();
        let name: String = name
            .trim()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        if name.is_empty() {
            "localhost".into()
        } else {
            name
        }
    })
}

/// The target's file name and the writer (host, process id) of one of [`temp_file`]'s
/// temporaries, recognised by their
/// exact form `.{name}~{host}~{pid}~{12 random alphanumerics}.tmp`: a user's own `.x.123.tmp`
/// in a figures folder is not woodpile's, and is never removed.
fn temp_parts(name: &str) -> Option<(&str, &str, u32)> {
    let rest = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let mut parts = rest.rsplitn(4, '~');
    let (Some(token), Some(pid), Some(host), Some(target)) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return None;
    };
    let random = token.len() == TEMP_RANDOM && token.chars().all(|c| c.is_ascii_alphanumeric());
    let digits = !pid.is_empty() && pid.chars().all(|c| c.is_ascii_digit());
    (random && digits && !host.is_empty()).then(|| Some((target, host, pid.parse().ok()?)))?
}

/// Random characters in a temporary's name.
const TEMP_RANDOM: usize = 12;

/// How old another machine's temporary must be before a sweep removes it: its writer cannot be
/// asked whether it still runs, and no writer spends a day on one file.
const FOREIGN_TEMP_AGE: std::time::Duration = std::time::Duration::from_secs(24 * 3600);

/// Removes temporaries in `dir` (not recursive) whose writer is gone: on this machine, a
/// process that no longer runs; on another machine sharing the directory, a file untouched
/// for a day. Temporaries of live writers (another shard writing into the same directory) are
/// left alone. Returns how many were removed.
pub fn sweep_stale_temps(dir: &Path) -> usize {
    sweep_stale(dir, None)
}

/// [`sweep_stale_temps`], of the temporaries of the file named `target` only when given.
fn sweep_stale(dir: &Path, target: Option<&str>) -> usize {
    let Ok(entries) = fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some((of, writer_host, pid)) = temp_parts(&name) else {
            continue;
        };
        if target.is_some_and(|t| t != of) {
            continue;
        }
        let gone = if writer_host == host() {
            !process_alive(pid)
        } else {
            entry
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age > FOREIGN_TEMP_AGE)
        };
        if gone && fs::remove_file(entry.path()).is_ok() {
            removed += 1;
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
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = fs::metadata(&path).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o644, "results are readable by others");
        }
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
        let dead = dir
            .path()
            .join(format!(".out.bin~{}~0~Ab3dEf6hIj9l.tmp", host()));
        let live_file = temp_file(&dir.path().join("out.bin"), dir.path()).unwrap();
        let live = live_file.path().to_path_buf();
        // Another machine's fresh temporary: its writer may be running there.
        let foreign = dir.path().join(".out.bin~elsewhere~0~Ab3dEf6hIj9l.tmp");
        let other = dir.path().join("keep.tmp");
        // A user's own temporaries that only look alike.
        let users = dir.path().join(".notes.123.tmp");
        let short = dir.path().join(format!(".out.bin~{}~0~1-ab.tmp", host()));
        for p in [&dead, &live, &foreign, &other, &users, &short] {
            fs::write(p, b"x").unwrap();
        }
        assert_eq!(sweep_stale_temps(dir.path()), 1);
        assert!(!dead.exists() && live.exists() && foreign.exists() && other.exists());
        assert!(users.exists() && short.exists());
    }

    /// A write sweeps the dead temporaries of its own target, and only those.
    #[test]
    fn a_write_removes_its_targets_dead_temporaries() {
        let dir = tempfile::tempdir().unwrap();
        let dead = |target: &str| {
            dir.path()
                .join(format!(".{target}~{}~0~Ab3dEf6hIj9l.tmp", host()))
        };
        std::fs::write(dead("field.parquet"), "left by a killed run").unwrap();
        std::fs::write(dead("other.parquet"), "not this write's").unwrap();
        write(&dir.path().join("field.parquet"), b"new").unwrap();
        assert!(!dead("field.parquet").exists());
        assert!(dead("other.parquet").exists());
    }

    #[test]
    fn temporaries_are_unique_and_name_their_writer() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.parquet");
        let (a, b) = (
            temp_file(&path, dir.path()).unwrap(),
            temp_file(&path, dir.path()).unwrap(),
        );
        assert_ne!(a.path(), b.path());
        let name = a.path().file_name().unwrap().to_str().unwrap();
        assert_eq!(
            temp_parts(name),
            Some(("a.parquet", host(), std::process::id()))
        );
        assert_eq!(temp_parts("a.parquet"), None);
        assert_eq!(temp_parts(".a.tmp"), None);
        assert_eq!(temp_parts(".a~h~x~t.tmp"), None);
        assert_eq!(temp_parts(".a.parquet.123.tmp"), None);
    }

    #[test]
    fn concurrent_writers_of_one_file_never_collide() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("point.bin");
        std::thread::scope(|scope| {
            for _ in 0..8 {
                scope.spawn(|| {
                    for _ in 0..50 {
                        write(&path, b"the same bytes").unwrap();
                    }
                });
            }
        });
        assert_eq!(fs::read(&path).unwrap(), b"the same bytes");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
