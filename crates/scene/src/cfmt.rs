//! C `printf` `%g` formatting (as Radiance's tools print reals).

/// `%.{prec}g` of `v`.
pub fn g(v: f64, prec: usize) -> String {
    let p = prec.max(1);
    if v == 0.0 {
        return if v.is_sign_negative() {
            "-0".into()
        } else {
            "0".into()
        };
    }
    if !v.is_finite() {
        return if v.is_nan() {
            "nan".into()
        } else if v > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    let e = format!("{:.*e}", p - 1, v);
    let (mant, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let x: i32 = exp.parse().unwrap_or(0);
    if x < -4 || x >= p as i32 {
        let m = strip_zeros(mant);
        let sign = if x < 0 { '-' } else { '+' };
        format!("{m}e{sign}{:02}", x.abs())
    } else {
        let decimals = (p as i32 - 1 - x).max(0) as usize;
        strip_zeros(&format!("{v:.decimals$}")).to_string()
    }
}

/// `%{width}.{prec}g` of `v` (right-aligned in `width` columns).
pub fn g_width(v: f64, width: usize, prec: usize) -> String {
    format!("{:>width$}", g(v, prec))
}

fn strip_zeros(s: &str) -> &str {
    if !s.contains('.') {
        return s;
    }
    let t = s.trim_end_matches('0');
    t.strip_suffix('.').unwrap_or(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn like_c() {
        let cases = [
            (0.5, 12, "0.5"),
            (1.86602540378443, 12, "1.86602540378"),
            (0.0025, 12, "0.0025"),
            (1e-5, 6, "1e-05"),
            (123456789.0, 6, "1.23457e+08"),
            (100000.0, 6, "100000"),
            (1000000.0, 6, "1e+06"),
            (-0.000123456, 3, "-0.000123"),
            (0.0001, 1, "0.0001"),
            (2.5, 1, "2"),
            (0.0, 12, "0"),
            (180.0, 12, "180"),
        ];
        for (v, p, want) in cases {
            assert_eq!(g(v, p), want, "{v} %.{p}g");
        }
        assert_eq!(g_width(0.5, 18, 12), "               0.5");
    }
}
