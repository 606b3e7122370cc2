//! getinfo: print the information header of Radiance files, strip it, add lines to it,
//! or print a picture's (or matrix's) dimensions.

use std::io::{BufReader, Write};
use std::process::ExitCode;

use anyhow::{Context, Result};
use fenestra_formats::dimensions::{is_picture, read_resolution};
use fenestra_formats::header::Header;

const HELP: &str = "getinfo: print or strip Radiance information headers

Usage:
  getinfo file ..          print each file's header: 'file:' then its lines, indented by a tab
  getinfo                  print the header of the standard input
  getinfo -                copy the standard input without its header
  getinfo -a line ..       copy the standard input, adding these lines to its header
  getinfo -d file ..       print each picture's resolution ('file: -Y rows +X columns'),
                           or a matrix's shape ('file: NROWS=r NCOLS=c NCOMP=n')
  getinfo -d               the same for the standard input
  getinfo -d -             copy a picture from the standard input without header and resolution
  getinfo [+d|-d] -c command args ..
                           print the standard input's header with the command line added, then
                           run the command on the data (+d: the picture resolution string kept
                           in the header's place, -d: dropped)
";

/// Runs getinfo.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let rest = &args[1..];
    if rest
        .first()
        .is_some_and(|a| a == "--help" || a == "-help" || a == "-h")
    {
        print!("{HELP}");
        return Ok(ExitCode::SUCCESS);
    }
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::with_capacity(1 << 16, stdout.lock());
    // [+d|-d] -c command ..: the header, then the command run on the data
    let (dim, after) = match rest.first().map(String::as_str) {
        Some("+d") => (Some(true), &rest[1..]),
        Some("-d") if rest.get(1).is_some_and(|a| a == "-c") => (Some(false), &rest[1..]),
        _ => (None, rest),
    };
    if after.len() > 1 && after[0] == "-c" {
        return run_command(&mut out, dim, &after[1..]);
    }
    let ok = match rest.first().map(String::as_str) {
        None => {
            let mut r = stdin_reader();
            let h = Header::read(&mut r, "<stdin>")?;
            h.write(&mut out, None)?;
            true
        }
        Some("-") if rest.len() == 1 => {
            let mut r = stdin_reader();
            Header::read(&mut r, "<stdin>")?;
            std::io::copy(&mut r, &mut out).context("cannot copy the data")?;
            true
        }
        Some("-a") => {
            let mut r = stdin_reader();
            let h = Header::read(&mut r, "<stdin>")?;
            // the data format line goes last, rewritten without padding (as Radiance)
            h.write_adding(&mut out, &rest[1..])?;
            std::io::copy(&mut r, &mut out).context("cannot copy the data")?;
            true
        }
        Some("-d") if rest.len() == 1 => {
            let mut r = stdin_reader();
            let d = fenestra_formats::dimensions::dimensions(&mut r, "<stdin>")?;
            writeln!(out, "{d}")?;
            true
        }
        Some("-d") if rest.len() == 2 && rest[1] == "-" => {
            let mut r = stdin_reader();
            let h = Header::read(&mut r, "<stdin>")?;
            if !is_picture(&h) {
                anyhow::bail!(
                    "<stdin>: not a picture (getinfo -d - strips a picture's resolution)"
                );
            }
            read_resolution(&mut r, "<stdin>")?;
            std::io::copy(&mut r, &mut out).context("cannot copy the data")?;
            true
        }
        Some("-d") => {
            let mut ok = true;
            for name in &rest[1..] {
                match open(name)
                    .and_then(|mut r| fenestra_formats::dimensions::dimensions(&mut r, name))
                {
                    Ok(d) => writeln!(out, "{name}: {d}")?,
                    Err(e) => {
                        out.flush()?;
                        eprintln!("{}: {e:#}", fenestra_cli::prog());
                        ok = false;
                    }
                }
            }
            ok
        }
        Some(_) => {
            let mut ok = true;
            for name in rest {
                match open(name).and_then(|mut r| Header::read(&mut r, name)) {
                    Ok(h) => {
                        writeln!(out, "{name}:")?;
                        for l in &h.lines {
                            writeln!(out, "\t{l}")?;
                        }
                        writeln!(out, "\t")?;
                    }
                    Err(e) => {
                        out.flush()?;
                        eprintln!("{}: {e:#}", fenestra_cli::prog());
                        ok = false;
                    }
                }
            }
            ok
        }
    };
    out.flush()?;
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// `getinfo [+d|-d] -c command ..`: the standard input's header with the command line
/// added (before the FORMAT line, as `-a`), the picture resolution string copied (`+d`,
/// `Some(true)`) or dropped (`-d`), then `command` run with the rest of the input as its
/// standard input and its output after the header; exits with the command's status.
fn run_command(out: &mut impl Write, dim: Option<bool>, command: &[String]) -> Result<ExitCode> {
    let mut r = stdin_reader();
    let h = Header::read(&mut r, "<stdin>")?;
    let words: Vec<String> = command
        .iter()
        .map(|w| fenestra_cli::quote_word(w))
        .collect();
    h.write_adding(out, &[words.join(" ")])?;
    if let Some(keep) = dim {
        let res = read_resolution(&mut r, "<stdin>")?;
        if keep {
            writeln!(out, "{}", res.to_string().trim_end())?;
        }
    }
    out.flush()?;
    let mut child = std::process::Command::new(&command[0])
        .args(&command[1..])
        .stdin(std::process::Stdio::piped())
        .spawn()
        .with_context(|| format!("cannot run '{}'", command[0]))?;
    let mut input = child.stdin.take().expect("piped standard input");
    // a command that stops reading early (head) closes the pipe: not an error here
    let copied = std::io::copy(&mut r, &mut input);
    drop(input);
    let status = child
        .wait()
        .with_context(|| format!("'{}' did not finish", command[0]))?;
    if let Err(e) = copied {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            return Err(e).context("cannot pass the data on");
        }
    }
    Ok(ExitCode::from(
        status.code().map_or(1, |c| u8::try_from(c).unwrap_or(1)),
    ))
}

fn stdin_reader() -> BufReader<std::io::StdinLock<'static>> {
    BufReader::with_capacity(1 << 16, std::io::stdin().lock())
}

fn open(name: &str) -> Result<BufReader<std::fs::File>> {
    let f = std::fs::File::open(name).with_context(|| format!("cannot open '{name}'"))?;
    Ok(BufReader::with_capacity(1 << 16, f))
}
