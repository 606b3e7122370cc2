//! C's `printf("%.Ng")` and `printf("%.Ne")` as glibc prints them: `nan`/`-nan`,
//! `inf`/`-inf`, `-0`, exponents of at least two digits, trailing zeros of `%g` removed.

use std::fmt::Write;

/// glibc's text for a value that is not finite.
fn nonfinite(x: f64) -> &'static str {
    if x.is_nan() {
        if x.is_sign_negative() {
            "-nan"
        } else {
            "nan"
        }
    } else if x > 0.0 {
        "inf"
    } else {
        "-inf"
    }
}

/// Appends `v` as C's `%.{prec}e` (`1.2345678e+00`).
pub fn push_e(out: &mut String, v: f64, prec: usize) {
    if !v.is_finite() {
        out.push_str(nonfinite(v));
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

/// C's `%.{prec}e`.
pub fn fmt_e(v: f64, prec: usize) -> String {
    let mut s = String::new();
    push_e(&mut s, v, prec);
    s
}

/// Appends `v` as C's `%.{prec}g` (`prec` 0 is taken as 1).
pub fn push_g(out: &mut String, v: f64, prec: usize) {
    let p = prec.max(1);
    if v == 0.0 {
        out.push_str(if v.is_sign_negative() { "-0" } else { "0" });
        return;
    }
    if !v.is_finite() {
        out.push_str(nonfinite(v));
        return;
    }
    // the exponent after rounding to p significant digits decides the style
    let e = format!("{:.*e}", p - 1, v);
    let (mant, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let x: i32 = exp.parse().unwrap_or(0);
    if x < -4 || x >= p as i32 {
        out.push_str(strip_zeros(mant));
        let _ = write!(
            out,
            "e{}{:02}",
            if x < 0 { '-' } else { '+' },
            x.unsigned_abs()
        );
    } else {
        let decimals = (p as i32 - 1 - x).max(0) as usize;
        out.push_str(strip_zeros(&format!("{v:.decimals$}")));
    }
}

/// C's `%.{prec}g`.
pub fn fmt_g(v: f64, prec: usize) -> String {
    let mut s = String::new();
    push_g(&mut s, v, prec);
    s
}

/// C's `%{width}.{prec}g` (right-aligned in `width` columns).
pub fn g_width(v: f64, width: usize, prec: usize) -> String {
    format!("{:>width$}", fmt_g(v, prec))
}

/// Appends `x` formatted like C's `%.{prec}g` (the same text as [`fmt_g`]) to `out`,
/// without allocating when `out` and `scratch` have room.
pub fn push_g_bytes(out: &mut Vec<u8>, x: f64, prec: usize, scratch: &mut String) {
    let p = prec.max(1);
    if x == 0.0 {
        out.extend_from_slice(if x.is_sign_negative() { b"-0" } else { b"0" });
        return;
    }
    if !x.is_finite() || p > 17 {
        out.extend_from_slice(fmt_g(x, prec).as_bytes());
        return;
    }
    const POW10: [f64; 18] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17,
    ];
    // an integer of at most `p` digits prints as itself (|x| < 1e17 < 2^63: `x as i64`
    // is exact for integers, single instructions both ways)
    if x.abs() < POW10[p] && (x as i64) as f64 == x {
        let mut n = (x as i64).unsigned_abs();
        let mut d = [0u8; 20];
        let mut i = d.len();
        while n > 0 || i == d.len() {
            i -= 1;
            d[i] = b'0' + (n % 10) as u8;
            n /= 10;
        }
        if x < 0.0 {
            out.push(b'-');
        }
        out.extend_from_slice(&d[i..]);
        return;
    }
    // the `p` significant digits and the exponent of `%.{p-1}e`; `%g`'s fixed form
    // prints the same digits (it rounds at the same place)
    scratch.clear();
    let _ = write!(scratch, "{:.*e}", p - 1, x.abs());
    let (mant, exp) = scratch.split_once('e').unwrap_or((scratch.as_str(), "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let mut buf = [0u8; 24];
    let mut nd = 0;
    for c in mant.bytes().filter(u8::is_ascii_digit).take(buf.len()) {
        buf[nd] = c;
        nd += 1;
    }
    // significant digits without trailing zeros
    let n = buf[..nd]
        .iter()
        .rposition(|&c| c != b'0')
        .map_or(1, |i| i + 1);
    let digits = &buf[..n];
    if x < 0.0 {
        out.push(b'-');
    }
    if exp < -4 || exp >= p as i32 {
        out.push(digits[0]);
        if digits.len() > 1 {
            out.push(b'.');
            out.extend_from_slice(&digits[1..]);
        }
        out.push(b'e');
        out.push(if exp < 0 { b'-' } else { b'+' });
        let e = exp.unsigned_abs();
        if e >= 100 {
            out.push(b'0' + (e / 100) as u8);
        }
        out.push(b'0' + (e / 10 % 10) as u8);
        out.push(b'0' + (e % 10) as u8);
    } else if exp < 0 {
        out.extend_from_slice(b"0.");
        out.extend(std::iter::repeat_n(b'0', (-exp - 1) as usize));
        out.extend_from_slice(digits);
    } else {
        let int = exp as usize + 1;
        if digits.len() <= int {
            out.extend_from_slice(digits);
            out.extend(std::iter::repeat_n(b'0', int - digits.len()));
        } else {
            out.extend_from_slice(&digits[..int]);
            out.push(b'.');
            out.extend_from_slice(&digits[int..]);
        }
    }
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::{fmt_e, fmt_g, g_width, push_g_bytes};

    #[test]
    fn matches_printf_g() {
        assert_eq!(fmt_g(1.0 / 3.0, 9), "0.333333333");
        assert_eq!(fmt_g(123456789012.0, 9), "1.23456789e+11");
        assert_eq!(fmt_g(0.1 + 0.2, 9), "0.3");
        assert_eq!(fmt_g(1e-20, 9), "1e-20");
        assert_eq!(fmt_g(5000.0, 9), "5000");
        assert_eq!(fmt_g(0.0001, 9), "0.0001");
        assert_eq!(fmt_g(0.00001234, 9), "1.234e-05");
        assert_eq!(fmt_g(999999999.5, 9), "1e+09");
        assert_eq!(fmt_g(-2.5, 9), "-2.5");
        assert_eq!(fmt_g(f64::INFINITY, 9), "inf");
        assert_eq!(fmt_g(1e100, 9), "1e+100");
        assert_eq!(fmt_g(100.0, 2), "1e+02");
        assert_eq!(fmt_g(99.0, 2), "99");
        assert_eq!(fmt_g(-123456789.0, 9), "-123456789");
        assert_eq!(fmt_g(1234567890.0, 9), "1.23456789e+09");
        assert_eq!(fmt_g(-7.0, 9), "-7");
    }

    #[test]
    fn push_g_matches_fmt_g() {
        let mut vals = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            1e-5,
            1.234e-5,
            9.999999995e-5,
            1e-4,
            0.000123456789,
            123456789.0,
            999999999.0,
            999999999.5,
            1e9,
            1.5e9,
            99.99999999,
            1e300,
            -2.5e-300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            5e-324,
            0.1 + 0.2,
            1.0 / 3.0,
            2.0 / 3.0,
            123.456,
            -0.001,
            1e21,
            1e22,
            4503599627370497.0,
        ];
        // a deterministic spread of magnitudes and digits
        let mut s = 1u64;
        for _ in 0..20000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let m = (s >> 11) as f64 / (1u64 << 53) as f64;
            let e = ((s >> 3) % 40) as i32 - 20;
            let v = m * 10f64.powi(e);
            vals.push(if s & 4 != 0 { -v } else { v });
            vals.push((v * 1000.0).round());
        }
        let mut scratch = String::new();
        for prec in [1, 2, 6, 9, 15, 17] {
            for &v in &vals {
                let mut out = Vec::new();
                push_g_bytes(&mut out, v, prec, &mut scratch);
                assert_eq!(
                    String::from_utf8(out).unwrap(),
                    fmt_g(v, prec),
                    "{v:e} %.{prec}g"
                );
            }
        }
    }

    #[test]
    fn e_and_nonfinite_as_glibc() {
        assert_eq!(fmt_e(1.23456789, 6), "1.234568e+00");
        assert_eq!(fmt_e(-2.5e-7, 6), "-2.500000e-07");
        assert_eq!(fmt_e(1e100, 2), "1.00e+100");
        assert_eq!(fmt_g(-f64::NAN, 6), "-nan");
        assert_eq!(fmt_g(f64::NAN, 6), "nan");
        assert_eq!(fmt_e(f64::NEG_INFINITY, 6), "-inf");
        assert_eq!(fmt_g(-0.0, 6), "-0");
        assert_eq!(g_width(0.5, 6, 3), "   0.5");
    }
}
