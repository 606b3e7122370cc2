//! Input rays (origin and direction, six numbers) read one at a time from text or binary
//! input, as rtrace and rcontrib read them: nothing is read past the ray asked for, so a
//! program that sends a ray and waits for its answer is served at once.
//!
//! Text words are numbers as C's `atof` reads whole words (`nan` and `inf` included); the
//! first word that is not a number ends the input with a warning naming its line (Radiance
//! stops there silently). Values that are not finite are passed on: the tools answer such a
//! ray with zeros and a warning, never a NaN.

use std::collections::VecDeque;
use std::io::BufRead;

use anyhow::Result;

pub use fenestra_io::numfmt::RayFormat;

/// The format a whole `-f` suffix names (`a`, `f` or `d`, one letter alone); `None` for
/// anything else.
pub fn format_suffix(w: &str) -> Option<RayFormat> {
    let mut c = w.chars();
    match (c.next().and_then(RayFormat::from_letter), c.next()) {
        (Some(f), None) => Some(f),
        _ => None,
    }
}

/// One input ray: origin (or point) and direction (or normal).
pub type Ray = ([f64; 3], [f64; 3]);

/// Reads rays one at a time.
pub struct RayReader<R: BufRead> {
    rd: R,
    fmt: RayFormat,
    words: VecDeque<String>,
    line: u64,
    rays: u64,
    done: bool,
    warning: Option<String>,
}

impl<R: BufRead> RayReader<R> {
    /// Reads rays of format `fmt` from `rd`.
    pub fn new(rd: R, fmt: RayFormat) -> Self {
        RayReader {
            rd,
            fmt,
            words: VecDeque::new(),
            line: 0,
            rays: 0,
            done: false,
            warning: None,
        }
    }

    /// Rays returned so far.
    pub fn count(&self) -> u64 {
        self.rays
    }

    /// Why the input ended early (a word that is not a number, an incomplete last ray),
    /// once, for the caller to print as a warning.
    pub fn take_warning(&mut self) -> Option<String> {
        self.warning.take()
    }

    /// The next ray; `None` at the end of input (or where it stopped).
    pub fn next_ray(&mut self) -> Result<Option<Ray>> {
        if self.done {
            return Ok(None);
        }
        let mut v = [0.0f64; 6];
        let got = match self.fmt {
            RayFormat::Ascii => self.ascii(&mut v)?,
            RayFormat::Float => self.binary::<4>(&mut v)?,
            RayFormat::Double => self.binary::<8>(&mut v)?,
        };
        if got < 6 {
            self.done = true;
            if got > 0 && self.warning.is_none() {
                self.warning = Some(format!(
                    "incomplete ray at the end of the input ({got} of 6 values) ignored"
                ));
            }
            return Ok(None);
        }
        self.rays += 1;
        Ok(Some(([v[0], v[1], v[2]], [v[3], v[4], v[5]])))
    }

    fn ascii(&mut self, v: &mut [f64; 6]) -> Result<usize> {
        let mut n = 0;
        while n < 6 {
            if self.words.is_empty() {
                let mut line = Vec::new();
                if self.rd.read_until(b'\n', &mut line)? == 0 {
                    return Ok(n);
                }
                self.line += 1;
                let text = String::from_utf8_lossy(&line);
                self.words
                    .extend(text.split_ascii_whitespace().map(str::to_string));
                continue;
            }
            let w = self.words.pop_front().unwrap_or_default();
            match w.parse::<f64>() {
                Ok(x) => {
                    v[n] = x;
                    n += 1;
                }
                Err(_) => {
                    self.done = true;
                    let shown: String = w.chars().take(40).collect();
                    self.warning = Some(format!(
                        "input line {}: '{shown}' is not a number; input ends there ({} complete rays read)",
                        self.line, self.rays
                    ));
                    return Ok(0);
                }
            }
        }
        Ok(n)
    }

