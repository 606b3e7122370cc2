//! The Radiance information header: text lines ended by an empty line.
//!
//! Lines are kept raw and in order (the `#?RADIANCE` identifier line included when
//! present). Keyed lines are `NAME=value` (case-sensitive, no blank before `=`); the
//! typed getters parse the keys that matrix and picture tools act on.

use std::io::{BufRead, Write};

use anyhow::{bail, Context, Result};

/// Longest header line accepted (Radiance splits lines at 2048 bytes; we refuse
/// pathological binary junk without a newline instead of reading it all).
const MAX_LINE: usize = 1 << 16;
/// Largest header accepted in total.
const MAX_HEADER: usize = 64 << 20;

/// A Radiance information header.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Header {
    /// The lines, without their line ends, in file order.
    pub lines: Vec<String>,
    /// Bytes the header occupied in its stream, blank line included (0 if built in memory).
    pub byte_len: u64,
}

impl Header {
    /// An empty header.
    pub fn new() -> Self {
        Header::default()
    }

    /// A header whose first line is `#?RADIANCE`.
    pub fn radiance() -> Self {
        Header {
            lines: vec!["#?RADIANCE".to_string()],
            byte_len: 0,
        }
    }

    /// Reads a header up to and including its terminating empty line. `name` is used
    /// in messages. Fails when the data do not start with a printable character (no
    /// header), when a line is absurdly long, or when the stream ends first.
    pub fn read<R: BufRead + ?Sized>(r: &mut R, name: &str) -> Result<Header> {
        let mut h = Header::new();
        let mut buf = Vec::with_capacity(128);
        let mut total = 0usize;
        let mut first = true;
        loop {
            buf.clear();
            let n = read_line_limited(r, &mut buf)
                .with_context(|| format!("{name}: cannot read header"))?;
            if n == 0 {
                if first {
                    bail!("{name}: empty input where a header was expected");
                }
                bail!("{name}: header not terminated by an empty line (end of data after {} header lines)", h.lines.len());
            }
            if n > MAX_LINE {
                bail!(
                    "{name}: header line {} is longer than {MAX_LINE} bytes (not a Radiance header?)",
                    h.lines.len() + 1
                );
            }
            if first {
                let c = buf[0];
                if !(c.is_ascii_graphic() || c == b' ' || c == b'\t' || c == b'\n' || c == b'\r') {
                    bail!("{name}: bad header (data do not begin with a text line)");
                }
                first = false;
            }
            total += n;
            if total > MAX_HEADER {
                bail!("{name}: header larger than {MAX_HEADER} bytes (missing empty line?)");
            }
            if buf.last() == Some(&b'\n') {
                buf.pop();
                if buf.last() == Some(&b'\r') {
                    buf.pop();
                }
            } else {
                bail!("{name}: header not terminated by an empty line (end of data inside a header line)");
            }
            if buf.is_empty() {
                break;
            }
            h.lines.push(String::from_utf8_lossy(&buf).into_owned());
        }
        h.byte_len = total as u64;
        Ok(h)
    }

    /// The value of the last line `KEY=value` (text after `=`, leading blanks skipped,
    /// trailing white space removed).
    pub fn get(&self, key: &str) -> Option<&str> {
        self.lines.iter().rev().find_map(|l| key_value(l, key))
    }

