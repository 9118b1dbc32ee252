//! The worker threads of sweeps. rayon's global pool is started once, with the size
//! `RAYON_NUM_THREADS` asks for after it is validated (rayon alone takes 100000, spends
//! seconds making threads and panics, and every later sweep then fails). A process forked
//! after the pool started (`multiprocessing`'s default on Linux up to Python 3.13) has the
//! pool's bookkeeping but none of its threads, so a parallel loop there would wait for ever:
//! it gets a pool of its own instead.

use std::sync::OnceLock;

/// The process that started the global pool.
static STARTED_IN: OnceLock<u32> = OnceLock::new();

/// Runs `work` (which uses rayon's parallel iterators) on a working pool, or says why none
/// can be started.
pub(crate) fn run_parallel<T: Send>(work: impl FnOnce() -> T + Send) -> Result<T, String> {
    let here = std::process::id();
    let asked = woodpile_scene::threads::asked_threads()?;
    let builder = || {
        let builder = rayon::ThreadPoolBuilder::new();
        match asked {
            Some(n) => builder.num_threads(n),
            None => builder,
        }
    };
    if STARTED_IN.get().is_none() {
        // Another library may have started the global pool already: then it is used as is.
        let _ = builder().build_global();
        let _ = STARTED_IN.set(here);
    }
    if STARTED_IN.get() == Some(&here) {
        return Ok(work());
    }
    let pool = builder()
        .build()
        .map_err(|e| format!("cannot start the worker threads: {e}"))?;
    Ok(pool.install(work))
}
