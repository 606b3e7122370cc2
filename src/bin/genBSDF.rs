fn main() -> std::process::ExitCode {
    fenestra_cli::main_with(fenestra::tools::genbsdf::run)
}
