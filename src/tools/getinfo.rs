//! getinfo (being written; see the open issues).

use std::process::ExitCode;

/// Runs getinfo.
pub fn run(_args: Vec<String>) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not implemented yet")
}
