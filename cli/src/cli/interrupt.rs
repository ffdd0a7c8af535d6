//! Ctrl-C (SIGINT), SIGTERM and SIGHUP during a long run (`simulate`, `workprec`): the first
//! signal sets a flag that the run's loop polls between steps, so the run stops cleanly — it
//! keeps what it computed, reports where it stopped and exits with
//! [`super::EXIT_INTERRUPTED`]; a second signal ends the process at once with the same status.
//! The handler is the `ctrlc` crate's (its `termination` feature adds SIGTERM and SIGHUP).

use super::EXIT_INTERRUPTED;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

static STOP: AtomicBool = AtomicBool::new(false);

/// Installs the handler (once per process). Where the system refuses it, the signals keep their
/// default action (the process ends; output files are still never half-replaced, see
/// [`super::output_file`]).
pub fn watch() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            if STOP.swap(true, Ordering::Relaxed) {
                // The second signal: the user insists.
                std::process::exit(i32::from(EXIT_INTERRUPTED));
            }
        });
    });
}

/// Whether a signal asked the run to stop (one relaxed atomic load: cheap enough for every step).
#[inline]
pub fn requested() -> bool {
    STOP.load(Ordering::Relaxed)
}