    /// The values of every `KEY=` line, in order.
    pub fn get_all<'a>(&'a self, key: &'a str) -> impl Iterator<Item = &'a str> + 'a {
        self.lines.iter().filter_map(move |l| key_value(l, key))
    }

    /// `FORMAT=` value.
    pub fn format(&self) -> Option<&str> {
        self.get("FORMAT")
    }

    /// `NROWS=` as a count (`Ok(None)` when absent; an error when not a positive integer).
    pub fn nrows(&self) -> Result<Option<usize>> {
        self.count("NROWS")
    }

    /// `NCOLS=` as a count.
    pub fn ncols(&self) -> Result<Option<usize>> {
        self.count("NCOLS")
    }

    /// `NCOMP=` as a count.
    pub fn ncomp(&self) -> Result<Option<usize>> {
        self.count("NCOMP")
    }

    /// A positive integer header value (`Ok(None)` when absent).
    pub fn count(&self, key: &str) -> Result<Option<usize>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => match v.trim().parse::<usize>() {
                Ok(n) if n > 0 => Ok(Some(n)),
                _ => bail!(
                    "bad header line {key}={} (expected a positive integer)",
                    printable(v)
                ),
            },
        }
    }

    /// `BigEndian=` (`Some(true)` for 1, `Some(false)` for anything else, `None` if absent).
    pub fn big_endian(&self) -> Option<bool> {
        // Radiance tolerates blanks around '='.
        self.lines.iter().rev().find_map(|l| {
            let rest = l.strip_prefix("BigEndian")?;
            let rest = rest.trim_start().strip_prefix('=')?;
            Some(rest.trim().parse::<i64>().map(|v| v != 0).unwrap_or(false))
        })
    }

    /// Product of all `EXPOSURE=` values (1 when none). Errors on a value that is not
    /// a positive number.
    pub fn exposure(&self) -> Result<f64> {
        let mut e = 1.0;
        for v in self.get_all("EXPOSURE") {
            match v.trim().parse::<f64>() {
                Ok(x) if x > 0.0 && x.is_finite() => e *= x,
                _ => bail!(
                    "bad header line EXPOSURE={} (expected a positive number)",
                    printable(v)
                ),
            }
        }
        Ok(e)
    }

    /// Per-channel product of all `COLORCORR=` lines (1 1 1 when none).
    pub fn colorcorr(&self) -> Result<[f64; 3]> {
        let mut c = [1.0; 3];
        for v in self.get_all("COLORCORR") {
            let vals: Vec<f64> = v
                .split_whitespace()
                .map(|w| w.parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .ok()
                .filter(|x: &Vec<f64>| x.len() == 3 && x.iter().all(|y| *y > 0.0 && y.is_finite()))
                .with_context(|| {
                    format!(
                        "bad header line COLORCORR={} (expected three positive numbers)",
                        printable(v)
                    )
                })?;
            for k in 0..3 {
                c[k] *= vals[k];
            }
        }
        Ok(c)
    }

    /// Appends a line (a trailing line end is removed).
    pub fn push(&mut self, line: impl Into<String>) {
        let mut l: String = line.into();
        while l.ends_with('\n') || l.ends_with('\r') {
            l.pop();
        }
        self.lines.push(l);
    }

    /// Removes every `KEY=` line.
    pub fn remove(&mut self, key: &str) {
        self.lines.retain(|l| key_value(l, key).is_none());
    }

    /// Whether the header has no lines.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// Writes the lines, then `command` (the provenance line) when given, then the
    /// empty line ending the header.
    pub fn write<W: Write + ?Sized>(
        &self,
        w: &mut W,
        command: Option<&str>,
    ) -> std::io::Result<()> {
        self.write_lines(w)?;
        if let Some(c) = command {
            writeln!(w, "{c}")?;
        }
        w.write_all(b"\n")
    }

    /// Writes the header with `added` lines after its own and its `FORMAT=` line moved last
    /// (rewritten without padding), then the terminating empty line, as Radiance's
    /// `getinfo -a` and `-c` do.
    pub fn write_adding<W: Write + ?Sized>(
        &self,
        w: &mut W,
        added: &[String],
    ) -> std::io::Result<()> {
        for l in self.lines.iter().filter(|l| !l.starts_with("FORMAT=")) {
            writeln!(w, "{l}")?;
        }
        for l in added {
            writeln!(w, "{l}")?;
        }
        if let Some(f) = self.format() {
            writeln!(w, "FORMAT={f}")?;
        }
        w.write_all(b"\n")
    }

    /// Writes the lines only (no terminating empty line).
    pub fn write_lines<W: Write + ?Sized>(&self, w: &mut W) -> std::io::Result<()> {
        for l in &self.lines {
            w.write_all(l.as_bytes())?;
            w.write_all(b"\n")?;
        }
        Ok(())
    }
}

/// The value of `line` if it is `KEY=value`.
fn key_value<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    let rest = line.strip_prefix(key)?.strip_prefix('=')?;
    Some(rest.trim_start_matches([' ', '\t']).trim_end())
}

/// Whether a line is a `NAME=value` assignment (an identifier then `=`).
pub fn is_assignment(line: &str) -> bool {
    match line.find('=') {
        Some(i) if i > 0 => line[..i]
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-'),
        _ => false,
    }
}

