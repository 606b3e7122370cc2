//! Multicall entry: `fenestra TOOL [args…]` runs any fenestra tool in-process.
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args: Vec<String> = std::env::args().collect();
    let tools = fenestra::tools::registry();
    if args.len() < 2 || args[1] == "--help" || args[1] == "-h" {
        println!(
            "usage: fenestra TOOL [options…]   or   fenestra doc TOOL (its documentation)\ntools:"
        );
        for (name, _) in tools {
            println!("  {name}");
        }
        return ExitCode::SUCCESS;
    }
    if args[1] == "doc" {
        let Some(tool) = args.get(2) else {
            let names: Vec<&str> = fenestra::docs::PAGES.iter().map(|(n, _)| *n).collect();
            println!("usage: fenestra doc TOOL\npages: {}", names.join(" "));
            return ExitCode::SUCCESS;
        };
        return match fenestra::docs::page(tool) {
            Some(text) => {
                use std::io::Write;
                // a closed pipe (| head) ends the page quietly
                let _ = std::io::stdout().lock().write_all(text.as_bytes());
                ExitCode::SUCCESS
            }
            None => {
                eprintln!("fenestra: fatal - no documentation page '{tool}' (see 'fenestra doc')");
                ExitCode::from(1)
            }
        };
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
