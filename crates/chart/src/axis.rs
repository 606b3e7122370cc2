//! Logarithmic axes: the decade range that holds the data, and tick values with labels
//! (every decade; 2 and 5 between them when the axis spans few decades).

/// A log axis from `10^lo` to `10^hi` (whole decades).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogAxis {
    /// Lower decade exponent.
    pub lo: i32,
    /// Upper decade exponent (> lo).
    pub hi: i32,
}

impl LogAxis {
    /// The smallest decade range holding every positive finite value (at least one decade).
    pub fn covering(values: impl Iterator<Item = f64>) -> Option<LogAxis> {
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| v.is_finite() && *v > 0.0) {
            a = a.min(v);
            b = b.max(v);
        }
        if !a.is_finite() {
            return None;
        }
        // a hair inside so that a value of exactly 10^k does not open an empty decade
        let lo = (a.log10() + 1e-9).floor() as i32;
        let hi = ((b.log10() - 1e-9).ceil() as i32).max(lo + 1);
        Some(LogAxis { lo, hi })
    }

    /// Position of `v` along the axis, 0 at the low end and 1 at the high end.
    pub fn frac(&self, v: f64) -> f64 {
        (v.log10() - f64::from(self.lo)) / f64::from(self.hi - self.lo)
    }

    /// Tick values: every decade, and 2 and 5 within each when the axis spans at most three
    /// decades. Each with whether it is labelled (all are).
    pub fn ticks(&self) -> Vec<f64> {
        let mut t = Vec::new();
        let minor = self.hi - self.lo <= 3;
        for e in self.lo..=self.hi {
            let d = 10f64.powi(e);
            t.push(d);
            if minor && e < self.hi {
                t.push(2.0 * d);
                t.push(5.0 * d);
            }
        }
        t
    }
}

/// A tick label: plain decimals from 0.001 to 100 000, powers of ten beyond.
pub fn label(v: f64) -> String {
    if (1e-3..1e5).contains(&v) {
        let s = format!("{v:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    } else {
        let e = v.log10().round() as i32;
        let m = v / 10f64.powi(e);
        if (m - 1.0).abs() < 1e-9 {
            format!("1e{e}")
        } else {
            format!("{m:.0}e{e}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_and_labels() {
        let a = LogAxis::covering([0.03, 0.7, 12.0].into_iter()).unwrap();
        assert_eq!(a, LogAxis { lo: -2, hi: 2 });
        assert!((a.frac(1.0) - 0.5).abs() < 1e-12);
        let b = LogAxis::covering([1.0, 10.0].into_iter()).unwrap();
        assert_eq!(b, LogAxis { lo: 0, hi: 1 });
        assert_eq!(b.ticks(), vec![1.0, 2.0, 5.0, 10.0]);
        assert!(LogAxis::covering([0.0, -1.0, f64::NAN].into_iter()).is_none());
        assert_eq!(label(0.05), "0.05");
        assert_eq!(label(2000.0), "2000");
        assert_eq!(label(1e-4), "1e-4");
        assert_eq!(label(2e6), "2e6");
    }
}
