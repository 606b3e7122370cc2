//! Resolution strings (`-Y 26 +X 32`): picture size and the order of its scanlines.
//!
//! Image coordinates have their origin at the lower left, x to the right, y up. The
//! string names the scanline axis second: `-Y N +X M` (standard) holds N scanlines
//! from top to bottom, each of M pixels from left to right; the eight sign/order
//! combinations give every flip and quarter turn.

use std::fmt;

/// Longest side of a picture accepted: 2^24 pixels (a scanline buffer of 64 MiB).
pub const MAX_SIDE: usize = 1 << 24;

/// X decreases along a scanline (or from scanline to scanline when not Y-major).
pub const XDECR: u8 = 1;
/// Y decreases.
pub const YDECR: u8 = 2;
/// Scanlines run along X (Y is the major, slower axis).
pub const YMAJOR: u8 = 4;
/// The standard orientation: top scanline first, pixels left to right.
pub const PIXSTANDARD: u8 = YMAJOR | YDECR;

/// A picture's size in image coordinates and its storage order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resolution {
    /// Orientation flags ([`XDECR`], [`YDECR`], [`YMAJOR`]).
    pub orient: u8,
    /// Size along image x (width).
    pub xr: usize,
    /// Size along image y (height).
    pub yr: usize,
}

impl Resolution {
    /// A standard-orientation resolution of `width` × `height`.
    pub fn standard(width: usize, height: usize) -> Self {
        Resolution {
            orient: PIXSTANDARD,
            xr: width,
            yr: height,
        }
    }

    /// Pixels per scanline.
    pub fn scanlen(&self) -> usize {
        if self.orient & YMAJOR != 0 {
            self.xr
        } else {
            self.yr
        }
    }

    /// Number of scanlines.
    pub fn numscans(&self) -> usize {
        if self.orient & YMAJOR != 0 {
            self.yr
        } else {
            self.xr
        }
    }

    /// Image coordinates (x right, y up; integer pixel) of pixel `px` in scanline `sc`.
    pub fn pix2xy(&self, px: usize, sc: usize) -> (usize, usize) {
        let (mut x, mut y) = if self.orient & YMAJOR != 0 {
            (px, sc)
        } else {
            (sc, px)
        };
        if self.orient & XDECR != 0 {
            x = self.xr - 1 - x;
        }
        if self.orient & YDECR != 0 {
            y = self.yr - 1 - y;
        }
        (x, y)
    }

    /// Image location in [0,1]² of the centre of pixel `px` in scanline `sc`.
    pub fn pix2loc(&self, px: usize, sc: usize) -> [f64; 2] {
        let (x, y) = self.pix2xy(px, sc);
        [
            (x as f64 + 0.5) / self.xr as f64,
            (y as f64 + 0.5) / self.yr as f64,
        ]
    }

    /// Parses a resolution line (`-Y 26 +X 32`, any of the eight forms; padding free).
    /// Sides over [`MAX_SIDE`] pixels are refused (`None`), so a damaged line cannot
    /// ask for a scanline buffer of gigabytes.
    pub fn parse(line: &str) -> Option<Self> {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() != 4 {
            return None;
        }
        let axis = |s: &str| -> Option<(bool, char)> {
            let mut c = s.chars();
            let sign = match c.next()? {
                '-' => true,
                '+' => false,
                _ => return None,
            };
            let ax = c.next()?;
            if c.next().is_some() || !(ax == 'X' || ax == 'Y') {
                return None;
            }
            Some((sign, ax))
        };
        let (s1, a1) = axis(w[0])?;
        let (s2, a2) = axis(w[2])?;
        if a1 == a2 {
            return None;
        }
        let n1: usize = w[1].parse().ok().filter(|&n| n <= MAX_SIDE)?;
        let n2: usize = w[3].parse().ok().filter(|&n| n <= MAX_SIDE)?;
        let mut orient = 0;
        let (xr, yr, xdec, ydec) = if a1 == 'Y' {
            orient |= YMAJOR;
            (n2, n1, s2, s1)
        } else {
            (n1, n2, s1, s2)
        };
        if xdec {
            orient |= XDECR;
        }
        if ydec {
            orient |= YDECR;
        }
        Some(Resolution { orient, xr, yr })
    }
}

impl fmt::Display for Resolution {
    /// The line as Radiance writes it (fields right-justified in 8), newline included.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sx = if self.orient & XDECR != 0 { '-' } else { '+' };
        let sy = if self.orient & YDECR != 0 { '-' } else { '+' };
        if self.orient & YMAJOR != 0 {
            writeln!(f, "{sy}Y {:8} {sx}X {:8}", self.yr, self.xr)
        } else {
            writeln!(f, "{sx}X {:8} {sy}Y {:8}", self.xr, self.yr)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_string_round_trips() {
        let r = Resolution::standard(32, 26);
        assert_eq!(r.to_string(), "-Y       26 +X       32\n");
        assert_eq!(Resolution::parse("-Y 26 +X 32"), Some(r));
    }

    #[test]
    fn all_eight_orientations_parse_and_print() {
        for o in 0..8u8 {
            let r = Resolution {
                orient: o,
                xr: 5,
                yr: 3,
            };
            assert_eq!(Resolution::parse(&r.to_string()), Some(r));
        }
    }

    #[test]
    fn standard_first_pixel_is_top_left() {
        let r = Resolution::standard(4, 2);
        assert_eq!(r.pix2xy(0, 0), (0, 1));
        assert_eq!(r.pix2loc(0, 0), [0.125, 0.75]);
        let rot = Resolution::parse("+X 4 +Y 2").unwrap();
        assert_eq!((rot.scanlen(), rot.numscans()), (2, 4));
        assert_eq!(rot.pix2xy(1, 3), (3, 1));
    }

    #[test]
    fn garbage_is_rejected() {
        for s in [
            "",
            "-Y 2",
            "-Y 2 +Y 3",
            "Y 2 X 3",
            "-Y a +X 3",
            "-Y 2 +X 3 4",
        ] {
            assert_eq!(Resolution::parse(s), None, "{s}");
        }
    }
}
