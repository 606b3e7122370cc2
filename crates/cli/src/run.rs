//! The entry point wrapper every tool binary calls, program name and messages.

use std::process::ExitCode;

pub use fenestra_io::diag::{prog, set_prog, set_warnings, warn, warn_note, warnings_on};

/// A request to end the program quietly with the given status (e.g. after `--help`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Exit(pub u8);

impl std::fmt::Display for Exit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "exit status {}", self.0)
    }
}

impl std::error::Error for Exit {}

/// Runs a tool: expands `@file`/`$VAR` arguments, sets the program name, and turns
/// an error into `prog: fatal - message` with exit status 1.
pub fn main_with(run: fn(Vec<String>) -> anyhow::Result<ExitCode>) -> ExitCode {
    let raw: Vec<String> = std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    main_with_args(raw, run)
}

/// [`main_with`] for given arguments (the first is the program name): the multicall
/// `fenestra TOOL …` runs its tools through this, with the same messages and exit codes.
pub fn main_with_args(
    raw: Vec<String>,
    run: fn(Vec<String>) -> anyhow::Result<ExitCode>,
) -> ExitCode {
    if let Some(p) = raw.first() {
        set_prog(p);
    }
    let args = match crate::expand::expand_args(raw) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{}: fatal - {:#}", prog(), e);
            return ExitCode::from(1);
        }
    };
    // the tool and rayon's global workers run on threads with deep stacks (deeply nested
    // .cal expressions)
    let _ = rayon::ThreadPoolBuilder::new()
        .stack_size(crate::threads::STACK_BYTES)
        .build_global();
    let result = std::thread::Builder::new()
        .name("main".into())
        .stack_size(crate::threads::STACK_BYTES)
        .spawn(move || run(args))
        .map_err(anyhow::Error::from)
        .and_then(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)));
    match result {
        Ok(code) => code,
        Err(e) => {
            if let Some(Exit(code)) = e.downcast_ref::<Exit>() {
                return ExitCode::from(*code);
            }
            if is_broken_pipe(&e) {
                // A closed downstream pipe (e.g. `| head`) is not an error worth a message.
                return ExitCode::from(1);
            }
            eprintln!("{}: fatal - {:#}", prog(), e);
            ExitCode::from(1)
        }
    }
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Formats arguments as Radiance's `printargs` writes a command line into a header:
/// words separated by one space, a word quoted when empty or containing white space.
pub fn command_line(args: &[String]) -> String {
    let mut out = String::new();
    for (i, a) in args.iter().enumerate() {
        if i > 0 {
            out.push(' ');
        }
        let word = if i == 0 {
            std::path::Path::new(a)
                .file_name()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| a.clone())
        } else {
            a.clone()
        };
        out.push_str(&quote_word(&word));
    }
    out
}

/// A word as Radiance's `fputword` writes it: quoted when empty, when it holds white
/// space, or when a quote mark stands inside it (not first, not last); in single quotes
/// when the last such inner mark is a double quote, else in double quotes.
pub fn quote_word(w: &str) -> String {
    let b = w.as_bytes();
    let mut quote = None;
    for (i, &c) in b.iter().enumerate() {
        if i > 0 && i + 1 < b.len() {
            if c == b'"' {
                quote = Some('\'');
            } else if c == b'\'' {
                quote = Some('"');
            }
        }
    }
    let space = b.iter().any(|c| c.is_ascii_whitespace() || *c == 0x0b);
    match (w.is_empty() || space, quote) {
        (_, Some(q)) => format!("{q}{w}{q}"),
        (true, None) => format!("\"{w}\""),
        (false, None) => w.to_string(),
    }
}

/// When `--help` is among the arguments after the program name: prints
/// `prog usage` and `text` on standard output and returns true (the tool then ends).
pub fn help_asked(args: &[String], usage: &str, text: &str) -> bool {
    if !args.iter().skip(1).any(|a| a == "--help") {
        return false;
    }
    println!("{} {usage}\n{text}", prog());
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn command_line_quotes_words_with_spaces() {
        let args: Vec<String> = ["/usr/bin/rmtxop", "-c", "a b", "", "x\"y z"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(command_line(&args), "rmtxop -c \"a b\" \"\" 'x\"y z'");
    }

    #[test]
    fn words_are_quoted_as_radiance_s_fputword() {
        // an inner quote mark (not first, not last) quotes with the other mark; a quote
        // mark at either end alone does not
        assert_eq!(quote_word("it's"), "\"it's\"");
        assert_eq!(quote_word("say \"hi\""), "'say \"hi\"'");
        assert_eq!(quote_word("\"a\""), "\"a\"");
        assert_eq!(quote_word("a'"), "a'");
        assert_eq!(quote_word("$1=$1*2"), "$1=$1*2");
        assert_eq!(quote_word("a\tb"), "\"a\tb\"");
    }
}
