//! A spinner for work that may take long (an exact best-subset search): the work runs on
//! the calling thread (a worker of the thread pool, so the library's parallel passes start at
//! once); if it is not done within a second, an indicatif spinner shows what is being done and
//! for how long. The library itself never prints.

use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// Runs `work`, with a spinner labelled `label` once it has taken more than a second.
pub fn with_spinner<T>(label: &str, work: impl FnOnce() -> T) -> T {
    let (done, finished) = mpsc::channel::<()>();
    // `done` moves into the scope: a panic in `work` drops it while unwinding, which ends the
    // spinner thread, so the scope's join does not wait for ever
    std::thread::scope(move |scope| {
        let done = done;
        scope.spawn(move || {
            // the work ended (sent or, on a panic, dropped the sender) within the second
            if !matches!(finished.recv_timeout(Duration::from_secs(1)), Err(RecvTimeoutError::Timeout)) {
                return;
            }
            let bar = ProgressBar::new_spinner();
            bar.set_style(
                ProgressStyle::with_template("{spinner} {elapsed:>4} {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.set_message(label.to_string());
            bar.enable_steady_tick(Duration::from_millis(120));
            let _ = finished.recv();
            bar.finish_and_clear();
        });
        // the crash path's regression test makes the work panic (tests/integration/hostile.rs)
        if std::env::var_os("TERMID_TEST_PANIC").is_some() {
            panic!("TERMID_TEST_PANIC is set");
        }
        let result = work();
        let _ = done.send(());
        result
    })
}

/// A counting progress bar on standard error for `len` items of repeated work (drawn only
/// when standard error is a terminal).
pub fn counter(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} {elapsed:>4}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(what.to_string());
    bar
}
