//! The number of worker threads a user asked for with `RAYON_NUM_THREADS`, validated once for
//! the command line and the Python module alike: rayon itself takes any number, and a huge one
//! spends seconds creating threads and then panics.

/// Most worker threads `RAYON_NUM_THREADS` may ask for.
pub const MAX_THREADS: usize = 1024;

/// `Ok(None)` when `RAYON_NUM_THREADS` is unset (one thread per core), `Ok(Some(n))` for a
/// whole number from 0 (all cores) to [`MAX_THREADS`], else the reason it is refused.
pub fn asked_threads() -> Result<Option<usize>, String> {
    let Some(text) = std::env::var_os("RAYON_NUM_THREADS") else {
        return Ok(None);
    };
    let text = text.to_string_lossy();
    match text.trim().parse::<usize>() {
        Ok(n) if n <= MAX_THREADS => Ok(Some(n)),
        _ => Err(format!(
            "RAYON_NUM_THREADS=`{}`: expected a whole number from 0 (all cores) to {MAX_THREADS}",
            crate::escape_controls(&text)
        )),
    }
}
