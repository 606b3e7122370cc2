//! Tool entry points: one module per tool, each with
//! `pub fn run(args: Vec<String>) -> anyhow::Result<ExitCode>`.

use std::process::ExitCode;

pub mod gendaylit;
pub mod gendaymtx;
pub mod gensky;
pub mod genskyvec;
pub mod oconv;
pub mod pcomb;
pub mod rcalc;
pub mod rtrace;
pub mod view_opts;
pub mod vwrays;
pub mod xform;

/// A tool's entry point.
pub type Run = fn(Vec<String>) -> anyhow::Result<ExitCode>;

/// Every tool by name (for the multicall `fenestra TOOL …` binary).
pub fn registry() -> &'static [(&'static str, Run)] {
    &[
        ("gendaymtx", gendaymtx::run),
        ("gensky", gensky::run),
        ("genskyvec", genskyvec::run),
        ("oconv", oconv::run),
        ("pcomb", pcomb::run),
        ("rcalc", rcalc::run),
        ("rtrace", rtrace::run),
        ("vwrays", vwrays::run),
        ("xform", xform::run),
    ]
}
