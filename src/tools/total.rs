//! total (being written; see the open issues).

use std::process::ExitCode;

/// Runs total.
pub fn run(_args: Vec<String>) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not implemented yet")
}
