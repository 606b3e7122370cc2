//! The `-f` output formats and `-o` specs with their `%s`/`%d` fields.

use anyhow::{bail, Result};

/// Output data format (`-fXo`): the matrix formats of `fenestra_formats` (one type for
/// every matrix any tool writes); rtcontrib writes all but XYZE.
pub use fenestra_formats::DataFormat as Format;

/// The output format of a `-f` letter (`a f d c`; `c`, RGBE, for output only).
pub fn format_of(c: char, output: bool) -> Result<Format> {
    Ok(match c {
        'a' => Format::Ascii,
        'f' => Format::Float,
        'd' => Format::Double,
        'c' if output => Format::Rgbe,
        _ => bail!("Illegal i/o format '{c}' (input: a, f, d; output: a, f, d, c)"),
    })
}

/// A parsed `-o` spec: where its `%s` and bin field are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Spec {
    /// The spec text.
    pub text: String,
    /// Has a `%s` field.
    pub has_mod: bool,
    /// Has a bin field (`%d`, `%03d`, `%x` …).
    pub has_bin: bool,
}

impl Spec {
    /// Parses a spec; any conversion other than one `%s` and one integer field is an error.
    pub fn parse(text: &str) -> Result<Spec> {
        let (mut has_mod, mut has_bin) = (false, false);
        for piece in pieces(text) {
            let Piece::Field { flags, conv } = piece else {
                continue;
            };
            fenestra_cli::printf::check_width(text, flags.trim_start_matches(['-', '+', '0']))?;
            match conv {
                Some('s') if !has_mod => has_mod = true,
                Some('d' | 'i' | 'o' | 'x' | 'X') if !has_bin => has_bin = true,
                _ => bail!("bad output format '{text}' (one %s and one %d field allowed)"),
            }
        }
        Ok(Spec {
            text: text.to_string(),
            has_mod,
            has_bin,
        })
    }

    /// The destination name for a modifier and bin.
    pub fn expand(&self, modifier: &str, bin: usize) -> String {
        let mut out = String::new();
        for piece in pieces(&self.text) {
            let (flags, conv) = match piece {
                Piece::Text(c) => {
                    out.push(c);
                    continue;
                }
                Piece::Field { flags, conv } => (flags, conv),
            };
            let left = flags.contains('-');
            let zero = flags.trim_start_matches(['-', '+']).starts_with('0');
            let width: usize = flags
                .trim_start_matches(['-', '+', '0'])
                .parse()
                .unwrap_or(0);
            let body = match conv {
                Some('s') => modifier.to_string(),
                Some('o') => format!("{bin:o}"),
                Some('x') => format!("{bin:x}"),
                Some('X') => format!("{bin:X}"),
                _ => bin.to_string(),
            };
            let pad = width.saturating_sub(body.chars().count());
            if left {
                out.push_str(&body);
                out.push_str(&" ".repeat(pad));
            } else if zero && conv != Some('s') {
                out.push_str(&"0".repeat(pad));
                out.push_str(&body);
            } else {
                out.push_str(&" ".repeat(pad));
                out.push_str(&body);
            }
        }
        out
    }
}

/// A piece of an output spec: a character of text (`%%` gives `%`) or a `%` field with
/// its flags and width and its conversion letter (`None` at the end of the text).
enum Piece {
    Text(char),
    Field { flags: String, conv: Option<char> },
}

/// The pieces of an output spec, in order.
fn pieces(text: &str) -> Vec<Piece> {
    let b: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] != '%' {
            out.push(Piece::Text(b[i]));
            i += 1;
            continue;
        }
        i += 1;
        if b.get(i) == Some(&'%') {
            out.push(Piece::Text('%'));
            i += 1;
            continue;
        }
        let start = i;
        while i < b.len() && (b[i].is_ascii_digit() || b[i] == '-' || b[i] == '+') {
            i += 1;
        }
        out.push(Piece::Field {
            flags: b[start..i].iter().collect(),
            conv: b.get(i).copied(),
        });
        i += 1;
    }
    out
}
