//! The scene file of `woodpile simulate` (docs/scene.md): TOML in two stages, ripgrep-style.
//!
//! `raw` mirrors the file exactly (`deny_unknown_fields`, no defaults applied); [`Scene`] is the
//! validated, typed result with the paper's defaults filled in and paper site numbers (-n..n)
//! translated to the simulator's 0-based indices. Every error names the file, the key and the
//! reason.
#![warn(missing_docs)]

pub mod columns;
pub mod cpu;
pub mod examples;
pub mod grid;
pub mod quantity;
mod raw;
pub mod report;
mod resolve;
pub mod sweep_grid;
pub mod template;
pub mod threads;
pub mod units_out;

pub use resolve::time::seconds;
pub use resolve::{DerivedDefect, Physical, Scene, DEFAULT_RESONATOR_SHARE};

use std::path::{Path, PathBuf};

/// A scene file that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read: {reason}")]
    Read {
        /// The file.
        file: PathBuf,
        /// The OS error.
        reason: String,
    },
    /// The TOML is malformed or has an unknown key or a value of the wrong type.
    #[error("{file}: {reason}")]
    Syntax {
        /// The file.
        file: PathBuf,
        /// The parser's message, with line, column and key.
        reason: String,
    },
    /// A key has a value the model cannot accept.
    #[error("{file}: key `{key}`: {reason}")]
    Invalid {
        /// The file.
        file: PathBuf,
        /// Dotted key path, e.g. `defect[1].eps`.
        key: String,
        /// Why the value is rejected.
        reason: String,
    },
}

/// Most defects a scene may have: a thousand times the paper's largest block, and few enough
/// that planning a sweep of such scenes never needs gigabytes.
pub const MAX_DEFECTS: usize = 10_000;

/// Largest scene or stage file accepted: a hundred times the largest the paper needs, and small
/// enough that parsing it never takes long or much memory.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Reads and validates the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = read_input(path).map_err(|reason| SceneError::Read {
        file: path.to_path_buf(),
        reason,
    })?;
    parse(&text, path)
}

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

/// Parses and validates scene TOML `text`; `path` only names the source in errors.
pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let raw: raw::SceneFile = toml::from_str(text).map_err(|e| SceneError::Syntax {
        file: path.to_path_buf(),
        reason: syntax_reason(&e, text),
    })?;
    validated(raw, path)
}

/// Validates a scene given as an already parsed TOML table (a pipeline sweep builds one per
/// parameter point); `path` only names the source in errors.
pub fn from_table(table: toml::Table, path: &Path) -> Result<Scene, SceneError> {
    let raw: raw::SceneFile =
        toml::Value::Table(table)
            .try_into()
            .map_err(|e: toml::de::Error| SceneError::Syntax {
                file: path.to_path_buf(),
                reason: escape_controls(e.message().trim_end()),
            })?;
    validated(raw, path)
}

fn validated(raw: raw::SceneFile, path: &Path) -> Result<Scene, SceneError> {
    resolve::resolve(raw).map_err(|(key, reason)| SceneError::Invalid {
        file: path.to_path_buf(),
        key,
        reason,
    })
}
