//! errplot: a log-log chart of error against run time, as SVG.
fn main() -> std::process::ExitCode {
    fenestra_cli::main_with(fenestra::tools::errplot::run)
}
