//! getinfo: print the information header of Radiance files, strip it, add lines to it,
//! or print a picture's (or matrix's) dimensions.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::ExitCode;

use anyhow::{Context, Result};
use fenestra_formats::header::Header;
use fenestra_formats::resolution::Resolution;

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
            let is_format = |l: &str| l.starts_with("FORMAT=");
            for l in h.lines.iter().filter(|l| !is_format(l)) {
                writeln!(out, "{l}")?;
            }
            for l in &rest[1..] {
                writeln!(out, "{l}")?;
            }
            // The data format line goes last, rewritten without padding (as Radiance).
            if let Some(f) = h.format() {
                writeln!(out, "FORMAT={f}")?;
            }
            writeln!(out)?;
            std::io::copy(&mut r, &mut out).context("cannot copy the data")?;
            true
        }
        Some("-d") if rest.len() == 1 => {
            let mut r = stdin_reader();
            let d = dimensions(&mut r, "<stdin>")?;
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
                match open(name).and_then(|mut r| dimensions(&mut r, name)) {
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

fn stdin_reader() -> BufReader<std::io::StdinLock<'static>> {
    BufReader::with_capacity(1 << 16, std::io::stdin().lock())
}

fn open(name: &str) -> Result<BufReader<std::fs::File>> {
    let f = std::fs::File::open(name).with_context(|| format!("cannot open '{name}'"))?;
    Ok(BufReader::with_capacity(1 << 16, f))
}

fn is_picture(h: &Header) -> bool {
    h.format().is_none_or(|f| f.contains("_rle_"))
        && h.ncols().ok().flatten().is_none()
        && h.lines.first().is_some_and(|l| l.starts_with("#?"))
}

fn read_resolution(r: &mut impl BufRead, name: &str) -> Result<Resolution> {
    let mut line = Vec::new();
    r.take(128)
        .read_until(b'\n', &mut line)
        .with_context(|| format!("{name}: read error"))?;
    let s = String::from_utf8_lossy(&line);
    Resolution::parse(s.trim_end())
        .with_context(|| format!("{name}: bad picture resolution string '{}'", s.trim_end()))
}

/// A picture's resolution string, or a matrix's shape from its header.
fn dimensions(r: &mut impl BufRead, name: &str) -> Result<String> {
    let h = Header::read(r, name)?;
    if let (Ok(Some(nr)), Ok(Some(nc))) = (h.nrows(), h.ncols()) {
        let ncomp = h.ncomp().ok().flatten().unwrap_or(3);
        return Ok(format!("NROWS={nr} NCOLS={nc} NCOMP={ncomp}"));
    }
    if is_picture(&h) {
        let res = read_resolution(r, name)?;
        return Ok(res.to_string().trim_end().to_string());
    }
    // rcontrib/rtcontrib write NROWS only with -y: count the rows the data hold (fenestra)
    if let Ok(Some(nc)) = h.ncols() {
        let ncomp = h.ncomp().ok().flatten().unwrap_or(3);
        let per_row = nc * ncomp;
        let size = match h.format().map(str::trim) {
            Some("float") => Some(4),
            Some("double") => Some(8),
            Some("ascii") | None => None,
            Some(other) => anyhow::bail!("{name}: matrix format '{other}' without NROWS"),
        };
        let (values, rest) = match size {
            Some(b) => {
                let n = std::io::copy(r, &mut std::io::sink())
                    .with_context(|| format!("{name}: read error"))?
                    as usize;
                (n / b, n % b)
            }
            None => {
                let mut text = String::new();
                r.read_to_string(&mut text)
                    .with_context(|| format!("{name}: read error"))?;
                (text.split_whitespace().count(), 0)
            }
        };
        if per_row > 0 && rest == 0 && values % per_row == 0 {
            return Ok(format!(
                "NROWS={} NCOLS={nc} NCOMP={ncomp}",
                values / per_row
            ));
        }
        anyhow::bail!(
            "{name}: {values} values are not whole rows of NCOLS={nc} x NCOMP={ncomp} (a truncated matrix?)"
        );
    }
    anyhow::bail!("{name}: unknown file type (neither a picture nor a matrix with NCOLS)")
}
