//! One writer of a results tree at a time: `woodpile run` and `woodpile merge` hold an
//! exclusive lock on `results/.woodpile.lock` for as long as they write stage outputs. A second
//! run on the same tree waits (and says so), then finds the first one's outputs fresh instead
//! of simulating everything again.
//!
//! Shards of a sweep (`run STAGE --shard I/N`) do not take it: they write only points and part
//! files, which are content-addressed and written atomically, so they cooperate without it.
//! The lock is an OS file lock (flock), released by the kernel when the holder exits, even by
//! `kill -9`: a crashed run never leaves the tree locked.

use std::fs::{self, File, OpenOptions, TryLockError};
use std::io::Write;
use std::path::Path;

use crate::error::{PipelineError, Result};
use crate::events::Events;
use woodpile_files::layout::lock_path;
use woodpile_files::regular;

/// Held while a run writes; dropping it releases the lock.
#[derive(Debug)]
pub struct ResultsLock {
    _file: Option<File>,
}

/// Locks `results` for writing, waiting (with a message through `events`) while another
/// process holds it. The lock file must be a regular file: a symbolic link (which would make
/// woodpile truncate or create a file elsewhere), a FIFO or a directory in its place is
/// refused by name. A lock file this user cannot write (another user's, on a shared file
/// system) is locked through a read-only descriptor, which flock allows; one it cannot even
/// read stops the run. Only a tree where no lock file exists and none can be created (a
/// read-only copy) is not locked: a run there can only find its stages fresh or fail at its
/// first write.
pub fn lock_results(results: &Path, events: &dyn Events) -> Result<ResultsLock> {
    let path = lock_path(results);
    let refuse = |reason: String| {
        PipelineError::refused(
            &path,
            format!(
                "{reason}; the results tree's lock must be a regular file: remove it and run again"
            ),
        )
    };
    fs::create_dir_all(results).map_err(|e| PipelineError::io(results, e))?;
    let writable = regular::open(
        &path,
        OpenOptions::new()
            .create(true)
            .truncate(false)
            .read(true)
            .write(true),
    );
    let (mut file, writable) = match writable {
        Ok(file) => (file, true),
        Err(e) if regular::refusal(&path).is_some() => return Err(refuse(e.to_string())),
        Err(_) if !path.exists() => return Ok(ResultsLock { _file: None }),
        Err(_) => match regular::open(&path, OpenOptions::new().read(true)) {
            Ok(file) => (file, false),
            Err(reason) => {
                return Err(PipelineError::io(
                    &path,
                    format!("cannot open the results tree's lock ({reason}): another user's run may be writing here"),
                ))
            }
        },
    };
    match file.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => {
            let holder = regular::read(&path, 256)
                .map(|b| String::from_utf8_lossy(&b).into_owned())
                .unwrap_or_default();
            events.warn(&format!(
                "another woodpile ({}) is writing {}; waiting for it to finish",
                holder.trim(),
                results.display()
            ));
            file.lock().map_err(|e| PipelineError::io(&path, e))?;
        }
        Err(TryLockError::Error(e)) => return Err(PipelineError::io(&path, e)),
    }
    // Who holds it, for the message a waiting run prints (best effort: the lock is the flock).
    if writable {
        let _ = file
            .set_len(0)
            .and_then(|()| write!(file, "pid {}", std::process::id()));
    }
    Ok(ResultsLock { _file: Some(file) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_holder_waits_until_the_first_releases() {
        let dir = tempfile::tempdir().unwrap();
        let first = lock_results(dir.path(), &crate::events::Silent).unwrap();
        let file = File::open(lock_path(dir.path())).unwrap();
        assert!(matches!(file.try_lock(), Err(TryLockError::WouldBlock)));
        drop(first);
        assert!(file.try_lock().is_ok());
    }

    #[cfg(unix)]
    #[test]
    fn a_symlinked_lock_is_refused_and_its_target_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("important.txt");
        std::fs::write(&target, "keep me").unwrap();
        let results = dir.path().join("results");
        std::fs::create_dir(&results).unwrap();
        std::os::unix::fs::symlink(&target, lock_path(&results)).unwrap();
        let err = lock_results(&results, &crate::events::Silent).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep me");
        // A dangling link creates nothing outside the tree.
        std::fs::remove_file(lock_path(&results)).unwrap();
        let elsewhere = dir.path().join("created-elsewhere");
        std::os::unix::fs::symlink(&elsewhere, lock_path(&results)).unwrap();
        assert!(lock_results(&results, &crate::events::Silent).is_err());
        assert!(!elsewhere.exists());
    }

    #[cfg(unix)]
    #[test]
    fn a_read_only_lock_file_still_locks() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(lock_path(dir.path()), "pid 1").unwrap();
        std::fs::set_permissions(
            lock_path(dir.path()),
            std::fs::Permissions::from_mode(0o444),
        )
        .unwrap();
        let held = lock_results(dir.path(), &crate::events::Silent).unwrap();
        assert!(held._file.is_some());
        let other = File::open(lock_path(dir.path())).unwrap();
        // Root ignores permissions and opens it writable: either way the lock is held.
        assert!(matches!(other.try_lock(), Err(TryLockError::WouldBlock)));
    }
}
