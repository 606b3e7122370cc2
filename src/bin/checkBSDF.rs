//! checkBSDF (binary named as Radiance's).
#![allow(non_snake_case)]
fn main() -> std::process::ExitCode {
    fenestra_cli::main_with(fenestra::tools::checkbsdf::run)
}
