//! Tool entry points: one module per tool, each with
//! `pub fn run(args: Vec<String>) -> anyhow::Result<ExitCode>`.

use std::process::ExitCode;

pub mod checkbsdf;
pub mod dametrics;
pub mod dctimestep;
pub mod errplot;
pub mod genbsdf;
pub mod gendaylit;
pub mod gendaymtx;
pub mod genklemsamp;
pub mod gensky;
pub mod genskyvec;
pub mod getinfo;
pub mod hdr2png;
pub mod mkillum;
pub mod oconv;
pub mod pcomb;
pub mod rcalc;
pub mod rfluxmtx;
pub mod rmtxop;
pub mod rtcontrib;
pub mod rtrace;
pub mod total;
pub mod view_opts;
pub mod vwrays;
pub mod xform;

/// A tool's entry point.
pub type Run = fn(Vec<String>) -> anyhow::Result<ExitCode>;

/// Every tool by name (for the multicall `fenestra TOOL …` binary).
pub fn registry() -> &'static [(&'static str, Run)] {
    &[
        ("checkBSDF", checkbsdf::run),
        ("dametrics", dametrics::run),
        ("dctimestep", dctimestep::run),
        ("errplot", errplot::run),
        ("genBSDF", genbsdf::run),
        ("gendaylit", gendaylit::run),
        ("gendaymtx", gendaymtx::run),
        ("genklemsamp", genklemsamp::run),
        ("gensky", gensky::run),
        ("genskyvec", genskyvec::run),
        ("getinfo", getinfo::run),
        ("hdr2png", hdr2png::run),
        ("mkillum", mkillum::run),
        ("oconv", oconv::run),
        ("pcomb", pcomb::run),
        ("rcalc", rcalc::run),
        ("rcontrib", rtcontrib::run),
        ("rfluxmtx", rfluxmtx::run),
        ("rmtxop", rmtxop::run),
        ("rtcontrib", rtcontrib::run),
        ("rtrace", rtrace::run),
        ("total", total::run),
        ("vwrays", vwrays::run),
        ("xform", xform::run),
    ]
}
