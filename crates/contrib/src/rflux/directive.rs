//! `#@rfluxmtx` directives: the hemisphere basis (`h=`), the up vector (`u=`) and a
//! receiver's output (`o=`), parsed as Radiance's rfluxmtx reads them.

use anyhow::{bail, Result};
use glam::DVec3;

/// A hemisphere basis named by `h=`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Basis {
    /// `h=u` (or `h=1`): one bin, cosine-weighted.
    Uniform,
    /// `h=kf`, `h=kh`, `h=kq` (also `k`, `k1`, `k2`, `k4`): Klems full, half, quarter.
    Klems(KlemsSize),
    /// `h=rN` / `h=tN`: Reinhart subdivision N (1 = Tregenza).
    Reinhart(u32),
    /// `h=scN`: Shirley–Chiu N × N square grid mapped to the disk.
    ShirleyChiu(u32),
    /// `h=cie`: the CIE sky-scanner pattern (receivers only).
    Cie,
}

/// The three Klems bases.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KlemsSize {
    /// 145 patches.
    Full,
    /// 77 patches.
    Half,
    /// 41 patches.
    Quarter,
}

impl KlemsSize {
    /// The basis of this size.
    pub fn basis(self) -> &'static fenestra_bsdf::KlemsBasis {
        match self {
            KlemsSize::Full => fenestra_bsdf::KlemsBasis::full(),
            KlemsSize::Half => fenestra_bsdf::KlemsBasis::half(),
            KlemsSize::Quarter => fenestra_bsdf::KlemsBasis::quarter(),
        }
    }
}

/// The directives in effect for a surface group.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Params {
    /// `true` for a left-handed basis (`h=-…`).
    pub left: bool,
    /// The basis letters after the sign (empty when no `h=` was given).
    pub hemis: String,
    /// The number in the basis letters (1 when none).
    pub hsiz: u32,
    /// The up vector (`None` until `u=` is given).
    pub up: Option<DVec3>,
    /// The receiver's output (`o=`).
    pub out: Option<String>,
}

impl Params {
    /// Forgets what belongs to one group (up vector, output) and keeps the basis, as
    /// rfluxmtx does between receivers.
    pub fn reset_group(&mut self) {
        self.up = None;
        self.out = None;
    }

    /// Applies directive text (the words after `#@rfluxmtx`, possibly several lines).
    pub fn apply(&mut self, text: &str) -> Result<()> {
        for word in split_words(text) {
            self.apply_word(&word)
                .map_err(|e| anyhow::anyhow!("bad parameter string: {}: {e}", text.trim()))?;
        }
        Ok(())
    }

    fn apply_word(&mut self, w: &str) -> Result<()> {
        if let Some(h) = w.strip_prefix("h=") {
            let (left, letters) = match h.as_bytes().first() {
                Some(b'-') => (true, &h[1..]),
                Some(b'+') => (false, &h[1..]),
                _ => (false, h),
            };
            if letters.is_empty() {
                bail!("'h=' needs a basis (u, kf, kh, kq, rN, scN, cie)");
            }
            let digits: String = letters.chars().filter(|c| c.is_ascii_digit()).collect();
            let n: u32 = if digits.is_empty() {
                0
            } else {
                digits
                    .parse()
                    .map_err(|_| anyhow::anyhow!("'{w}': the number is too large"))?
            };
            self.left = left;
            self.hemis = letters.to_string();
            self.hsiz = n.max(1);
            return Ok(());
        }
        if let Some(u) = w.strip_prefix("u=") {
            self.up = Some(direction(u).ok_or_else(|| {
                anyhow::anyhow!("'{w}': expected u=±X, ±Y, ±Z or u=x,y,z (not zero)")
            })?);
            return Ok(());
        }
        if let Some(o) = w.strip_prefix("o=") {
            let o = o.trim_matches(|c| c == '"' || c == '\'');
            if o.is_empty() {
                bail!("'o=' needs a file name or !command");
            }
            self.out = Some(o.to_string());
            return Ok(());
        }
        bail!("unknown directive '{w}' (expected h=, u= or o=)")
    }

