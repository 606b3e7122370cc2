//! Progress on stderr for long runs: a bar with rate and ETA when stderr is a
//! terminal, nothing otherwise (pipelines and CI stay quiet).

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A progress bar that is hidden unless stderr is a terminal.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar for `total` units of work labelled `label`.
    pub fn new(total: u64, label: &str) -> Self {
        let bar = if std::io::stderr().is_terminal()
            && std::env::var_os("FENESTRA_NO_PROGRESS").is_none()
        {
            let b =
                ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr_with_hz(4));
            let style = ProgressStyle::with_template(
                "{msg} [{bar:30}] {human_pos}/{human_len} ({per_sec}, ETA {eta})",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
            b.set_style(style);
            b
        } else {
            ProgressBar::hidden()
        };
        bar.set_message(label.to_string());
        Progress { bar }
    }

    /// Starts over with `total` units labelled `label` (the next of several jobs).
    pub fn restart(&self, total: u64, label: &str) {
        self.bar.set_length(total);
        self.bar.set_position(0);
        self.bar.set_message(label.to_string());
        self.bar.reset_eta();
    }

    /// Whether anything is drawn.
    pub fn visible(&self) -> bool {
        !self.bar.is_hidden()
    }

    /// Adds `n` done units.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if !self.bar.is_finished() {
            self.bar.finish_and_clear();
        }
    }
}
