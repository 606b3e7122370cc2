//! The base layer under fenestra's library crates and tools: what every one of them needs
//! of files and the process, and nothing of command lines — inputs (files, `-` and
//! `!command`), outputs written aside and renamed into place ([`output::AtomicFile`]), the
//! removal of such files on a signal, file lookup through RAYPATH, the `-f` letters of
//! number streams, and the program name and warnings (`prog: warning - …`). `fenestra-cli` builds the tools' conventions on it;
//! `fenestra-formats` and `fenestra-trace` use it directly.

pub mod cleanup;
pub mod diag;
pub mod input;
pub mod numfmt;
pub mod output;
pub mod raypath;

pub use diag::{prog, set_prog, set_warnings, warn, warn_note, warnings_on};
