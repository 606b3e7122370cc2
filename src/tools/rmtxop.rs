//! rmtxop (being written; see the open issues).

use std::process::ExitCode;

/// Runs rmtxop.
pub fn run(_args: Vec<String>) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not implemented yet")
}
