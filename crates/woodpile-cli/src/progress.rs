//! Pipeline progress on stderr: an indicatif bar per sweep on a terminal (scenes done,
//! scenes/s, ETA), and a plain line every few seconds otherwise (CI logs, `make` in a pipe),
//! where a bar would be invisible or garble the log.

use std::collections::HashMap;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use woodpile_pipeline::events::Events;

/// How often the plain progress line is printed.
const PLAIN_EVERY: Duration = Duration::from_secs(5);

/// The CLI's [`Events`].
pub(crate) struct Progress {
    terminal: bool,
    sweep: Mutex<Option<Sweep>>,
    done: AtomicUsize,
    /// When each running stage started, for its `done` line (stages run side by side).
    started: Mutex<HashMap<String, Instant>>,
}

struct Sweep {
    stage: String,
    total: usize,
    started: Instant,
    last_line: Instant,
    bar: Option<ProgressBar>,
}

impl Progress {
    pub(crate) fn new() -> Self {
        Self {
            terminal: std::io::stderr().is_terminal(),
            sweep: Mutex::new(None),
            done: AtomicUsize::new(0),
            started: Mutex::new(HashMap::new()),
        }
    }

    /// Prints `text` (control characters escaped: it may quote a stage file) above the bar.
    fn line(&self, text: &str) {
        let text = &woodpile_files::input::escape_controls(text);
        let sweep = self.sweep.lock().ok();
        match sweep
            .as_ref()
            .and_then(|s| s.as_ref())
            .and_then(|s| s.bar.as_ref())
        {
            Some(bar) => bar.println(text),
            None => eprintln!("{text}"),
        }
    }
}

fn plain_line(s: &Sweep, done: usize) -> String {
    let elapsed = s.started.elapsed().as_secs_f64();
    let rate = done as f64 / elapsed.max(1e-9);
    let eta = if rate > 0.0 {
        (s.total - done) as f64 / rate
    } else {
        f64::INFINITY
    };
    format!(
        "  {}: {done}/{} scenes ({:.0}%), {rate:.1} scenes/s, ETA {eta:.0} s",
        s.stage,
        s.total,
        100.0 * done as f64 / s.total.max(1) as f64
    )
}

impl Events for Progress {
    fn stage_started(&self, stage: &str, why: &str) {
        if let Ok(mut started) = self.started.lock() {
            started.insert(stage.to_string(), Instant::now());
        }
        self.line(&format!("run {stage}: {why}"));
    }

    fn simulating(&self, stage: &str, to_simulate: usize, cached: usize) {
        self.line(&format!(
            "  {stage}: {to_simulate} scenes to simulate, {cached} cached"
        ));
        self.done.store(0, Ordering::SeqCst);
        let bar = (self.terminal && to_simulate > 0).then(|| {
            let bar = ProgressBar::with_draw_target(
                Some(to_simulate as u64),
                ProgressDrawTarget::stderr(),
            );
            if let Ok(style) = ProgressStyle::with_template(
                "  {prefix} [{bar:30}] {pos}/{len} scenes, {per_sec}, ETA {eta}",
            ) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.set_prefix(stage.to_string());
            bar
        });
        if let Ok(mut s) = self.sweep.lock() {
            *s = Some(Sweep {
                stage: stage.to_string(),
                total: to_simulate,
                started: Instant::now(),
                last_line: Instant::now(),
                bar,
            });
        }
    }

    fn point_done(&self) {
        let done = self.done.fetch_add(1, Ordering::SeqCst) + 1;
        // Never block a worker on the lock: a skipped update is harmless.
        let Ok(mut guard) = self.sweep.try_lock() else {
            return;
        };
        let Some(s) = guard.as_mut() else { return };
        match &s.bar {
            Some(bar) => bar.set_position(done as u64),
            None if s.last_line.elapsed() >= PLAIN_EVERY => {
                s.last_line = Instant::now();
                eprintln!("{}", plain_line(s, done));
            }
            None => {}
        }
    }

    fn stage_finished(&self, stage: &str, summary: &str) {
        // Only the stage that owns the progress bar clears it: stages run side by side.
        if let Ok(mut guard) = self.sweep.lock() {
            if let Some(s) = guard.take_if(|s| s.stage == stage) {
                if let Some(bar) = s.bar {
                    bar.finish_and_clear();
                }
                if s.total > 0 {
                    let secs = s.started.elapsed().as_secs_f64();
                    eprintln!(
                        "  {stage}: simulated {} scenes in {secs:.1} s ({:.1} scenes/s)",
                        s.total,
                        s.total as f64 / secs.max(1e-9)
                    );
                }
            }
        }
        let secs = self
            .started
            .lock()
            .ok()
            .and_then(|mut started| started.remove(stage))
            .map(|t| t.elapsed().as_secs_f64());
        match secs {
            Some(secs) => eprintln!("done {stage}: {summary} ({secs:.1} s)"),
            None => eprintln!("done {stage}: {summary}"),
        }
    }

    fn stage_skipped(&self, stage: &str) {
        eprintln!("fresh {stage}");
    }

    fn warn(&self, message: &str) {
        self.line(&format!("warning: {message}"));
    }
}
