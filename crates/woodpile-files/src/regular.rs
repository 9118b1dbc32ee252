//! Opening only regular files: what woodpile reads from a results tree (tables, point files,
//! shard parts) or writes in place (the lock) must be a regular file, never a symbolic link,
//! a FIFO (which would block a reader forever), a device (`/dev/zero` reads without end) or a
//! directory, nor a kernel file (procfs, sysfs). Files are opened without following a final
//! symbolic link and checked with `fstat` and `fstatfs` on the open descriptor, so nothing
//! can be swapped in between the check and the use.

use std::fs::{File, OpenOptions};
use std::io::{Error, Read};
use std::path::Path;

/// Why a path is refused, for messages: `None` when it is a regular file (or absent).
pub fn refusal(path: &Path) -> Option<String> {
    let meta = std::fs::symlink_metadata(path).ok()?;
    let kind = meta.file_type();
    if kind.is_file() {
        None
    } else if kind.is_symlink() {
        Some("a symbolic link, which woodpile does not follow in a results tree".into())
    } else if kind.is_dir() {
        Some("a directory, not a file".into())
    } else {
        Some("not a regular file (a FIFO, socket or device)".into())
    }
}

/// `options` made to refuse a final symbolic link and not to block on a FIFO.
fn no_follow(options: &mut OpenOptions) -> &mut OpenOptions {
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
    }
    options
}

/// Opens `path` with `options` (plus no-follow), then checks that it is a regular file.
pub fn open(path: &Path, options: &mut OpenOptions) -> Result<File, Error> {
    if let Some(reason) = refusal(path) {
        return Err(Error::other(reason));
    }
    let file = no_follow(options)
        .open(path)
        .map_err(|e| refusal(path).map_or(e, Error::other))?;
    if !file.metadata()?.is_file() {
        return Err(Error::other("not a regular file"));
    }
    // procfs and sysfs files pass as regular ones (`/proc/kmsg` blocks a root reader).
    if crate::input::on_kernel_fs(&file) {
        return Err(Error::other("a kernel file (procfs or sysfs), not a table"));
    }
    Ok(file)
}

/// The whole of the regular file `path`, if it has at most `limit` bytes.
pub fn read(path: &Path, limit: u64) -> Result<Vec<u8>, Error> {
    let file = open(path, OpenOptions::new().read(true))?;
    let too_big = |n: u64| {
        Error::other(format!(
            "{n} bytes, more than the {limit} a file here may have"
        ))
    };
    let len = file.metadata()?.len();
    if len > limit {
        return Err(too_big(len));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    // The file may grow between the check and the read: never read more than the limit.
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("t.parquet");
        std::fs::write(&file, b"1234").unwrap();
        assert_eq!(read(&file, 4).unwrap(), b"1234");
        let message = |p: &Path, limit| read(p, limit).unwrap_err().to_string();
        assert!(message(&file, 3).contains("more than the 3"));
        assert!(message(dir.path(), 10).contains("directory"));
        // A kernel file passes as a regular one, and is refused by its file system.
        assert!(message(Path::new("/proc/self/status"), 1 << 20).contains("kernel file"));
        #[cfg(unix)]
        {
            let link = dir.path().join("link.parquet");
            std::os::unix::fs::symlink(&file, &link).unwrap();
            assert!(message(&link, 10).contains("symbolic link"));
            let zero = dir.path().join("zero.parquet");
            std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
            assert!(message(&zero, 10).contains("symbolic link"));
            let fifo = dir.path().join("fifo.parquet");
            let made = std::process::Command::new("mkfifo").arg(&fifo).status();
            if made.is_ok_and(|s| s.success()) {
                assert!(message(&fifo, 10).contains("FIFO"));
            }
        }
    }
}
