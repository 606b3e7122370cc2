//! Multicall entry: `fenestra TOOL [args…]` runs any fenestra tool in-process.
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args: Vec<String> = std::env::args().collect();
    let tools = fenestra::tools::registry();
    if args.len() < 2 || args[1] == "--help" || args[1] == "-h" {
        println!("usage: fenestra TOOL [options…]\ntools:");
        for (name, _) in tools {
            println!("  {name}");
        }
        return ExitCode::SUCCESS;
    }
    args.remove(0);
    let Some((_, run)) = tools.iter().find(|(n, _)| *n == args[0]) else {
        eprintln!(
            "fenestra: fatal - unknown tool '{}' (see 'fenestra --help')",
            args[0]
        );
        return ExitCode::from(1);
    };
    // the same entry as the single binaries: messages, exit codes, a closed pipe, deep
    // stacks and interrupted outputs alike
    fenestra_cli::main_with_args(args, *run)
}
