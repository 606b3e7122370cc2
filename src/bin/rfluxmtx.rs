//! rfluxmtx: sender/receiver flux-transfer matrices over the contribution engine.
fn main() -> std::process::ExitCode {
    fenestra_cli::main_with(fenestra::tools::rfluxmtx::run)
}
