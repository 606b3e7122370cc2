//! Radiance's C idioms, written once for every fenestra crate: `printf`'s `%g` and `%e` as
//! glibc prints them, C's `atof`, and running a command line with `sh -c`. No
//! dependencies: every other crate may use it.

mod atof;
mod printf;

pub use atof::atof;
pub use printf::{fmt_e, fmt_g, g_width, push_e, push_g, push_g_bytes};

/// A command that runs `cmd` with `sh -c`, as Radiance's `popen` and `system` do.
pub fn sh_c(cmd: &str) -> std::process::Command {
    let mut c = std::process::Command::new("sh");
    c.arg("-c").arg(cmd);
    c
}
