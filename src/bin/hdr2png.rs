//! hdr2png: a Radiance picture as a PNG (tone-mapped or false colour).
fn main() -> std::process::ExitCode {
    fenestra_cli::main_with(fenestra::tools::hdr2png::run)
}
