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
use std::io::{ErrorKind, Write};
use std::path::{Path, PathBuf};

use crate::error::{PipelineError, Result};
use crate::events::Events;

/// The lock file's name inside the results tree.
pub const LOCK_FILE: &str = ".woodpile.lock";

/// Held while a run writes; dropping it releases the lock.
#[derive(Debug)]
pub struct ResultsLock {
    _file: Option<File>,
}

/// Locks `results` for writing, waiting (with a message through `events`) while another
/// process holds it. A tree that cannot be written at all (a read-only copy) is not locked:
/// a run there can only find its stages fresh or fail at its first write.
pub fn lock_results(results: &Path, events: &dyn Events) -> Result<ResultsLock> {
    let path = lock_path(results);
    let opened = fs::create_dir_all(results).and_then(|()| {
        OpenOptions::new()
            .create(true)
            .truncate(false)
            .read(true)
            .write(true)
            .open(&path)
    });
    let mut file = match opened {
        Ok(file) => file,
        Err(e)
            if matches!(
                e.kind(),
                ErrorKind::ReadOnlyFilesystem | ErrorKind::PermissionDenied
            ) =>
        {
            return Ok(ResultsLock { _file: None })
        }
        Err(e) => return Err(PipelineError::io(&path, e)),
    };
    match file.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => {
            let holder = fs::read_to_string(&path).unwrap_or_default();
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
    let _ = file
        .set_len(0)
        .and_then(|()| write!(file, "pid {}", std::process::id()));
    Ok(ResultsLock { _file: Some(file) })
}

/// Where the lock of `results` lives.
pub fn lock_path(results: &Path) -> PathBuf {
    results.join(LOCK_FILE)
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
}
