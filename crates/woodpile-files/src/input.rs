//! Reading an input file (a scene or a stage file) as text, and saying what is wrong with it
//! without echoing what was read.

use std::path::Path;

/// Largest scene or stage file accepted: a hundred times the largest the paper needs, and small
/// enough that parsing it never takes long or much memory.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Why `path` is refused as a kernel file: procfs and sysfs hold files that pass as regular
/// ones but are the kernel's (`/proc/kmsg`, read as root, blocks for ever; others print the
/// environment). Known by the file system's type wherever it is mounted (`/host/proc` in a
/// container), and by the usual paths. `None` for any other file.
pub fn kernel_file(path: &Path) -> Option<String> {
    let kernel_fs = rustix::fs::statfs(path).is_ok_and(|fs| is_kernel_fs(&fs));
    let real = std::fs::canonicalize(path).ok()?;
    let kernel_path = ["/proc", "/sys"].iter().any(|root| real.starts_with(root));
    (kernel_fs || kernel_path).then(|| format!("a kernel file ({}), not an input", real.display()))
}

/// Whether the open `file` lies on procfs or sysfs: [`kernel_file`]'s test by file system, one
/// system call on a descriptor already open, for readers of many files (the point cache).
pub fn on_kernel_fs(file: &std::fs::File) -> bool {
    rustix::fs::fstatfs(file).is_ok_and(|fs| is_kernel_fs(&fs))
}

fn is_kernel_fs(fs: &rustix::fs::StatFs) -> bool {
    const PROC_SUPER_MAGIC: u64 = 0x9fa0;
    const SYSFS_MAGIC: u64 = 0x6265_6572;
    // `f_type`'s integer type differs between platforms: compare its bits.
    #[allow(clippy::unnecessary_cast)]
    [PROC_SUPER_MAGIC, SYSFS_MAGIC].contains(&(fs.f_type as u64))
}

/// Reads an input file (scene or stage) as text: only a regular file of at most
/// [`MAX_FILE_BYTES`], so that `/dev/zero`, a FIFO or a runaway generated file is refused
/// at once instead of read until memory runs out. The error is the reason, without the path.
pub fn read_input(path: &Path) -> Result<String, String> {
    use std::io::Read;
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file".into());
    }
    if let Some(reason) = kernel_file(path) {
        return Err(reason);
    }
    let too_big =
        |n: u64| format!("{n} bytes, more than the {MAX_FILE_BYTES} an input file may have");
    if meta.len() > MAX_FILE_BYTES {
        return Err(too_big(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut text = String::new();
    // The file may grow between the check and the read: never read more than the limit.
    file.take(MAX_FILE_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(|e| e.to_string())?;
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(too_big(text.len() as u64));
    }
    Ok(text)
}

/// A TOML error as one line, `line L, column C: message`, without the quoted source line
/// that the parser's own text carries: an input can be any file (`/proc/self/environ`,
/// `/etc/passwd`), and an error must never print what it read. Control characters in the
/// message (a key can hold any) are escaped, so that nothing read reaches the terminal raw.
pub fn syntax_reason(error: &toml::de::Error, text: &str) -> String {
    let message = escape_controls(error.message().trim_end());
    match error.span() {
        Some(span) => {
            let before = &text.as_bytes()[..span.start.min(text.len())];
            let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
            let column = before.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
            format!("line {line}, column {column}: {message}")
        }
        None => message,
    }
}

/// `text` with every control character (ESC, CR, BEL, a newline ... but not a plain space)
/// written as an escape, so that a message quoting a file's key or value cannot move the
/// cursor, recolour, rewrite the terminal it is printed to, or start a line of its own that
/// passes for another message.
pub fn escape_controls(text: &str) -> String {
    text.chars()
        .flat_map(|c| match c.is_control() {
            true => c.escape_default().collect::<Vec<_>>(),
            false => vec![c],
        })
        .collect()
}
