//! Radiance HDR pictures (`.hdr`/`.pic`): header, resolution string and RGBE/XYZE
//! scanlines in any of the eight orientations; written in the standard orientation
//! with the new run-length encoding.
// Component-wise vector arithmetic reads most clearly with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::io::{BufRead, Read, Write};

use crate::picture_rle::{read_scanline, write_scanline};
use crate::resolution::{Resolution, PIXSTANDARD};
use crate::rgbe;
use crate::view::View;

/// FORMAT value of RGB pictures.
pub const FMT_RGBE: &str = "32-bit_rle_rgbe";
/// FORMAT value of CIE XYZ pictures.
pub const FMT_XYZE: &str = "32-bit_rle_xyze";

/// Why a picture could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PictureError {
    /// The information header is unreadable.
    #[error("{0}")]
    Header(String),
    /// The FORMAT line names something other than a picture.
    #[error("not a Radiance picture (FORMAT={0})")]
    Format(String),
    /// The resolution line is missing or malformed.
    #[error("bad resolution string '{0}'")]
    Resolution(String),
    /// A scanline could not be decoded.
    #[error("scanline {line} of {total}: {msg}")]
    Scanline {
        /// Scanline index (0 = first in the file).
        line: usize,
        /// Number of scanlines.
        total: usize,
        /// What went wrong.
        msg: String,
    },
    /// Reading failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
}

/// What the header of a picture says.
#[derive(Debug, Clone, PartialEq)]
pub struct PictureInfo {
    /// The header lines in order, without the `#?` line, FORMAT line and newline characters.
    pub lines: Vec<String>,
    /// True for `32-bit_rle_xyze`.
    pub xyz: bool,
    /// Product of all `EXPOSURE=` values (1 when absent).
    pub exposure: f64,
    /// Product of all `COLORCORR=` triples.
    pub colorcorr: [f64; 3],
    /// Product of all `PIXASPECT=` values (1 when absent).
    pub pixaspect: f64,
    /// The view from `VIEW=` (and renderer command) lines, if any (not set up).
    pub view: Option<View>,
}

impl Default for PictureInfo {
    fn default() -> Self {
        PictureInfo {
            lines: Vec::new(),
            xyz: false,
            exposure: 1.0,
            colorcorr: [1.0; 3],
            pixaspect: 1.0,
            view: None,
        }
    }
}

/// A decoded picture: pixels in the file's scanline order.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// Header information.
    pub info: PictureInfo,
    /// Size and orientation as stored.
    pub res: Resolution,
    /// Pixels, scanline after scanline as stored (values as stored: exposure not undone).
    pub pixels: Vec<[f32; 3]>,
}

/// Reads header lines up to the blank line that ends them.
pub fn read_header_lines(r: &mut impl BufRead) -> Result<Vec<String>, PictureError> {
    let mut lines = Vec::new();
    let mut buf = Vec::new();
    let mut first = true;
    loop {
        buf.clear();
        let n = r.read_until(b'\n', &mut buf)?;
        if n == 0 {
            return Err(PictureError::Header(if first {
                "empty input (no header)".into()
            } else {
                "header not ended by a blank line".into()
            }));
        }
        if first && !buf[0].is_ascii_graphic() && buf[0] != b' ' && buf[0] != b'\t' {
            return Err(PictureError::Header(
                "no Radiance header (binary data at start)".into(),
            ));
        }
        first = false;
        while buf.last().is_some_and(|&c| c == b'\n' || c == b'\r') {
            buf.pop();
        }
        if buf.is_empty() {
            return Ok(lines);
        }
        lines.push(String::from_utf8_lossy(&buf).into_owned());
    }
}

