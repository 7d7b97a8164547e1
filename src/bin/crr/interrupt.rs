//! SIGINT (Ctrl-C) and SIGTERM for the long commands (`crr simulate`, `crr study`): the first
//! signal asks the run to stop and keep what it computed, a second one ends the process.

use crr::Cancel;

/// A flag set by the first SIGINT (Ctrl-C) or SIGTERM: the run stops within one integration step
/// (`crr::Cancel`) and writes what it computed. A second signal ends the process at once (exit 130), for a run that
/// does not come back.
pub(crate) fn interrupt_flag() -> Cancel {
    let cancel = Cancel::new();
    let flag = cancel.clone();
    // Without a handler (one is already installed) the signals keep their default action.
    let _ = ctrlc::set_handler(move || {
        if flag.is_cancelled() {
            std::process::exit(130);
        }
        flag.cancel();
    });
    cancel
}
