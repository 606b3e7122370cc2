//! dametrics: annual daylight metrics per sensor, with how far they can move within the errors.
fn main() -> std::process::ExitCode {
    fenestra_cli::main_with(fenestra::tools::dametrics::run)
}