impl PictureInfo {
    /// Interprets header lines (`prog` names the program, whose own command lines
    /// count as view lines, as Radiance does).
    pub fn from_lines(all: &[String], prog: &str) -> Result<Self, PictureError> {
        let mut info = PictureInfo::default();
        let mut view = View::default();
        let mut has_view = false;
        for l in all {
            if l.starts_with("#?") {
                continue;
            }
            if let Some(f) = l.strip_prefix("FORMAT=") {
                let f = f.trim();
                match f {
                    FMT_RGBE => info.xyz = false,
                    FMT_XYZE => info.xyz = true,
                    _ => return Err(PictureError::Format(f.to_string())),
                }
                continue;
            }
            if let Some(v) = l.strip_prefix("EXPOSURE=") {
                let e: f64 = v
                    .trim()
                    .parse()
                    .map_err(|_| PictureError::Header(format!("bad EXPOSURE value in '{l}'")))?;
                info.exposure *= e;
            } else if let Some(v) = l.strip_prefix("COLORCORR=") {
                let w: Vec<f64> = v
                    .split_whitespace()
                    .filter_map(|x| x.parse().ok())
                    .collect();
                if w.len() != 3 {
                    return Err(PictureError::Header(format!("bad COLORCORR line '{l}'")));
                }
                for k in 0..3 {
                    info.colorcorr[k] *= w[k];
                }
            } else if let Some(v) = l.strip_prefix("PIXASPECT=") {
                let a: f64 = v
                    .trim()
                    .parse()
                    .map_err(|_| PictureError::Header(format!("bad PIXASPECT value in '{l}'")))?;
                info.pixaspect *= a;
            }
            if View::is_view_line(l, prog) && view.scan_line(l) > 0 {
                has_view = true;
            }
            info.lines.push(l.clone());
        }
        if has_view {
            info.view = Some(view);
        }
        Ok(info)
    }
}

impl Picture {
    /// Reads a whole picture.
    pub fn read(r: &mut impl BufRead, prog: &str) -> Result<Picture, PictureError> {
        let lines = read_header_lines(r)?;
        let info = PictureInfo::from_lines(&lines, prog)?;
        let res = read_resolution(r)?;
        let pixels = read_pixels(r, &res)?;
        Ok(Picture { info, res, pixels })
    }

    /// Width and height as stored (scanline length, number of scanlines).
    pub fn scan_dims(&self) -> (usize, usize) {
        (self.res.scanlen(), self.res.numscans())
    }

    /// Divides the exposure (and colour correction) out of the pixels.
    pub fn undo_exposure(&mut self) {
        let f: Vec<f64> = (0..3)
            .map(|k| 1.0 / (self.info.exposure * self.info.colorcorr[k]))
            .collect();
        if f.iter().all(|&x| x == 1.0) {
            return;
        }
        for p in &mut self.pixels {
            for k in 0..3 {
                p[k] = (p[k] as f64 * f[k]) as f32;
            }
        }
        self.info.exposure = 1.0;
        self.info.colorcorr = [1.0; 3];
    }

    /// The pixels rearranged in standard orientation of the image frame (the frame the
    /// view refers to): `xr` wide, `yr` high, top row first. Returns (width, height, pixels).
    pub fn to_standard(&self) -> (usize, usize, Vec<[f32; 3]>) {
        let (w, h) = (self.res.xr, self.res.yr);
        if self.res.orient == PIXSTANDARD {
            return (w, h, self.pixels.clone());
        }
        let mut out = vec![[0f32; 3]; w * h];
        let sl = self.res.scanlen();
        for (i, p) in self.pixels.iter().enumerate() {
            let (x, y) = self.res.pix2xy(i % sl, i / sl);
            out[(h - 1 - y) * w + x] = *p;
        }
        (w, h, out)
    }
}

/// Reads the resolution line that follows the header.
pub fn read_resolution(r: &mut impl BufRead) -> Result<Resolution, PictureError> {
    let mut line = Vec::new();
    r.by_ref().take(64).read_until(b'\n', &mut line)?;
    let s = String::from_utf8_lossy(&line);
    let s = s.trim_end();
    if line.is_empty() {
        return Err(PictureError::Resolution("missing".into()));
    }
    Resolution::parse(s).ok_or_else(|| PictureError::Resolution(s.to_string()))
}

/// Decodes every scanline after the resolution line (file order).
pub fn read_pixels(r: &mut impl Read, res: &Resolution) -> Result<Vec<[f32; 3]>, PictureError> {
    let (sl, ns) = (res.scanlen(), res.numscans());
    let mut out = Vec::new();
    let mut scan = vec![[0u8; 4]; sl];
    for line in 0..ns {
        read_scanline(r, &mut scan).map_err(|e| PictureError::Scanline {
            line,
            total: ns,
            msg: e.to_string(),
        })?;
        out.extend(scan.iter().map(|&p| rgbe::decode(p)));
    }
    Ok(out)
}

/// What goes into a written picture's header besides the pixels.
#[derive(Debug, Clone, Default)]
pub struct PictureHeader {
    /// Lines copied first (e.g. the inputs' headers), without newlines.
    pub lines: Vec<String>,
    /// The writing program's command line (provenance).
    pub command: Option<String>,
    /// A view to record as `VIEW=`.
    pub view: Option<View>,
    /// An exposure to record as `EXPOSURE=` (values are written as given).
    pub exposure: Option<f64>,
    /// XYZE instead of RGBE.
    pub xyz: bool,
}

