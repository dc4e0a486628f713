//! A panic is a bug of unfold, never the user's mistake: the command line catches it
//! and reports one line naming the stage that was running and the panel it was
//! working on, with exit code 1 and nothing written to the output folder (files are
//! only written whole at the end of a run). The Rust panic message and backtrace show
//! only when asked for with `RUST_BACKTRACE`.
//!
//! The stage is one for the whole process (stages run one after another); the panel
//! is the worker thread's own, set around each panel's work.

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

use crate::error::{Error, Result};

/// The stage now running, as the progress line names it.
static STAGE: Mutex<String> = Mutex::new(String::new());

/// The ids of the panels, in the order the stages number them.
static PANEL_IDS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// What the panic hook saw of the first panic.
static CAUGHT: Mutex<Option<Caught>> = Mutex::new(None);

thread_local! {
    /// The panel this thread is working on.
    static PANEL: Cell<Option<usize>> = const { Cell::new(None) };
}

/// Where a panic happened and what it said.
#[derive(Clone, Debug)]
struct Caught {
    panel: Option<usize>,
    message: String,
}

/// Names the stage now running.
pub fn enter_stage(what: &str) {
    let mut stage = lock(&STAGE);
    stage.clear();
    stage.push_str(what);
}

/// Gives the ids of the panels that later stages number 0, 1, …
pub fn name_panels(ids: impl IntoIterator<Item = String>) {
    *lock(&PANEL_IDS) = ids.into_iter().collect();
}

/// Runs `work` on panel `index`: a panic inside it names that panel.
pub fn for_panel<R>(index: usize, work: impl FnOnce() -> R) -> R {
    let outer = PANEL.with(|p| p.replace(Some(index)));
    inject_panic(index);
    let result = work();
    PANEL.with(|p| p.set(outer));
    result
}

/// Builds with debug assertions (the test builds) panic on purpose at the first panel
/// of the stage whose name contains `UNFOLD_INJECT_PANIC`, so the tests can check
/// what a user sees of a bug.
fn inject_panic(index: usize) {
    #[cfg(debug_assertions)]
    if index == 0 {
        if let Ok(wanted) = std::env::var("UNFOLD_INJECT_PANIC") {
            if !wanted.is_empty() && lock(&STAGE).contains(&wanted) {
                panic!("panic injected by UNFOLD_INJECT_PANIC={wanted}");
            }
        }
    }
    #[cfg(not(debug_assertions))]
    let _ = index;
}

/// Records every panic for [`catch`], and prints Rust's own panic message and
/// backtrace only when `RUST_BACKTRACE` asks for them. For the binary: a library
/// user's panics stay theirs.
pub fn install_hook() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let text = payload_text(info.payload());
        let message = match info.location() {
            Some(at) => format!("{text} (at {}:{})", at.file(), at.line()),
            None => text,
        };
        let mut caught = lock(&CAUGHT);
        if caught.is_none() {
            *caught = Some(Caught {
                panel: PANEL.with(Cell::get),
                message,
            });
        }
        drop(caught);
        if std::env::var("RUST_BACKTRACE").is_ok_and(|v| !v.is_empty() && v != "0") {
            default(info);
        }
    }));
}

/// Runs `work`, turning a panic inside it into [`Error::Panic`].
pub fn catch<R>(work: impl FnOnce() -> Result<R>) -> Result<R> {
    *lock(&CAUGHT) = None;
    match catch_unwind(AssertUnwindSafe(work)) {
        Ok(result) => result,
        Err(payload) => {
            let caught = lock(&CAUGHT).take();
            let message = caught
                .as_ref()
                .map_or_else(|| payload_text(payload.as_ref()), |c| c.message.clone());
            let panel = caught
                .and_then(|c| c.panel)
                .map(|i| lock(&PANEL_IDS).get(i).cloned().unwrap_or(format!("#{i}")));
            let stage = lock(&STAGE).clone();
            Err(Error::Panic {
                stage: if stage.is_empty() {
                    "starting".to_string()
                } else {
                    stage
                },
                panel,
                message: message.split_whitespace().collect::<Vec<_>>().join(" "),
            })
        }
    }
}

/// What a panic said: its message when it is text.
fn payload_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".to_string())
}

/// The guarded value, also after a panic elsewhere poisoned the lock.
fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|e| e.into_inner())
}