/// Reads one line (with its `\n`), at most `MAX_LINE + 1` bytes; returns bytes read.
fn read_line_limited<R: BufRead + ?Sized>(r: &mut R, out: &mut Vec<u8>) -> std::io::Result<usize> {
    let mut n = 0;
    loop {
        let avail = match r.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if avail.is_empty() {
            return Ok(n);
        }
        let (take, done) = match avail.iter().position(|&b| b == b'\n') {
            Some(i) => (i + 1, true),
            None => (avail.len(), false),
        };
        let take = take.min(MAX_LINE + 1 - n);
        out.extend_from_slice(&avail[..take]);
        r.consume(take);
        n += take;
        if done && out.last() == Some(&b'\n') || n > MAX_LINE {
            return Ok(n);
        }
    }
}

/// Text of a header value fit for a message: printable ASCII as it is, anything else
/// (control bytes, binary garbage, characters outside ASCII) as `\xNN` / `\u{…}` escapes, at
/// most 80 characters.
pub fn printable(v: &str) -> String {
    let mut out = String::new();
    for (i, c) in v.chars().enumerate() {
        if i == 80 {
            out.push('…');
            break;
        }
        if c.is_ascii_graphic() || c == ' ' {
            out.push(c);
        } else if (c as u32) < 0x80 {
            out.push_str(&format!("\\x{:02x}", c as u32));
        } else {
            out.push_str(&c.escape_unicode().to_string());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &[u8]) -> Result<Header> {
        Header::read(&mut &s[..], "test")
    }

    #[test]
    fn reads_up_to_blank_line_and_leaves_data() {
        let data = b"#?RADIANCE\nrmtxop -ff x\nNROWS=2\nNCOLS=3\nNCOMP=1\nFORMAT=float  \n\nDATA";
        let mut r = &data[..];
        let h = Header::read(&mut r, "t").unwrap();
        assert_eq!(r, b"DATA");
        assert_eq!(h.lines[0], "#?RADIANCE");
        assert_eq!(h.format(), Some("float"));
        assert_eq!(h.nrows().unwrap(), Some(2));
        assert_eq!(h.ncols().unwrap(), Some(3));
        assert_eq!(h.ncomp().unwrap(), Some(1));
        assert_eq!(h.byte_len as usize, data.len() - 4);
    }

    #[test]
    fn crlf_lines_are_accepted() {
        let h = parse(b"#?RADIANCE\r\nNROWS=4\r\n\r\n").unwrap();
        assert_eq!(h.nrows().unwrap(), Some(4));
    }

    #[test]
    fn exposures_multiply_and_bigendian_parses() {
        let h = parse(b"EXPOSURE=2\nEXPOSURE= 0.25\nBigEndian = 1\n\n").unwrap();
        assert_eq!(h.exposure().unwrap(), 0.5);
        assert_eq!(h.big_endian(), Some(true));
        let h = parse(b"BigEndian=0\n\n").unwrap();
        assert_eq!(h.big_endian(), Some(false));
        assert_eq!(parse(b"X=1\n\n").unwrap().big_endian(), None);
    }

    #[test]
    fn bad_values_are_errors() {
        assert!(parse(b"NROWS=abc\n\n").unwrap().nrows().is_err());
        assert!(parse(b"NROWS=0\n\n").unwrap().nrows().is_err());
        assert!(parse(b"EXPOSURE=-1\n\n").unwrap().exposure().is_err());
    }

    #[test]
    fn unterminated_and_binary_headers_fail() {
        let e = parse(b"#?RADIANCE\nNROWS=1\n").unwrap_err().to_string();
        assert!(e.contains("not terminated"), "{e}");
        assert!(parse(b"").is_err());
        assert!(parse(b"\x00\x01\x02\n\n").is_err());
        let long = vec![b'a'; MAX_LINE + 10];
        assert!(parse(&long).is_err());
    }

    #[test]
    fn write_appends_command_and_blank_line() {
        let mut h = Header::radiance();
        h.push("gendaymtx x.wea\n");
        let mut out = Vec::new();
        h.write(&mut out, Some("rmtxop -ff -")).unwrap();
        assert_eq!(out, b"#?RADIANCE\ngendaymtx x.wea\nrmtxop -ff -\n\n");
        h.remove("NOPE");
        assert_eq!(h.lines.len(), 2);
    }

    #[test]
    fn assignment_lines_are_recognised() {
        assert!(is_assignment("NROWS=3"));
        assert!(is_assignment("SOFTWARE= RADIANCE"));
        assert!(!is_assignment("rcalc -e x=1"));
        assert!(!is_assignment("=3"));
    }
}