/// Writes the header, resolution string and scanlines of a standard-orientation picture.
/// `pixels` holds `height` rows of `width`, top row first. `header = None` writes no
/// header (Radiance's `-h`), only the resolution string and pixels.
pub fn write_picture(
    w: &mut impl Write,
    header: Option<&PictureHeader>,
    width: usize,
    height: usize,
    pixels: &[[f32; 3]],
) -> std::io::Result<()> {
    assert_eq!(pixels.len(), width * height, "pixel count");
    if let Some(h) = header {
        let mut text = String::from("#?RADIANCE\n");
        for l in &h.lines {
            text.push_str(l);
            text.push('\n');
        }
        if let Some(c) = &h.command {
            text.push_str(c);
            text.push('\n');
        }
        if let Some(v) = &h.view {
            text.push_str(&v.header_line());
            text.push('\n');
        }
        if let Some(e) = h.exposure {
            text.push_str(&format!("EXPOSURE={}\n", crate::view_print::fmt_e(e, 4)));
        }
        text.push_str(&format!(
            "FORMAT={}\n\n",
            if h.xyz { FMT_XYZE } else { FMT_RGBE }
        ));
        w.write_all(text.as_bytes())?;
    }
    write_resolution_and_pixels(w, width, height, pixels)
}

/// Writes the standard resolution string then the run-length encoded scanlines.
pub fn write_resolution_and_pixels(
    w: &mut impl Write,
    width: usize,
    height: usize,
    pixels: &[[f32; 3]],
) -> std::io::Result<()> {
    w.write_all(Resolution::standard(width, height).to_string().as_bytes())?;
    let mut scan = vec![[0u8; 4]; width];
    for row in pixels.chunks(width.max(1)).take(height) {
        for (s, p) in scan.iter_mut().zip(row) {
            *s = rgbe::encode(*p);
        }
        write_scanline(w, &scan)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(w: usize, h: usize) -> Vec<[f32; 3]> {
        // Decoded RGBE values re-encode exactly (largest mantissa >= 128).
        (0..w * h)
            .map(|i| {
                if i % 11 == 5 {
                    return [0.0; 3];
                }
                rgbe::decode([
                    200,
                    (i % 200) as u8,
                    (i * 3 % 200) as u8,
                    120 + (i % 20) as u8,
                ])
            })
            .collect()
    }

    #[test]
    fn write_then_read_is_identical() {
        for (w, h) in [(1usize, 1usize), (1, 7), (20, 3), (33, 17)] {
            let px = sample(w, h);
            let hdr = PictureHeader {
                command: Some("test -x".into()),
                exposure: Some(2.0),
                ..Default::default()
            };
            let mut buf = Vec::new();
            write_picture(&mut buf, Some(&hdr), w, h, &px).unwrap();
            let p = Picture::read(&mut buf.as_slice(), "test").unwrap();
            assert_eq!(p.res, Resolution::standard(w, h));
            assert_eq!(p.pixels, px);
            assert_eq!(p.info.exposure, 2.0);
            assert_eq!(p.to_standard().2, px);
        }
    }

    #[test]
    fn rotated_picture_is_reoriented() {
        // +X 3 +Y 2: scanlines run up the image, left column first.
        let mut data = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+X 3 +Y 2\n".to_vec();
        for i in 0..6u8 {
            data.extend_from_slice(&[i + 1, 0, 0, 129]);
        }
        let p = Picture::read(&mut data.as_slice(), "t").unwrap();
        let (w, h, std) = p.to_standard();
        assert_eq!((w, h), (3, 2));
        let reds: Vec<f32> = std.iter().map(|p| (p[0] * 128.0).floor()).collect();
        // file order: (x0,y0)=1 (x0,y1)=2 (x1,y0)=3 ...; top row is y=1.
        assert_eq!(reds, vec![2.0, 4.0, 6.0, 1.0, 3.0, 5.0]);
    }

    #[test]
    fn wrong_format_and_bad_resolution_are_errors() {
        let e = Picture::read(&mut &b"FORMAT=ascii\n\n-Y 1 +X 1\n"[..], "t").unwrap_err();
        assert!(e.to_string().contains("not a Radiance picture"), "{e}");
        let e = Picture::read(&mut &b"#?RADIANCE\n\n-Y 1\n"[..], "t").unwrap_err();
        assert!(e.to_string().contains("resolution"), "{e}");
        let e =
            Picture::read(&mut &b"#?RADIANCE\n\n-Y 2 +X 1\n\x01\x02\x03\x04"[..], "t").unwrap_err();
        assert!(e.to_string().contains("scanline 1 of 2"), "{e}");
    }

    #[test]
    fn view_is_found_in_header() {
        let data = b"#?RADIANCE\nVIEW= -vta -vh 180 -vv 180\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n\0\0\0\0";
        let p = Picture::read(&mut &data[..], "t").unwrap();
        assert_eq!(p.info.view.unwrap().horiz, 180.0);
    }
}

/// `CAPDATE=` and `GMT=` header lines for now, as Radiance's `fputnow` writes them
/// (`YYYY:MM:DD HH:MM:SS`); both are written in UTC.
pub fn capdate_lines() -> [String; 2] {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let s = format_time(secs);
    [format!("CAPDATE= {s}"), format!("GMT= {s}")]
}

/// Seconds since 1970 (UTC) as `YYYY:MM:DD HH:MM:SS`.
fn format_time(secs: i64) -> String {
    let days = secs.div_euclid(86400);
    let rem = secs.rem_euclid(86400);
    // Civil date from day count (proleptic Gregorian calendar).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}:{m:02}:{d:02} {:02}:{:02}:{:02}",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

#[cfg(test)]
mod time_tests {
    #[test]
    fn known_dates() {
        assert_eq!(super::format_time(0), "1970:01:01 00:00:00");
        assert_eq!(super::format_time(1_709_210_096), "2024:02:29 12:34:56");
    }
}

#[cfg(test)]
mod prop_tests {
    use super::*;
    use proptest::prelude::*;

    fn pixel() -> impl Strategy<Value = [f32; 3]> {
        prop_oneof![
            Just([0.0f32; 3]),
            (any::<u8>(), any::<u8>(), 128u8..=255, 30u8..=255, 0usize..3).prop_map(
                |(a, b, big, e, which)| {
                    let mut m = [a.min(big), b.min(big), a.min(big)];
                    m[which] = big;
                    rgbe::decode([m[0], m[1], m[2], e])
                }
            ),
        ]
    }

    proptest! {
        /// Decoded RGBE values survive write + read exactly, any size, runs or not.
        #[test]
        fn round_trip(w in 1usize..70, h in 1usize..6, seed in prop::collection::vec(pixel(), 1..40), rep in 1usize..9) {
            let px: Vec<[f32; 3]> = (0..w * h).map(|i| seed[(i / rep) % seed.len()]).collect();
            let mut buf = Vec::new();
            write_picture(&mut buf, Some(&PictureHeader::default()), w, h, &px).unwrap();
            let p = Picture::read(&mut buf.as_slice(), "t").unwrap();
            prop_assert_eq!(p.pixels, px);
        }

        /// Arbitrary floats (tiny, huge, negative, denormal) encode to within one
        /// mantissa step of the largest channel, negatives to zero.
        #[test]
        fn encode_error_bounded(r in any::<f32>(), g in any::<f32>(), b in any::<f32>()) {
            prop_assume!(r.is_finite() && g.is_finite() && b.is_finite());
            let c = [r, g, b];
            let d = rgbe::decode(rgbe::encode(c));
            let max = r.max(g).max(b) as f64;
            for k in 0..3 {
                let want = (c[k] as f64).max(0.0);
                if max > 1e-32 && max < 1e38 {
                    prop_assert!((d[k] as f64 - want).abs() <= max / 128.0 + 1e-38, "{:?} -> {:?}", c, d);
                }
            }
        }

        /// Mutated pictures never panic: they decode or give an error.
        #[test]
        fn mutations_do_not_panic(pos in 0usize..400, val in any::<u8>(), cut in 0usize..400) {
            let px: Vec<[f32; 3]> = (0..40 * 3).map(|i| [i as f32 * 0.1, 1.0, (i % 5) as f32]).collect();
            let mut buf = Vec::new();
            write_picture(&mut buf, Some(&PictureHeader::default()), 40, 3, &px).unwrap();
            let p = pos % buf.len();
            buf[p] = val;
            buf.truncate(buf.len() - cut % buf.len());
            let _ = Picture::read(&mut buf.as_slice(), "t");
        }
    }
}
