//! Numbers in text records as rcalc reads them: plain decimals by a fast exact path,
//! every other word as C's `atof`; lines split at white space or at a separator.

use anyhow::Result;
use fenestra_cli::num::atof;

/// `u8::is_ascii_whitespace`, the white space of `str::split_ascii_whitespace`.
#[inline]
pub(crate) fn is_ws(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\x0C' | b'\r')
}

/// Powers of ten exactly representable as f64.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A plain decimal number (`[+-]digits[.digits]`, at most 18 digits, at most 2^53)
/// at `buf[i..]` ending at white space or at the end of `buf`: its value as one
/// correctly rounded division of two exact numbers (the value `str::parse` gives),
/// and where it ends; `None` for anything else.
#[inline(always)]
pub(crate) fn plain_at(buf: &[u8], mut i: usize) -> Option<(f64, usize)> {
    let n = buf.len();
    // (no branch on the sign: it is unpredictable in typical input)
    let c = buf.get(i).copied().unwrap_or(0);
    let neg = c == b'-';
    i += usize::from(neg | (c == b'+'));
    let (mut m, mut nd, mut frac) = (0u64, 0u32, 0usize);
    // the integer part is usually short: digit by digit
    while i < n && buf[i].is_ascii_digit() && nd < 18 {
        m = m * 10 + u64::from(buf[i] - b'0');
        nd += 1;
        i += 1;
    }
    if i < n && buf[i].is_ascii_digit() {
        i = digit_run(buf, i, &mut m, &mut nd);
    }
    if i < n && buf[i] == b'.' {
        let at = nd;
        i = digit_run(buf, i + 1, &mut m, &mut nd);
        frac = (nd - at) as usize;
    }
    if nd == 0 || nd > 18 || (i < n && !is_ws(buf[i])) || m > 1 << 53 || frac >= POW10.len() {
        return None;
    }
    // (m <= 2^53: converted exactly, through i64 for a single instruction)
    let v = (m as i64) as f64 / POW10[frac];
    Some((f64::from_bits(v.to_bits() | u64::from(neg) << 63), i))
}

/// Reads the digits at `buf[i..]` into `m` (`nd` counts them), eight at a time where
/// eight bytes are there; stops before a 19th digit. Returns where it stopped.
#[inline(always)]
fn digit_run(buf: &[u8], mut i: usize, m: &mut u64, nd: &mut u32) -> usize {
    const POW: [u64; 9] = [
        1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000,
    ];
    while let Some(w) = buf.get(i..i + 8) {
        let v = u64::from_le_bytes(w.try_into().unwrap_or([0; 8]));
        let x = v ^ 0x3030_3030_3030_3030; // digit bytes become their values
        let bad =
            (((x & 0x7F7F_7F7F_7F7F_7F7F) + 0x7676_7676_7676_7676) | x) & 0x8080_8080_8080_8080;
        let k = (bad.trailing_zeros() / 8) as usize; // leading digit bytes
        if k == 0 || *nd + k as u32 > 18 {
            break;
        }
        // the k digits as the last k of eight (zeros in front), combined pairwise
        let mut d = if k == 8 { x } else { x << (8 * (8 - k)) };
        // (the products overflow by design: the bits above 64 are not needed)
        d = (d * 10) + (d >> 8);
        d = ((d & 0x0000_00FF_0000_00FF).wrapping_mul(100 + (1_000_000 << 32)))
            .wrapping_add(((d >> 16) & 0x0000_00FF_0000_00FF).wrapping_mul(1 + (10_000 << 32)))
            >> 32;
        *m = *m * POW[k] + d;
        *nd += k as u32;
        i += k;
        if k < 8 {
            return i;
        }
    }
    while i < buf.len() && buf[i].is_ascii_digit() && *nd < 19 {
        *m = *m * 10 + u64::from(buf[i] - b'0');
        *nd += 1;
        i += 1;
    }
    i
}

/// A plain decimal word (see [`plain_at`]).
#[cfg(test)]
pub(crate) fn parse_plain(w: &[u8]) -> Option<f64> {
    plain_at(w, 0)
        .filter(|&(_, e)| e == w.len())
        .map(|(v, _)| v)
}