    /// The basis the letters name (`None` when `h=` was not given).
    pub fn basis(&self) -> Result<Option<Basis>> {
        if self.hemis.is_empty() {
            return Ok(None);
        }
        let l = self.hemis.to_ascii_lowercase();
        let b = l.as_bytes();
        let second = b.get(1).copied();
        let basis = if b[0] == b'u' || b[0] == b'1' {
            Basis::Uniform
        } else if b[0] == b's' && second == Some(b'c') {
            if self.hsiz <= 1 {
                bail!("missing size for Shirley-Chiu sampling! (h=scN, N > 1)");
            }
            Basis::ShirleyChiu(self.hsiz)
        } else if b[0] == b'r' || b[0] == b't' {
            Basis::Reinhart(self.hsiz)
        } else if b[0] == b'k' {
            match second {
                None | Some(b'f') | Some(b'1') => Basis::Klems(KlemsSize::Full),
                Some(b'h') | Some(b'2') => Basis::Klems(KlemsSize::Half),
                Some(b'q') | Some(b'4') => Basis::Klems(KlemsSize::Quarter),
                _ => bail!("unrecognized hemisphere sampling: h={}", self.hemis),
            }
        } else if l == "cie" {
            Basis::Cie
        } else {
            bail!("unrecognized hemisphere sampling: h={}", self.hemis)
        };
        Ok(Some(basis))
    }
}

/// Splits directive text into `key=value` words; a quoted `o=` value may hold blanks.
fn split_words(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quote: Option<char> = None;
    for c in text.chars() {
        match quote {
            Some(q) => {
                cur.push(c);
                if c == q {
                    quote = None;
                }
            }
            None if c.is_whitespace() => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            None => {
                if (c == '"' || c == '\'') && cur.ends_with('=') {
                    quote = Some(c);
                }
                cur.push(c);
            }
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// An up vector: `±X`, `±Y`, `±Z` (signs may repeat) or `x,y,z`, normalised.
pub fn direction(s: &str) -> Option<DVec3> {
    let mut sign = 1.0;
    let mut rest = s;
    while let Some(c) = rest.chars().next() {
        match c {
            '+' => rest = &rest[1..],
            '-' => {
                sign = -sign;
                rest = &rest[1..];
            }
            _ => break,
        }
    }
    let axis = match rest {
        "x" | "X" => Some(DVec3::X),
        "y" | "Y" => Some(DVec3::Y),
        "z" | "Z" => Some(DVec3::Z),
        _ => None,
    };
    if let Some(a) = axis {
        return Some(a * sign);
    }
    let v: Vec<f64> = rest
        .split(',')
        .map(|w| w.trim().parse::<f64>().ok())
        .collect::<Option<_>>()?;
    if v.len() != 3 {
        return None;
    }
    let d = DVec3::new(sign * v[0], v[1], v[2]);
    let len = d.length();
    (len > 0.0 && len.is_finite()).then(|| d / len)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directives_parse_as_radiance_reads_them() {
        let mut p = Params::default();
        p.apply("h=-kq u=-Y o=\"out file.dat\"").unwrap();
        assert!(p.left);
        assert_eq!(p.basis().unwrap(), Some(Basis::Klems(KlemsSize::Quarter)));
        assert_eq!(p.up, Some(-DVec3::Y));
        assert_eq!(p.out.as_deref(), Some("out file.dat"));
        p.apply("h=r4 u=0,0,2").unwrap();
        assert_eq!(p.basis().unwrap(), Some(Basis::Reinhart(4)));
        assert_eq!(p.up, Some(DVec3::Z));
        p.apply("h=sc6").unwrap();
        assert_eq!(p.basis().unwrap(), Some(Basis::ShirleyChiu(6)));
        p.apply("h=u").unwrap();
        assert_eq!(p.basis().unwrap(), Some(Basis::Uniform));
        p.apply("h=k").unwrap();
        assert_eq!(p.basis().unwrap(), Some(Basis::Klems(KlemsSize::Full)));
        p.apply("h=r").unwrap();
        assert_eq!(p.basis().unwrap(), Some(Basis::Reinhart(1)));
        // a Radiance quirk kept: '-' before the first component negates x only
        assert_eq!(
            direction("-1,1,0"),
            Some(DVec3::new(-1.0, 1.0, 0.0).normalize())
        );
    }

    #[test]
    fn bad_directives_are_refused() {
        let mut p = Params::default();
        assert!(p.apply("h=").is_err());
        assert!(p.apply("q=1").is_err());
        assert!(p.apply("u=0,0,0").is_err());
        assert!(p.apply("u=up").is_err());
        p.apply("h=sc").unwrap();
        assert!(p.basis().is_err());
        p.apply("h=kx").unwrap();
        assert!(p.basis().is_err());
        p.apply("h=w").unwrap();
        assert!(p.basis().is_err());
    }
}
