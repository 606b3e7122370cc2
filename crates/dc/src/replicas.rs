//! Replica files (`rtcontrib -E -Er K`): K independent estimates of a matrix, interleaved
//! row by row, with their count in the header's `NREPLICAS=` line.

use anyhow::{bail, Result};
use fenestra_formats::matrix::Matrix;

/// Reads the replica file `name`: the matrix of all replica rows and K from its header
/// (warnings about the data go to fenestra's warning stream as they are noticed).
pub fn read(name: &str) -> Result<(Matrix, usize)> {
    let m = Matrix::read_reporting(name, fenestra_cli::warn_note)?;
    let k = match m.header.get("NREPLICAS") {
        Some(v) => v
            .trim()
            .parse()
            .map_err(|_| anyhow::anyhow!("{name}: NREPLICAS={v} is not a number of replicas"))?,
        None => {
            bail!("{name}: no NREPLICAS= line in the header: not a replica file of rtcontrib -Er")
        }
    };
    Ok((m, k))
}
