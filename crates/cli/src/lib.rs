//! Command-line conventions shared by every fenestra tool: Radiance-style options
//! (`-ab 4`, `-faf`, `-vd x y z`, `+f`/`-f`, `@optfile`), RAYPATH look-up, inputs
//! (`-`, `!command`), atomic output files, progress bars and error printing.

pub mod expand;
pub mod num;
pub mod opts;
pub mod printf;
pub mod progress;
pub mod rays;
mod run;

pub use fenestra_io::{cleanup, input, output, raypath};
pub mod threads;
pub use threads::{peak_memory_line, peak_rss_kb};

pub use run::{
    command_line, help_asked, main_with, main_with_args, prog, quote_word, set_prog, set_warnings,
    warn, warn_note, warnings_on, Exit,
};
