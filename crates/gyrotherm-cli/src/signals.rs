//! Interrupted runs leave no partial output: on SIGINT, SIGTERM or SIGHUP the temporary
//! files being written are removed, then the process ends as that signal would have ended it.

/// Install the handler (a thread that waits for the signals). Without it (e.g. signals
/// cannot be registered) the program still runs; an interrupted write then leaves its
/// hidden temporary file behind, as a SIGKILL always does.
pub fn remove_temp_files_on_termination() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        use signal_hook::iterator::Signals;
        let Ok(mut signals) = Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return;
        };
        let spawned = std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                if let Some(sig) = signals.forever().next() {
                    gyrotherm::atomic_file::remove_temp_files();
                    let _ = signal_hook::low_level::emulate_default_handler(sig);
                    // Not reached when the default action ended the process.
                    std::process::exit(128 + sig);
                }
            });
        drop(spawned);
    }
}
