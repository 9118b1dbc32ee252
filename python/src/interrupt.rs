//! Work that runs without the GIL and stops on Ctrl-C.
//!
//! Python handles SIGINT by setting a flag that only the main thread, holding the GIL, can act
//! on. Two ways to honour it:
//! - [`on_this_thread`] (one scene): the work runs on the calling thread with the GIL
//!   released, and its stop check re-takes the GIL at most every [`POLL`] to ask Python
//!   whether a signal arrived. No thread is started, so a short scene pays nothing for it.
//! - [`interruptible`] (a sweep, whose rayon workers are other threads): the work runs on a
//!   worker thread while the calling thread waits with the GIL released, waking every
//!   [`POLL`] to ask; on a signal it raises the work's cancel flag and joins the worker.
//!
//! Either way simulations read the stop check at every sample through [`Watch`], the
//! signal's exception (`KeyboardInterrupt`) is raised, a panic becomes `SimulationError`,
//! and other Python threads run meanwhile, since the GIL is free.

use std::cell::{Cell, RefCell};
use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use pyo3::prelude::*;
use woodpile_sim::integrate::Observer;
use woodpile_sim::Model;

use crate::SimulationError;

/// How often the waiting thread checks for a signal: Ctrl-C stops work within about this
/// plus one sample interval of the slowest running scene.
const POLL: Duration = Duration::from_millis(50);

/// What the thread holding the GIL calls every [`POLL`] while work runs, and once when it is
/// done: a progress report. An error it returns stops the work and is raised, as a signal is.
pub(crate) type Poll<'a> = &'a (dyn Fn(Python<'_>) -> PyResult<()> + Sync);

/// A [`Poll`] that reports nothing.
pub(crate) fn quiet(_: Python<'_>) -> PyResult<()> {
    Ok(())
}

/// Runs `work` on this thread with the GIL released. `work` gets a stop check to poll (at
/// every sample): it is true once Python has a pending signal, whose exception is then raised.
/// `poll` runs whenever the stop check takes the GIL, and once at the end.
pub(crate) fn on_this_thread<T, F>(py: Python<'_>, poll: Poll<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&dyn Fn() -> bool) -> T + Send,
{
    let (result, signal) = py.detach(|| {
        let next_check = Cell::new(Instant::now() + POLL);
        let signal: RefCell<Option<PyErr>> = RefCell::new(None);
        let stop = || {
            if signal.borrow().is_some() {
                return true;
            }
            let now = Instant::now();
            if now < next_check.get() {
                return false;
            }
            next_check.set(now + POLL);
            match Python::attach(|py| py.check_signals().and_then(|()| poll(py))) {
                Ok(()) => false,
                Err(e) => {
                    *signal.borrow_mut() = Some(e);
                    true
                }
            }
        };
        let result = std::panic::catch_unwind(AssertUnwindSafe(|| work(&stop)));
        (result, signal.into_inner())
    });
    if let Some(signal) = signal {
        return Err(signal);
    }
    let result = result.map_err(|panic| internal_error(&panic))?;
    poll(py)?;
    Ok(result)
}

/// Runs `work` on a worker thread with the GIL released, raising the pending signal's
/// exception (after stopping the work) if one arrives, and `SimulationError` if it panics.
pub(crate) fn interruptible<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&AtomicBool) -> T + Send,
{
    match interruptible_keeping(py, &quiet, work)? {
        (_, Some(signal)) => Err(signal),
        (value, None) => Ok(value),
    }
}

/// [`interruptible`], keeping what the work returned after it was stopped: the work's value
/// and the signal's exception, if one arrived (a sweep's finished points survive Ctrl-C).
/// `poll` runs every [`POLL`] while the work runs, and once when it is done.
pub(crate) fn interruptible_keeping<T, F>(
    py: Python<'_>,
    poll: Poll<'_>,
    work: F,
) -> PyResult<(T, Option<PyErr>)>
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
                if let Err(signal) = py.check_signals().and_then(|()| poll(py)) {
                    cancel.store(true, Ordering::Relaxed);
                    interrupted = Some(signal);
                }
            }
        }
        if interrupted.is_none() {
            if let Err(e) = poll(py) {
                interrupted = Some(e);
            }
        }
        match (py.detach(|| worker.join()), interrupted) {
            (Ok(Ok(value)), interrupted) => Ok((value, interrupted)),
            (_, Some(signal)) => Err(signal),
            (Ok(Err(panic)) | Err(panic), None) => Err(internal_error(&panic)),
        }
    })
}

/// A panic as the exception Python sees.
fn internal_error(panic: &Box<dyn std::any::Any + Send>) -> PyErr {
    SimulationError::new_err(internal_message(panic))
}

/// What a panic's caller is told.
pub(crate) fn internal_message(panic: &Box<dyn std::any::Any + Send>) -> String {
    format!(
        "internal error (a bug in woodpile; please report it): {}",
        panic_message(panic)
    )
}

/// _panic_in_worker()
/// --
///
/// Panics on the worker thread, as a bug in the core would: the test suite's check that a
/// panic becomes a `SimulationError` and leaves the interpreter running.
#[cfg(feature = "testing")]
#[pyfunction]
#[pyo3(name = "_panic_in_worker")]
pub(crate) fn panic_in_worker(py: Python<'_>) -> PyResult<()> {
    let here = on_this_thread(py, &quiet, |_| -> () {
        panic!("deliberate panic on the calling thread")
    });
    let worker = interruptible(py, |_| -> () {
        panic!("deliberate panic on a worker thread")
    });
    here.and(worker)
}

/// The text of a panic's payload.
fn panic_message(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic".into())
}

/// An observer that also stops its run when `stop()` says so, and, with a `clock`, says
/// where the run is.
pub(crate) struct Watch<'a, O, C: Fn() -> bool + ?Sized> {
    pub(crate) inner: O,
    pub(crate) stop: &'a C,
    pub(crate) clock: Option<&'a Clock>,
}

impl<O: Observer, C: Fn() -> bool + ?Sized> Observer for Watch<'_, O, C> {
    fn observe(&mut self, model: &Model, t: f64, y: &[f64]) {
        self.inner.observe(model, t, y);
        if let Some(clock) = self.clock {
            clock.t.store(t.to_bits(), Ordering::Relaxed);
        }
    }
    fn reset(&mut self) {
        self.inner.reset();
        if let Some(clock) = self.clock {
            clock.runs.fetch_add(1, Ordering::Relaxed);
        }
    }
    fn cancelled(&self) -> bool {
        (self.stop)() || self.inner.cancelled()
    }
}

/// Where one scene's run is, for its progress line: the time of its last sample, and how
/// many runs `auto`'s ladder has started (each repeats the observation from t = 0).
#[derive(Debug, Default)]
pub(crate) struct Clock {
    t: AtomicU64,
    runs: AtomicUsize,
}

impl Clock {
    /// (run, t): the run under way (1 for the first) and its last sample's time.
    pub(crate) fn read(&self) -> (usize, f64) {
        (
            self.runs.load(Ordering::Relaxed) + 1,
            f64::from_bits(self.t.load(Ordering::Relaxed)),
        )
    }
}
