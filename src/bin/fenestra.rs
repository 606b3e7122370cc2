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
    fenestra_cli::set_prog(&args[0]);
    match fenestra_cli::expand::expand_args(args).and_then(run) {
        Ok(code) => code,
        Err(e) => {
            if let Some(fenestra_cli::Exit(code)) = e.downcast_ref::<fenestra_cli::Exit>() {
                return ExitCode::from(*code);
            }
            eprintln!("{}: fatal - {:#}", fenestra_cli::prog(), e);
            ExitCode::from(1)
        }
    }
}
