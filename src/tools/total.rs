//! total: sums (means, powers, products, extrema) of the columns of text or binary records,
//! with Radiance's command line and output (`%.9g`, tab-separated).

use std::process::ExitCode;

use anyhow::{bail, Result};
use fenestra_records::total::{atof, Binary, Mode, Settings};

const USAGE: &str = "Usage: total [-m][-sE|p|u|l][-tC][-i{f|d}[N]][-o{f|d}][-count [-r]] [file..]";

const HELP: &str = "total: column sums, means, products and extrema of records

Usage: total [-m][-sE|p|u|l][-tC][-i{f|d}[N]][-o{f|d}][-count [-r]] [file..]

  -m        means instead of sums (with -sE: (mean of |x|^E)^(1/E); with -p: geometric mean)
  -sE       sum |x|^E over non-zero x (E = 0 or none: plain sum)
  -p        products
  -u, -l    maxima, minima
  -tC       fields separated by the character C (default: white space); output uses C too
  -if[N]    binary input: records of N floats (default 1); -id[N] doubles
  -of, -od  binary output: floats or doubles
  -N        a result for every N records (the last, shorter batch too)
  -r        with -N: running results (accumulate over all records)

Text input: one record per line; a blank line ends a set of records, whose result is printed
(a blank line straight after a printed result ends the input). Each file gives its own results;
no file (or '-') reads the standard input. Unparsable fields count as 0, as in Radiance.
";

fn parse(args: &[String]) -> Result<(Settings, Vec<String>)> {
    let mut o = Settings {
        mean: false,
        mode: Mode::Sum,
        sep: None,
        input: None,
        output: None,
        count: 0,
        running: false,
    };
    let mut files = Vec::new();
    for (i, a) in args.iter().enumerate().skip(1) {
        if a == "--help" || a == "-help" {
            print!("{HELP}");
            return Err(fenestra_cli::Exit(0).into());
        }
        if !a.starts_with('-') || a == "-" {
            files.extend(args[i..].iter().cloned());
            break;
        }
        let body = &a[1..];
        let bad = || anyhow::anyhow!("bad option '{a}'\n{USAGE}");
        match body.chars().next() {
            Some('m') if body == "m" => o.mean = !o.mean,
            Some('s') => {
                let e = atof(&body[1..]);
                o.mode = if e == 0.0 { Mode::Sum } else { Mode::Power(e) };
            }
            Some('p') if body == "p" => o.mode = Mode::Product,
            Some('u') if body == "u" => o.mode = Mode::Max,
            Some('l') if body == "l" => o.mode = Mode::Min,
            Some('r') if body == "r" => o.running = true,
            Some('t') => o.sep = body[1..].chars().next().or(Some('\t')),
            Some('i') => {
                let kind = match body[1..].chars().next() {
                    Some('f') => Some(Binary::Float),
                    Some('d') => Some(Binary::Double),
                    Some('a') => None,
                    _ => return Err(bad()),
                };
                let n = &body[2..];
                let n = if n.is_empty() {
                    1
                } else {
                    n.parse::<usize>().ok().filter(|&n| n > 0).ok_or_else(bad)?
                };
                o.input = kind.map(|k| (k, n));
            }
            Some('o') => {
                o.output = match &body[1..] {
                    "f" => Some(Binary::Float),
                    "d" => Some(Binary::Double),
                    "a" => None,
                    _ => return Err(bad()),
                }
            }
            Some(c) if c.is_ascii_digit() => {
                o.count = body.parse::<usize>().map_err(|_| bad())?;
            }
            _ => return Err(bad()),
        }
    }
    if o.mean && matches!(o.mode, Mode::Max | Mode::Min) {
        bail!(
            "average {}?! (-m cannot be combined with -u or -l)",
            if o.mode == Mode::Max {
                "maximum"
            } else {
                "minimum"
            }
        );
    }
    Ok((o, files))
}

/// Runs total.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let (o, mut files) = parse(&args)?;
    if files.is_empty() {
        files.push("-".to_string());
    }
    fenestra_records::total::run(&o, &files, std::io::stdout().lock())?;
    Ok(ExitCode::SUCCESS)
}
