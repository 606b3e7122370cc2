//! Text numbers: a streaming white-space tokenizer and C `printf` style formatting.

use std::io::BufRead;

use anyhow::{bail, Result};

/// Longest number token accepted.
const MAX_TOKEN: usize = 256;

/// Reads the next white-space separated number; `Ok(None)` at end of data.
pub(crate) fn next_number<R: BufRead + ?Sized>(
    r: &mut R,
    tok: &mut Vec<u8>,
    name: &str,
) -> Result<Option<f64>> {
    tok.clear();
    // Skip white space.
    loop {
        let buf = match r.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(anyhow::Error::new(e).context(format!("{name}: read error"))),
        };
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
        let buf = match r.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(anyhow::Error::new(e).context(format!("{name}: read error"))),
        };
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

/// Appends `v` as C's `%.{prec}e` (`1.2345678e+00`, `-inf`, `nan`).
pub fn format_c_e(out: &mut String, v: f64, prec: usize) {
    use std::fmt::Write;
    if !v.is_finite() {
        out.push_str(if v.is_nan() {
            if v.is_sign_negative() {
                "-nan"
            } else {
                "nan"
            }
        } else if v > 0.0 {
            "inf"
        } else {
            "-inf"
        });
        return;
    }
    let start = out.len();
    let _ = write!(out, "{v:.prec$e}");
    let epos = start + out[start..].rfind('e').unwrap_or(out.len() - start);
    let exp: i32 = out[epos + 1..].parse().unwrap_or(0);
    out.truncate(epos);
    let _ = write!(
        out,
        "e{}{:02}",
        if exp < 0 { '-' } else { '+' },
        exp.unsigned_abs()
    );
}

/// Appends `v` as C's `%.{prec}g` (`prec` 0 is taken as 1).
pub fn format_c_g(out: &mut String, v: f64, prec: usize) {
    use std::fmt::Write;
    let p = prec.max(1);
    if !v.is_finite() || v == 0.0 {
        if v == 0.0 {
            out.push_str(if v.is_sign_negative() { "-0" } else { "0" });
        } else {
            format_c_e(out, v, 0);
        }
        return;
    }
    // The exponent after rounding to p significant digits decides the style.
    let mut tmp = String::new();
    format_c_e(&mut tmp, v, p - 1);
    let epos = tmp.rfind('e').unwrap_or(tmp.len());
    let exp: i32 = tmp[epos + 1..].parse().unwrap_or(0);
    if exp < -4 || exp >= p as i32 {
        let (mant, ex) = tmp.split_at(epos);
        out.push_str(strip_zeros(mant));
        out.push_str(ex);
    } else {
        let decimals = (p as i32 - 1 - exp).max(0) as usize;
        let s = format!("{v:.decimals$}");
        out.push_str(strip_zeros(&s));
    }
    let _ = write!(out, "");
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}
