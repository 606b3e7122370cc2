//! Text numbers: a streaming white-space tokenizer and C `printf` style formatting.

use std::io::BufRead;

use anyhow::{bail, Result};

/// Longest number token accepted.
const MAX_TOKEN: usize = 256;

/// The reader's buffered bytes (empty at the end of data), retried when interrupted.
fn fill<'r, R: BufRead + ?Sized>(r: &'r mut R, name: &str) -> Result<&'r [u8]> {
    loop {
        match r.fill_buf() {
            Ok(_) => break,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(anyhow::Error::new(e).context(format!("{name}: read error"))),
        }
    }
    Ok(r.fill_buf()?)
}

/// Reads the next white-space separated number; `Ok(None)` at end of data.
pub(crate) fn next_number<R: BufRead + ?Sized>(
    r: &mut R,
    tok: &mut Vec<u8>,
    name: &str,
) -> Result<Option<f64>> {
    tok.clear();
    // Skip white space.
    loop {
        let buf = fill(r, name)?;
        if buf.is_empty() {
            return Ok(None);
        }
        let skip = buf.iter().take_while(|b| b.is_ascii_whitespace()).count();
        let done = skip < buf.len();
        r.consume(skip);
        if done {
            break;
        }
    }
    // Collect the token.
    loop {
        let buf = fill(r, name)?;
        if buf.is_empty() {
            break;
        }
        let take = buf.iter().take_while(|b| !b.is_ascii_whitespace()).count();
        if tok.len() + take > MAX_TOKEN {
            bail!(
                "{name}: bad number in ascii data (a word of more than {MAX_TOKEN} characters; binary data with FORMAT=ascii?)"
            );
        }
        tok.extend_from_slice(&buf[..take]);
        let done = take < buf.len();
        r.consume(take);
        if done {
            break;
        }
    }
    match std::str::from_utf8(tok).ok().and_then(parse_c_number) {
        Some(v) => Ok(Some(v)),
        None => bail!(
            "{name}: bad number '{}' in ascii data",
            String::from_utf8_lossy(tok)
        ),
    }
}

/// Parses a number as C's `strtod` would for a whole word (decimal forms, inf, nan).
fn parse_c_number(s: &str) -> Option<f64> {
    if let Ok(v) = s.parse::<f64>() {
        return Some(v);
    }
    // strtod also accepts a leading '+' before inf/nan and forms like "1." or ".5e3",
    // which Rust accepts too; and trailing 'f'/'F'? No: keep to what parses.
    let t = s.strip_prefix('+').unwrap_or(s);
    t.parse::<f64>().ok()
}

pub use fenestra_cfmt::{push_e as format_c_e, push_g as format_c_g};
