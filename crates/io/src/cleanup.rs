//! Temporary files removed when the process is interrupted (SIGINT, SIGTERM, SIGHUP):
//! outputs written aside by [`crate::output::AtomicFile`] register here while they are
//! incomplete, so a killed run leaves no hidden partial file behind.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once};

static FILES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static INSTALL: Once = Once::new();

/// Registers a temporary file to remove on interruption (and installs the handler once).
pub fn register(path: &Path) {
    install();
    if let Ok(mut f) = FILES.lock() {
        f.push(path.to_path_buf());
    }
}

/// Forgets a temporary file (it was renamed into place or removed).
pub fn unregister(path: &Path) {
    if let Ok(mut f) = FILES.lock() {
        f.retain(|p| p != path);
    }
}

/// Installs the interruption handler: a thread that waits for the signals, removes the
/// registered files, and ends the process as the signal would have.
fn install() {
    INSTALL.call_once(|| {
        #[cfg(unix)]
        {
            use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
            let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
            else {
                return;
            };
            std::thread::spawn(move || {
                if let Some(sig) = signals.forever().next() {
                    if let Ok(files) = FILES.lock() {
                        for p in files.iter() {
                            let _ = std::fs::remove_file(p);
                        }
                    }
                    let _ = signal_hook::low_level::emulate_default_handler(sig);
                    std::process::exit(128 + sig);
                }
            });
        }
    });
}
