//! mkillum: illum proxy sources sampled through the scene.
fn main() -> std::process::ExitCode {
    fenestra_cli::main_with(fenestra::tools::mkillum::run)
}
