//! Expansion of `@optfile` and `$VAR` arguments, as Radiance's tools do before parsing.
//!
//! `@file` is replaced by the words of the file (white space separated, `"…"` and `'…'`
//! quote words with blanks, lines whose first non-blank character is `#` are comments);
//! `$VAR` (a whole argument naming an environment variable) by the words of its value.
//! Expansion repeats on the words it produced, so option files may include others.

use anyhow::{bail, Context, Result};

const MAX_DEPTH: usize = 32;
/// Largest option file read (1 MiB): `@/dev/zero` or a huge file is an error, not a
/// process that grows without limit.
const MAX_FILE_BYTES: u64 = 1 << 20;
/// Most words the expansion may produce (files that include each other twice over
/// would double at each level).
const MAX_WORDS: usize = 1 << 20;

/// Expands every `@file` and `$VAR` argument after the program name.
pub fn expand_args(args: Vec<String>) -> Result<Vec<String>> {
    let mut out = Vec::with_capacity(args.len());
    let mut iter = args.into_iter();
    if let Some(p) = iter.next() {
        out.push(p);
    }
    for a in iter {
        expand_one(a, 0, &mut out)?;
    }
    Ok(out)
}

fn expand_one(arg: String, depth: usize, out: &mut Vec<String>) -> Result<()> {
    if let Some(file) = arg.strip_prefix('@').filter(|f| !f.is_empty()) {
        if depth >= MAX_DEPTH {
            bail!("option files nested more than {MAX_DEPTH} deep at '{arg}' (a file that includes itself?)");
        }
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(
            &mut std::io::Read::take(
                std::fs::File::open(file)
                    .with_context(|| format!("cannot read option file '{file}'"))?,
                MAX_FILE_BYTES + 1,
            ),
            &mut bytes,
        )
        .with_context(|| format!("cannot read option file '{file}'"))?;
        if bytes.len() as u64 > MAX_FILE_BYTES {
            bail!("option file '{file}' is larger than {MAX_FILE_BYTES} bytes");
        }
        let text = String::from_utf8_lossy(&bytes);
        let words = split_words(&text).with_context(|| format!("in option file '{file}'"))?;
        for w in words {
            expand_one(w, depth + 1, out)?;
        }
        return Ok(());
    }
    if let Some(name) = env_name(&arg) {
        if depth >= MAX_DEPTH {
            bail!("variables nested more than {MAX_DEPTH} deep at '{arg}'");
        }
        let val = std::env::var(name).with_context(|| {
            format!("cannot expand '{arg}': environment variable {name} is not set")
        })?;
        let words = split_words(&val).with_context(|| format!("in environment variable {name}"))?;
        for w in words {
            expand_one(w, depth + 1, out)?;
        }
        return Ok(());
    }
    if out.len() >= MAX_WORDS {
        bail!("option files and variables expand to more than {MAX_WORDS} words");
    }
    out.push(arg);
    Ok(())
}

/// `Some(NAME)` when the argument is exactly `$NAME` with NAME an identifier (so `$1`
/// in an rcalc expression is left alone).
fn env_name(arg: &str) -> Option<&str> {
    let name = arg.strip_prefix('$')?;
    let mut chars = name.chars();
    let first = chars.next()?;
    if !(first.is_ascii_alphabetic() || first == '_') {
        return None;
    }
    chars
        .all(|c| c.is_ascii_alphanumeric() || c == '_')
        .then_some(name)
}

/// Splits text into words: blanks separate, quotes group, `#` lines are comments.
pub fn split_words(text: &str) -> Result<Vec<String>> {
    let mut words = Vec::new();
    for (lineno, line) in text.lines().enumerate() {
        if line.trim_start().starts_with('#') {
            continue;
        }
        let mut chars = line.chars().peekable();
        loop {
            while chars.peek().is_some_and(|c| c.is_whitespace()) {
                chars.next();
            }
            let Some(&c0) = chars.peek() else { break };
            let mut word = String::new();
            let mut quoted = false;
            if c0 == '"' || c0 == '\'' {
                chars.next();
                quoted = true;
                let mut closed = false;
                for c in chars.by_ref() {
                    if c == c0 {
                        closed = true;
                        break;
                    }
                    word.push(c);
                }
                if !closed {
                    bail!("line {}: unterminated {c0} quote", lineno + 1);
                }
            }
            while let Some(&c) = chars.peek() {
                if c.is_whitespace() {
                    break;
                }
                word.push(c);
                chars.next();
            }
            if quoted || !word.is_empty() {
                words.push(word);
            }
        }
    }
    Ok(words)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(v: &[&str]) -> Vec<String> {
        v.iter().map(|x| x.to_string()).collect()
    }

    #[test]
    fn splits_quoted_words_and_skips_comments() {
        let w = split_words("-ab 4 \"a b\" 'c d'\n# comment -x\n  -lw 1e-4\n").unwrap();
        assert_eq!(w, s(&["-ab", "4", "a b", "c d", "-lw", "1e-4"]));
    }

    #[test]
    fn unterminated_quote_is_an_error_with_line() {
        let e = split_words("-ab 4\n\"oops\n").unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
    }

    #[test]
    fn nested_option_files_expand_in_place() {
        let dir = std::env::temp_dir().join(format!("fen-expand-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let inner = dir.join("inner.opt");
        let outer = dir.join("outer.opt");
        std::fs::write(&inner, "-lw 1e-4\n").unwrap();
        std::fs::write(&outer, format!("-ab 2 @{} -ad 512", inner.display())).unwrap();
        let got = expand_args(s(&[
            "rtrace",
            "-I",
            &format!("@{}", outer.display()),
            "x.oct",
        ]))
        .unwrap();
        assert_eq!(
            got,
            s(&["rtrace", "-I", "-ab", "2", "-lw", "1e-4", "-ad", "512", "x.oct"])
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn self_including_file_stops_with_error() {
        let dir = std::env::temp_dir().join(format!("fen-expand-loop-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("loop.opt");
        std::fs::write(&f, format!("@{}", f.display())).unwrap();
        let e = expand_args(s(&["x", &format!("@{}", f.display())])).unwrap_err();
        assert!(format!("{e:#}").contains("nested"));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn dollar_digit_is_not_a_variable() {
        let got = expand_args(s(&["rcalc", "-e", "$1", "$1=$2"])).unwrap();
        assert_eq!(got, s(&["rcalc", "-e", "$1", "$1=$2"]));
    }

    #[test]
    fn missing_variable_is_a_clear_error() {
        let e = expand_args(s(&["x", "$FENESTRA_SURELY_UNSET_VAR"])).unwrap_err();
        assert!(e.to_string().contains("FENESTRA_SURELY_UNSET_VAR"));
    }
}
