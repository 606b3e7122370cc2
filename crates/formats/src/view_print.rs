//! C `printf` number formats (`%g`, `%e`) as Radiance's tools print them.

/// `printf("%.{prec}e", x)`: mantissa with `prec` decimals, signed exponent of at least two digits.
pub fn fmt_e(x: f64, prec: usize) -> String {
    if !x.is_finite() {
        return nonfinite(x);
    }
    let s = format!("{:.*e}", prec, x);
    let (mant, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let e: i32 = exp.parse().unwrap_or(0);
    let sign = if e < 0 { '-' } else { '+' };
    format!("{mant}e{sign}{:02}", e.abs())
}

/// `printf("%.{prec}g", x)`: shortest of `%e`/`%f` at `prec` significant digits,
/// trailing zeros removed.
pub fn fmt_g(x: f64, prec: usize) -> String {
    if !x.is_finite() {
        return nonfinite(x);
    }
    let p = prec.max(1);
    if x == 0.0 {
        return if x.is_sign_negative() { "-0" } else { "0" }.to_string();
    }
    let s = format!("{:.*e}", p - 1, x);
    let (_, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let e: i32 = exp.parse().unwrap_or(0);
    if e < -4 || e >= p as i32 {
        let m = fmt_e(x, p - 1);
        let (mant, ex) = m.split_once('e').unwrap_or((&m, ""));
        format!("{}e{}", strip_zeros(mant), ex)
    } else {
        let decimals = (p as i32 - 1 - e).max(0) as usize;
        strip_zeros(&format!("{:.*}", decimals, x)).to_string()
    }
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

fn nonfinite(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x > 0.0 {
        "inf".into()
    } else {
        "-inf".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn e_format_like_c() {
        assert_eq!(fmt_e(0.0, 5), "0.00000e+00");
        assert_eq!(fmt_e(-0.408248290463863, 5), "-4.08248e-01");
        assert_eq!(fmt_e(1.5e-300, 2), "1.50e-300");
        assert_eq!(fmt_e(12345.0, 3), "1.234e+04");
    }

    #[test]
    fn g_format_like_c() {
        assert_eq!(fmt_g(45.0, 5), "45");
        assert_eq!(fmt_g(-0.08, 7), "-0.08");
        assert_eq!(fmt_g(1e-5, 5), "1e-05");
        assert_eq!(fmt_g(123456.0, 5), "1.2346e+05");
        assert_eq!(fmt_g(0.0001, 6), "0.0001");
        assert_eq!(fmt_g(100000.0, 6), "100000");
        assert_eq!(fmt_g(1e6, 6), "1e+06");
        assert_eq!(fmt_g(2.5, 1), "2");
    }
}
