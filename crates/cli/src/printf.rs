//! printf-style fields in output names (`-o 'step_%04d.hdr'`, `-o '%s_%03d.dat'`): where
//! they are, and the name they give for a number, with C's flags and widths. A width
//! beyond [`MAX_WIDTH`] is refused: no file name can be that long.

use anyhow::{bail, Result};

/// The widest field accepted (the longest path a POSIX system takes).
pub const MAX_WIDTH: usize = 4096;

/// Reads a field width (digits, possibly empty) of the name `spec`, refusing widths over
/// [`MAX_WIDTH`].
pub fn check_width(spec: &str, digits: &str) -> Result<usize> {
    if digits.is_empty() {
        return Ok(0);
    }
    match digits.parse::<usize>() {
        Ok(w) if w <= MAX_WIDTH => Ok(w),
        _ => bail!(
            "output name '{}': field width {} is too large (at most {MAX_WIDTH})",
            spec.chars().take(200).collect::<String>(),
            digits.chars().take(30).collect::<String>()
        ),
    }
}

/// Whether a name holds a printf integer field (`%d %i %o %x %X`, flags and width allowed).
pub fn has_int_field(s: &str) -> bool {
    find_int_field(s).is_some()
}

/// Position (start, end) of the first integer field in `s`.
pub fn find_int_field(s: &str) -> Option<(usize, usize)> {
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            if b.get(i + 1) == Some(&b'%') {
                i += 2;
                continue;
            }
            let mut j = i + 1;
            while j < b.len() && b"-+ #0".contains(&b[j]) {
                j += 1;
            }
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            if j < b.len() && b"dioxX".contains(&b[j]) {
                return Some((i, j + 1));
            }
        }
        i += 1;
    }
    None
}

/// Formats `s` with `n` in its integer field (printf rules for flags `-+ #0` and width;
/// `%%` becomes `%`).
pub fn format_int_field(s: &str, n: usize) -> Result<String> {
    let Some((a, e)) = find_int_field(s) else {
        return Ok(s.replace("%%", "%"));
    };
    let f = &s[a + 1..e - 1];
    let conv = s.as_bytes()[e - 1];
    let flags: String = f.chars().take_while(|c| "-+ #0".contains(*c)).collect();
    let width = check_width(s, &f[flags.len()..])?;
    let mut digits = match conv {
        b'o' => format!("{n:o}"),
        b'x' => format!("{n:x}"),
        b'X' => format!("{n:X}"),
        _ => n.to_string(),
    };
    if flags.contains('#') && n != 0 {
        digits = match conv {
            b'o' => format!("0{digits}"),
            b'x' => format!("0x{digits}"),
            b'X' => format!("0X{digits}"),
            _ => digits,
        };
    }
    if matches!(conv, b'd' | b'i') {
        if flags.contains('+') {
            digits = format!("+{digits}");
        } else if flags.contains(' ') {
            digits = format!(" {digits}");
        }
    }
    let field = if digits.len() >= width {
        digits
    } else if flags.contains('-') {
        format!("{digits:<width$}")
    } else if flags.contains('0') {
        let sign = digits.starts_with(['+', ' ']);
        let (p, d) = digits.split_at(usize::from(sign));
        format!("{p}{}{d}", "0".repeat(width - digits.len()))
    } else {
        format!("{digits:>width$}")
    };
    Ok(format!(
        "{}{}{}",
        s[..a].replace("%%", "%"),
        field,
        s[e..].replace("%%", "%")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_as_printf() {
        assert_eq!(format_int_field("o_%04d.dat", 7).unwrap(), "o_0007.dat");
        assert_eq!(format_int_field("o_%-3d|", 7).unwrap(), "o_7  |");
        assert_eq!(format_int_field("%+d%%", 7).unwrap(), "+7%");
        assert_eq!(format_int_field("%#x", 255).unwrap(), "0xff");
        assert_eq!(format_int_field("plain%%", 3).unwrap(), "plain%");
        assert!(has_int_field("a%3i"));
        assert!(!has_int_field("a%%d"));
    }

    #[test]
    fn huge_width_is_an_error() {
        let e = format_int_field("o_%65536d.dat", 1).unwrap_err();
        assert!(format!("{e}").contains("too large"), "{e}");
        assert!(format_int_field("o_%99999999999999999999d", 1).is_err());
        assert_eq!(format_int_field("%4096d", 1).unwrap().len(), 4096);
    }
}
