//! Word reader for Radiance scene text: white-space separated words, `"`/`'` quoting,
//! line counting, and statement-level `#` comments and `!command` lines.

/// A cursor over scene text that counts lines.
pub struct Words<'a> {
    text: &'a [u8],
    pos: usize,
    line: u32,
}

/// Longest word Radiance accepts (its buffer holds 511 characters).
pub const MAX_WORD: usize = 511;

impl<'a> Words<'a> {
    /// A reader at the start of `text`.
    pub fn new(text: &'a str) -> Self {
        Words {
            text: text.as_bytes(),
            pos: 0,
            line: 1,
        }
    }

    /// The current line (1-based).
    pub fn line(&self) -> u32 {
        self.line
    }

    fn is_space(c: u8) -> bool {
        matches!(c, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
    }

    /// Skips white space; returns the next byte without consuming it.
    pub fn skip_space(&mut self) -> Option<u8> {
        while self.pos < self.text.len() {
            let c = self.text[self.pos];
            if !Self::is_space(c) {
                return Some(c);
            }
            if c == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        None
    }

    /// Consumes the rest of the current line (without its newline), returning it.
    pub fn rest_of_line(&mut self) -> &'a str {
        let start = self.pos;
        while self.pos < self.text.len() && self.text[self.pos] != b'\n' {
            self.pos += 1;
        }
        std::str::from_utf8(&self.text[start..self.pos]).unwrap_or("")
    }

    /// Reads a `!command` (the `!` already at the cursor): the line, continued while a line
    /// ends with a backslash (backslash-newline kept, as the shell sees it). Returns the
    /// command text and whether it was terminated by a newline-free backslash at end of input.
    pub fn command(&mut self) -> (String, bool) {
        self.pos += 1; // the '!'
        let mut cmd = String::new();
        loop {
            let part = self.rest_of_line();
            cmd.push_str(part);
            let continued = part.ends_with('\\');
            if self.pos >= self.text.len() {
                return (cmd, continued);
            }
            // at a newline
            if !continued {
                return (cmd, false);
            }
            cmd.push('\n');
            self.pos += 1;
            self.line += 1;
            if self.pos >= self.text.len() {
                return (cmd, true);
            }
        }
    }

    /// The next word (quotes removed), or `None` at end of input. Errors on a word longer
    /// than [`MAX_WORD`] or an unterminated quote.
    pub fn word(&mut self) -> Result<Option<String>, String> {
        let Some(_) = self.skip_space() else {
            return Ok(None);
        };
        let mut out: Vec<u8> = Vec::new();
        let mut quote: Option<u8> = None;
        let start_line = self.line;
        while self.pos < self.text.len() {
            let c = self.text[self.pos];
            match quote {
                Some(q) if c == q => {
                    quote = None;
                    self.pos += 1;
                    continue;
                }
                Some(_) if c == b'\n' => self.line += 1,
                Some(_) => {}
                None if c == b'"' || c == b'\'' => {
                    quote = Some(c);
                    self.pos += 1;
                    continue;
                }
                None if Self::is_space(c) => break,
                None => {}
            }
            out.push(c);
            self.pos += 1;
        }
        if quote.is_some() {
            return Err(format!(
                "unterminated quote in word starting on line {start_line}"
            ));
        }
        if out.len() > MAX_WORD {
            return Err(format!("word longer than {MAX_WORD} characters"));
        }
        Ok(Some(String::from_utf8_lossy(&out).into_owned()))
    }
}

/// Parses a real number as Radiance's `isflt`+`atof` accept it (no `inf`/`nan`).
pub fn parse_real(w: &str) -> Option<f64> {
    let b = w.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let digits_start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    let mut nd = i - digits_start;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        let f = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        nd += i - f;
    }
    if nd == 0 {
        return None;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
            i += 1;
        }
        let e = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i == e {
            return None;
        }
    }
    if i != b.len() {
        return None;
    }
    let v: f64 = w.parse().ok()?;
    v.is_finite().then_some(v)
}

/// Parses a non-negative count word.
pub fn parse_count(w: &str) -> Option<usize> {
    let t = w.strip_prefix('+').unwrap_or(w);
    if t.is_empty() || !t.bytes().all(|c| c.is_ascii_digit()) {
        return None;
    }
    t.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_quotes() {
        let mut w = Words::new("a \"b c\"\n  'd'e\n");
        assert_eq!(w.word().unwrap().unwrap(), "a");
        assert_eq!(w.word().unwrap().unwrap(), "b c");
        assert_eq!(w.word().unwrap().unwrap(), "de");
        assert_eq!(w.line(), 2);
        assert_eq!(w.word().unwrap(), None);
    }

    #[test]
    fn reals() {
        for (s, v) in [
            ("1", 1.0),
            (".5", 0.5),
            ("1.", 1.0),
            ("-2e-3", -2e-3),
            ("+4E2", 400.0),
        ] {
            assert_eq!(parse_real(s), Some(v), "{s}");
        }
        for s in ["", ".", "e3", "1e", "inf", "nan", "1.2.3", "0x10", "1,5"] {
            assert_eq!(parse_real(s), None, "{s}");
        }
    }

    #[test]
    fn command_continuation() {
        let mut w = Words::new("!echo a \\\n b\nrest");
        let (c, open) = w.command();
        assert_eq!(c, "echo a \\\n b");
        assert!(!open);
        assert_eq!(w.line(), 2);
        let mut w = Words::new("!echo a \\");
        assert!(w.command().1);
        let mut w = Words::new("!echo a \\\n");
        assert!(w.command().1);
    }
}
