//! The program name used in messages, and warnings as Radiance's tools print them.

use std::sync::OnceLock;

static PROG: OnceLock<String> = OnceLock::new();
static WARNINGS: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(true);

/// Whether warnings are printed.
pub fn warnings_on() -> bool {
    WARNINGS.load(std::sync::atomic::Ordering::Relaxed)
}

/// Turns warnings on or off (Radiance's `-w`).
pub fn set_warnings(on: bool) {
    WARNINGS.store(on, std::sync::atomic::Ordering::Relaxed);
}

/// Sets the program name used in messages (done by fenestra-cli's `main_with`; tests may call it).
pub fn set_prog(name: &str) {
    let base = std::path::Path::new(name)
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| name.to_string());
    let _ = PROG.set(base);
}

/// The program name used in messages (`fenestra` until set).
pub fn prog() -> &'static str {
    PROG.get().map(String::as_str).unwrap_or("fenestra")
}

/// [`warn`] for one owned message, usable as a `fn(String)` (a library's warning sink,
/// e.g. `MatrixReader::report_to`).
pub fn warn_note(msg: String) {
    warn(msg);
}

/// Prints `prog: warning - msg` on stderr, as Radiance tools do.
pub fn warn(msg: impl std::fmt::Display) {
    if !WARNINGS.load(std::sync::atomic::Ordering::Relaxed) {
        return;
    }
    eprintln!("{}: warning - {}", prog(), msg);
}