/// The columns of the line at the start of `buf`, split at white space; returns the
/// length of the line with its newline.
pub(crate) fn ws_line(buf: &[u8], cols: &mut Vec<f64>) -> Result<usize> {
    cols.clear();
    let n = buf.len();
    let mut i = 0;
    loop {
        while i < n && matches!(buf[i], b' ' | b'\t' | b'\r' | b'\x0C') {
            i += 1;
        }
        if i >= n {
            return Ok(n);
        }
        if buf[i] == b'\n' {
            return Ok(i + 1);
        }
        if let Some((v, e)) = plain_at(buf, i) {
            cols.push(v);
            i = e;
            continue;
        }
        let s = i;
        while i < n && !is_ws(buf[i]) {
            i += 1;
        }
        cols.push(word_value(&buf[s..i])?);
    }
}

/// A word's value as C's `atof` reads it (called where [`plain_at`] did not read it).
fn word_value(w: &[u8]) -> Result<f64> {
    let s = std::str::from_utf8(w)
        .map_err(|_| anyhow::anyhow!("stream did not contain valid UTF-8"))?;
    Ok(atof(s))
}

/// The columns of one input line (without its newline).
pub(crate) fn line_cols(
    line: &[u8],
    sep: Option<char>,
    count: usize,
    cols: &mut Vec<f64>,
) -> Result<()> {
    let mut end = line.len();
    while end > 0 && line[end - 1] == b'\r' {
        end -= 1;
    }
    let line = &line[..end];
    cols.clear();
    match sep {
        None => {
            // (a carriage return is white space)
            ws_line(line, cols)?;
        }
        Some(c) => {
            let text = std::str::from_utf8(line)
                .map_err(|_| anyhow::anyhow!("stream did not contain valid UTF-8"))?;
            cols.extend(text.split(c).map(atof));
        }
    }
    if count > 0 {
        cols.truncate(count);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{atof, parse_plain};

    #[test]
    fn plain_decimals_parse_as_str_parse_does() {
        let mut s = 7u64;
        let mut n = 0;
        for _ in 0..200_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let int = (s >> 20) % 10u64.pow(((s >> 8) % 12) as u32);
            let frac = (s >> 40) % 1_000_000;
            let w = format!(
                "{}{int}.{frac:0w$}",
                ["", "-", "+"][(s % 3) as usize],
                w = ((s >> 4) % 7) as usize
            );
            let want: f64 = w.parse().unwrap();
            if let Some(v) = parse_plain(w.as_bytes()) {
                assert_eq!(v.to_bits(), want.to_bits(), "{w}");
                n += 1;
            }
        }
        assert!(n > 150_000, "{n} plain words");
        for w in [
            "",
            "-",
            ".",
            "1e3",
            "1.5.",
            "0x1",
            "nan",
            "1 ",
            "99999999999999999999",
        ] {
            assert_eq!(parse_plain(w.as_bytes()), None, "{w}");
        }
        assert_eq!(
            parse_plain(b"-0.000").map(f64::to_bits),
            Some((-0.0f64).to_bits())
        );
        assert_eq!(parse_plain(b"5."), Some(5.0));
        assert_eq!(parse_plain(b".25"), Some(0.25));
        // whole lines (eight digits at a time where eight bytes follow)
        let mut line = String::new();
        let mut words = Vec::new();
        for _ in 0..50_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let int = (s >> 20) % 10u64.pow(((s >> 8) % 13) as u32);
            let frac = (s >> 40) % 10u64.pow(((s >> 2) % 12) as u32);
            let w = match s % 5 {
                0 => format!("{int}"),
                1 => format!("-{int}.{frac}"),
                2 => format!("{int}.{frac:09}"),
                3 => format!("{int}.{frac}e{}", (s >> 30) % 7),
                _ => format!("+{int}.{frac}x"),
            };
            line += &w;
            line.push([' ', '\t', ' '][(s >> 50) as usize % 3]);
            words.push(w);
        }
        let mut cols = Vec::new();
        let len = super::ws_line(line.as_bytes(), &mut cols).unwrap();
        assert_eq!(len, line.len());
        assert_eq!(cols.len(), words.len());
        for (w, v) in words.iter().zip(&cols) {
            assert_eq!(v.to_bits(), atof(w).to_bits(), "{w}");
        }
    }

    #[test]
    fn atof_reads_prefixes() {
        assert_eq!(atof("1e3"), 1000.0);
        assert_eq!(atof("-2.5x"), -2.5);
        assert_eq!(atof(".5"), 0.5);
        assert_eq!(atof("a"), 0.0);
        assert_eq!(atof("1,2"), 1.0);
        assert_eq!(atof("3e"), 3.0);
    }
}
