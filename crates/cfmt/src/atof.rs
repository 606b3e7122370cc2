//! C's `atof`: the longest numeric prefix of a word.

/// The longest numeric prefix of `s` as C's `atof`/`strtod` reads it, 0 when there is none:
/// leading white space skipped; a sign; `inf`/`infinity` and `nan` (any case); decimal
/// digits with an optional fraction and exponent; hexadecimal `0x` digits with an optional
/// fraction and binary exponent `p±N`.
pub fn atof(s: &str) -> f64 {
    let b = s.trim_start().as_bytes();
    let (sign, rest) = match b.first() {
        Some(b'-') => (-1.0, &b[1..]),
        Some(b'+') => (1.0, &b[1..]),
        _ => (1.0, b),
    };
    let starts = |w: &[u8]| rest.len() >= w.len() && rest[..w.len()].eq_ignore_ascii_case(w);
    if starts(b"inf") {
        return sign * f64::INFINITY;
    }
    if starts(b"nan") {
        return f64::NAN;
    }
    if rest.len() > 2
        && rest[0] == b'0'
        && (rest[1] | 0x20) == b'x'
        && (rest[2].is_ascii_hexdigit()
            || (rest[2] == b'.' && rest.get(3).is_some_and(u8::is_ascii_hexdigit)))
    {
        return sign * hex(&rest[2..]);
    }
    let digits = |j: &mut usize| {
        let s = *j;
        while *j < rest.len() && rest[*j].is_ascii_digit() {
            *j += 1;
        }
        *j - s
    };
    let mut j = 0;
    let mut nd = digits(&mut j);
    if j < rest.len() && rest[j] == b'.' {
        j += 1;
        nd += digits(&mut j);
    }
    if nd == 0 {
        return 0.0;
    }
    if j < rest.len() && (rest[j] | 0x20) == b'e' {
        let mut k = j + 1;
        if k < rest.len() && (rest[k] == b'+' || rest[k] == b'-') {
            k += 1;
        }
        if digits(&mut k) > 0 {
            j = k;
        }
    }
    let text = std::str::from_utf8(&rest[..j]).unwrap_or("0");
    sign * text.parse::<f64>().unwrap_or(0.0)
}

/// Hexadecimal digits, fraction and binary exponent (after `0x`).
fn hex(b: &[u8]) -> f64 {
    let mut v = 0.0f64;
    let mut j = 0;
    let digit = |c: u8| (c as char).to_digit(16).map(f64::from);
    while let Some(d) = b.get(j).copied().and_then(digit) {
        v = v * 16.0 + d;
        j += 1;
    }
    if b.get(j) == Some(&b'.') {
        j += 1;
        let mut scale = 1.0 / 16.0;
        while let Some(d) = b.get(j).copied().and_then(digit) {
            v += d * scale;
            scale /= 16.0;
            j += 1;
        }
    }
    if b.get(j).is_some_and(|c| (c | 0x20) == b'p') {
        let mut k = j + 1;
        let neg = match b.get(k) {
            Some(b'-') => {
                k += 1;
                true
            }
            Some(b'+') => {
                k += 1;
                false
            }
            _ => false,
        };
        let s = k;
        let mut e: i32 = 0;
        while let Some(c) = b.get(k).filter(|c| c.is_ascii_digit()) {
            e = e.saturating_mul(10).saturating_add((c - b'0') as i32);
            k += 1;
        }
        if k > s {
            v *= 2f64.powi(if neg { -e } else { e });
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::atof;

    #[test]
    fn numeric_prefixes_as_c_reads_them() {
        for (s, v) in [
            ("12abc", 12.0),
            ("0x10", 16.0),
            ("-0x1.8p1", -3.0),
            ("0x1p-2", 0.25),
            ("0x", 0.0),
            ("0xg", 0.0),
            (".5e1", 5.0),
            ("+3", 3.0),
            ("-.5", -0.5),
            ("1e", 1.0),
            ("5e+", 5.0),
            ("abc", 0.0),
            ("", 0.0),
            (" 7 ", 7.0),
            ("1.5e3x", 1500.0),
        ] {
            assert_eq!(atof(s), v, "{s}");
        }
        assert_eq!(atof("-inf"), f64::NEG_INFINITY);
        assert_eq!(atof("Infinity"), f64::INFINITY);
        assert!(atof("nan").is_nan() && atof("-NaN").is_nan());
        assert_eq!(atof("-0").to_bits(), (-0.0f64).to_bits());
    }
}
