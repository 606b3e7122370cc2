//! C `printf` `%g` formatting (as Radiance's tools print reals).

pub use fenestra_cfmt::{fmt_g as g, g_width};

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
