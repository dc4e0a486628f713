//! What the job shows and keeps of its own progress: a spinner or bar on a terminal
//! naming the running stage, and the stopwatch that times each stage for the report.

use std::time::{Duration, Instant};

use crate::config::Job;

/// A spinner on stderr naming the running stage with its time so far, a bar for the
/// stages that say how far they have got (the nest, the sheets' drawing): only when
/// stderr is a terminal and the job is not `--quiet`, so Make and CI logs stay as they
/// were. Cleared when dropped, whatever the outcome.
pub(super) struct Progress(Option<indicatif::ProgressBar>);

/// Steps of a progress bar.
const BAR_STEPS: u64 = 1000;

impl Progress {
    pub(super) fn new(job: &Job) -> Self {
        use std::io::IsTerminal;
        if job.quiet || !std::io::stderr().is_terminal() {
            return Progress(None);
        }
        let bar = indicatif::ProgressBar::new_spinner();
        bar.enable_steady_tick(Duration::from_millis(120));
        Progress(Some(bar))
    }

    /// Names the stage now running, with a spinner (and for an internal error's
    /// message).
    pub(super) fn stage(&self, what: &str) {
        crate::internal::enter_stage(what);
        if let Some(bar) = &self.0 {
            if let Ok(style) =
                indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
            {
                bar.set_style(style);
            }
            bar.reset_elapsed();
            bar.set_message(what.to_string());
        }
    }

    /// Names the stage now running, with a bar that [`Progress::set`] fills.
    pub(super) fn bar(&self, what: &str) {
        crate::internal::enter_stage(what);
        if let Some(bar) = &self.0 {
            // In this order, so no frame mixes the old stage's name or style with the
            // new one's.
            bar.set_length(BAR_STEPS);
            bar.set_position(0);
            let template = "{spinner} {msg} [{bar:30}] {percent:>3} % ({elapsed})";
            if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.reset_elapsed();
            bar.set_message(what.to_string());
        }
    }

    /// The bar's stage has done `done` (0 to 1) of its work.
    pub(super) fn set(&self, done: f64) {
        if let Some(bar) = &self.0 {
            bar.set_position((done.clamp(0.0, 1.0) * BAR_STEPS as f64) as u64);
        }
    }

    /// Runs `f` (which prints) with the spinner off the screen.
    pub(super) fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.0 {
            Some(bar) => bar.suspend(f),
            None => f(),
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}

pub(super) struct Stopwatch {
    last: Instant,
    pub(super) times: Vec<(&'static str, Duration)>,
}

impl Stopwatch {
    pub(super) fn new() -> Self {
        Self {
            last: Instant::now(),
            times: Vec::new(),
        }
    }

    pub(super) fn lap(&mut self, stage: &'static str) {
        let now = Instant::now();
        self.times.push((stage, now - self.last));
        self.last = now;
    }
}
