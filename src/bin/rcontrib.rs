//! rcontrib: the same program as rtcontrib (Radiance installs both names).
fn main() -> std::process::ExitCode {
    fenestra_cli::main_with(fenestra::tools::rtcontrib::run)
}
