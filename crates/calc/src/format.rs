//! C `printf("%.Ng")` formatting of numbers, as rcalc prints them.

/// Formats `x` like C's `%.{prec}g` (glibc: `nan`/`-nan`, `inf`/`-inf`).
pub fn fmt_g(x: f64, prec: usize) -> String {
    if x.is_nan() {
        return if x.is_sign_negative() { "-nan" } else { "nan" }.to_string();
    }
    if x.is_infinite() {
        return if x < 0.0 { "-inf" } else { "inf" }.to_string();
    }
    if x == 0.0 {
        return if x.is_sign_negative() { "-0" } else { "0" }.to_string();
    }
    let p = prec.max(1);
    // integers with at most `p` digits print as themselves (the common case of bin numbers)
    if x.fract() == 0.0 && p <= 17 && x.abs() < 10f64.powi(p as i32) {
        return format!("{}", x as i64);
    }
    let e = format!("{:.*e}", p - 1, x);
    let (mant, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if exp < -4 || exp >= p as i32 {
        let mant = strip_zeros(mant);
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{mant}e{sign}{:02}", exp.abs())
    } else {
        let decimals = (p as i32 - 1 - exp).max(0) as usize;
        strip_zeros(&format!("{x:.decimals$}")).to_string()
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
    use super::fmt_g;

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
}
