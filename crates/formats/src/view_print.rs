//! C `printf` number formats (`%g`, `%e`) as Radiance's tools print them.

pub use fenestra_cfmt::{fmt_e, fmt_g};

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