    fn binary<const S: usize>(&mut self, v: &mut [f64; 6]) -> Result<usize> {
        let mut rec = [0u8; 48];
        let want = 6 * S;
        let mut got = 0;
        while got < want {
            let k = self.rd.read(&mut rec[got..want])?;
            if k == 0 {
                break;
            }
            got += k;
        }
        let whole = got / S;
        for (i, c) in rec[..whole * S].chunks_exact(S).enumerate() {
            v[i] = if S == 4 {
                f32::from_ne_bytes([c[0], c[1], c[2], c[3]]) as f64
            } else {
                f64::from_ne_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]])
            };
        }
        Ok(if got == want {
            6
        } else {
            whole.max(usize::from(got > 0))
        })
    }
}

/// When Radiance's renderers flush their output: after every `every` records (`-x`
/// without a picture's `-y`; 0: never) and after a record holding a dummy
/// (zero-direction) ray, which also restarts the count.
#[derive(Debug, Clone, Copy)]
pub struct FlushSchedule {
    every: usize,
    left: usize,
}

impl FlushSchedule {
    /// Flushes every `every` records (0: only after dummy rays).
    pub fn new(every: usize) -> Self {
        FlushSchedule { every, left: every }
    }

    /// A record ended (`dummy`: it held a zero-direction ray): whether to flush now.
    pub fn record_done(&mut self, dummy: bool) -> bool {
        if dummy {
            self.left = self.every;
            return true;
        }
        if self.every > 0 {
            self.left -= 1;
            if self.left == 0 {
                self.left = self.every;
                return true;
            }
        }
        false
    }
}

/// Whether every value of a ray is finite.
pub fn finite(r: &Ray) -> bool {
    r.0.iter().chain(&r.1).all(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &[u8], fmt: RayFormat) -> (Vec<Ray>, Option<String>) {
        let mut r = RayReader::new(text, fmt);
        let mut v = Vec::new();
        while let Some(x) = r.next_ray().unwrap() {
            v.push(x);
        }
        (v, r.take_warning())
    }

    #[test]
    fn text_rays_across_lines() {
        let (v, w) = all(b"0 0 0\n0 0 1 1 2 3 4\n5 6\n", RayFormat::Ascii);
        assert_eq!(
            v,
            [
                ([0.0; 3], [0.0, 0.0, 1.0]),
                ([1.0, 2.0, 3.0], [4.0, 5.0, 6.0])
            ]
        );
        assert!(w.is_none());
    }

    #[test]
    fn non_number_stops_with_a_warning() {
        let (v, w) = all(b"0 0 0 0 0 1\n1 2 x 4 5 6\n0 0 0 0 0 1\n", RayFormat::Ascii);
        assert_eq!(v.len(), 1);
        let w = w.unwrap();
        assert!(w.contains("line 2") && w.contains("'x'"), "{w}");
    }

    #[test]
    fn nan_and_inf_are_numbers() {
        let (v, w) = all(b"nan 0 0 0 0 1 inf -Infinity 0 0 0 1\n", RayFormat::Ascii);
        assert_eq!(v.len(), 2);
        assert!(!finite(&v[0]) && !finite(&v[1]));
        assert!(w.is_none());
    }

    #[test]
    fn flushes_as_radiance() {
        let mut f = FlushSchedule::new(3);
        let got: Vec<bool> = [false, false, false, false, true, false, false, false]
            .iter()
            .map(|&d| f.record_done(d))
            .collect();
        assert_eq!(got, [false, false, true, false, true, false, false, true]);
        let mut never = FlushSchedule::new(0);
        assert!(!never.record_done(false) && never.record_done(true));
    }

    #[test]
    fn incomplete_ray_is_reported() {
        let (v, w) = all(b"0 0 0 0 0 1 7 8", RayFormat::Ascii);
        assert_eq!(v.len(), 1);
        assert!(w.unwrap().contains("2 of 6"));
        let mut bytes: Vec<u8> = [1.0f32, 2.0, 3.0, 0.0, 0.0, 1.0, 9.0]
            .iter()
            .flat_map(|x| x.to_ne_bytes())
            .collect();
        bytes.push(0);
        let (v, w) = all(&bytes, RayFormat::Float);
        assert_eq!(v, [([1.0, 2.0, 3.0], [0.0, 0.0, 1.0])]);
        assert!(w.unwrap().contains("1 of 6"));
    }
}
