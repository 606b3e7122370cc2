//! The worker count of `-n N`: at least one, at most the machine's cores (more threads
//! than cores cannot help, and results are the same for any count).

use anyhow::{bail, Result};

/// Stack size of the threads that run a tool and its workers: deep enough for the
/// recursion of expressions nested to the .cal parser's limit (50 000 levels) and for
/// dropping such trees. Only the pages used are committed.
pub const STACK_BYTES: usize = 1 << 30;

/// A worker pool of `n` threads with [`STACK_BYTES`] stacks.
pub fn pool(n: usize) -> Result<rayon::ThreadPool> {
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .stack_size(STACK_BYTES)
        .build()?)
}

/// Threads for a request of `n` processes: an error below 1, capped at the cores
/// available with a warning.
pub fn worker_count(n: f64) -> Result<usize> {
    if n.is_nan() || n < 1.0 {
        bail!("-n {n}: illegal number of processes (at least 1)");
    }
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    if n > cores as f64 {
        crate::warn(format!(
            "-n {n}: more processes than the {cores} core(s) here; using {cores} (the output is the same for any -n)"
        ));
        return Ok(cores);
    }
    Ok(n as usize)
}

/// The `-v` line on memory: `peak resident memory X MB` (`None` where the system does not say).
pub fn peak_memory_line() -> Option<String> {
    peak_rss_kb().map(|kb| format!("peak resident memory {:.1} MB", kb as f64 / 1024.0))
}

/// Peak resident memory of this process in kilobytes (Linux `VmHWM`); `None` where the
/// system does not say.
pub fn peak_rss_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

#[cfg(test)]
mod tests {
    #[test]
    fn bounds() {
        assert!(super::worker_count(0.0).is_err());
        assert!(super::worker_count(-1.0).is_err());
        assert!(super::worker_count(f64::NAN).is_err());
        assert_eq!(super::worker_count(1.0).unwrap(), 1);
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        assert_eq!(super::worker_count(1e9).unwrap(), cores);
    }
}
