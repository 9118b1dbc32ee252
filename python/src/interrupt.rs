//! Work that runs without the GIL and stops on Ctrl-C.
//!
//! Python handles SIGINT by setting a flag that only the main thread, holding the GIL, can act
//! on. So the work runs on a worker thread while the calling thread waits with the GIL
//! released, waking every [`POLL`] to ask Python whether a signal arrived. When one did, the
//! work's cancel flag is raised (simulations read it at every sample through [`Watch`]), the
//! worker is joined, and the signal's exception (`KeyboardInterrupt`) is raised. Other Python
//! threads run meanwhile, since the GIL is free.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::prelude::*;
use woodpile_sim::integrate::Observer;
use woodpile_sim::Model;

use crate::SimulationError;

/// How often the waiting thread checks for a signal: Ctrl-C stops work within about this
/// plus one sample interval of the slowest running scene.
const POLL: Duration = Duration::from_millis(50);

/// Runs `work` on a worker thread with the GIL released, raising the pending signal's
/// exception (after stopping the work) if one arrives, and `SimulationError` if it panics.
pub(crate) fn interruptible<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&AtomicBool) -> T + Send,
{
    let cancel = AtomicBool::new(false);
    let done = AtomicBool::new(false);
    let waiter = std::thread::current();
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let result = std::panic::catch_unwind(AssertUnwindSafe(|| work(&cancel)));
            done.store(true, Ordering::Release);
            waiter.unpark();
            result
        });
        let mut interrupted = None;
        while !done.load(Ordering::Acquire) {
            py.detach(|| std::thread::park_timeout(POLL));
            if interrupted.is_none() {
                if let Err(signal) = py.check_signals() {
                    cancel.store(true, Ordering::Relaxed);
                    interrupted = Some(signal);
                }
            }
        }
        let result = py.detach(|| worker.join());
        if let Some(signal) = interrupted {
            return Err(signal);
        }
        match result {
            Ok(Ok(value)) => Ok(value),
            Ok(Err(panic)) | Err(panic) => Err(SimulationError::new_err(format!(
                "internal error (a bug in woodpile; please report it): {}",
                panic_message(&panic)
            ))),
        }
    })
}

/// _panic_in_worker()
/// --
///
/// Panics on the worker thread, as a bug in the core would: the test suite's check that a
/// panic becomes a `SimulationError` and leaves the interpreter running.
#[pyfunction]
#[pyo3(name = "_panic_in_worker")]
pub(crate) fn panic_in_worker(py: Python<'_>) -> PyResult<()> {
    interruptible(py, |_| -> () { panic!("deliberate panic (woodpile._core._panic_in_worker)") })
}

/// The text of a panic's payload.
pub(crate) fn panic_message(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic".into())
}

/// An observer that also stops its run when `cancel` is raised.
pub(crate) struct Watch<'a, O> {
    pub(crate) inner: O,
    pub(crate) cancel: &'a AtomicBool,
}

impl<O: Observer> Observer for Watch<'_, O> {
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]) {
        self.inner.observe(model, t, y);
    }
    fn reset(&mut self) {
        self.inner.reset();
    }
    fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed) || self.inner.cancelled()
    }
}
