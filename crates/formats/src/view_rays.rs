//! vwrays' engine: the ray through each pixel of a view (or each pixel position read),
//! jittered (`-pj`) and sampled over an aperture (`-pd`) with numbers keyed by the pixel
//! and the repeat, written as a number stream (ascii `%e`, float or double).
// Component-wise vector arithmetic reads most clearly with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::io::{BufRead, Read, Write};

use anyhow::{bail, Context, Result};

use crate::resolution::Resolution;
use crate::view::{View, FTINY};
use crate::view_print::fmt_e;

/// The `-f` number-stream format (one type for every tool).
pub type Fmt = fenestra_io::numfmt::RayFormat;

/// How the rays are made and written.
#[derive(Debug, Clone)]
pub struct Settings {
    /// Output format.
    pub fmt: Fmt,
    /// `-c`: each ray written this many times (with its own jitter and aperture sample).
    pub repeat: i64,
    /// `-pj`: pixel jitter fraction.
    pub pj: f64,
    /// `-pd`: aperture diameter.
    pub pd: f64,
    /// `-u`: flush after each ray.
    pub unbuffered: bool,
}

/// A uniform number in [0,1) keyed by a sample index (splitmix64), so output does not
/// depend on anything but the command line.
fn urand(key: u64) -> f64 {
    let mut z = key.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// The ray for image location `loc`, with aperture sampling; zeros outside the view.
fn ray_at(view: &View, loc: [f64; 2], set: &Settings, key: u64) -> ([f64; 3], [f64; 3]) {
    let Some((mut o, mut d, dist)) = view.ray(loc[0], loc[1]) else {
        return ([0.0; 3], [0.0; 3]);
    };
    if set.pd > FTINY {
        aperture(view, &mut o, &mut d, set.pd, key);
    }
    if view.vaft > FTINY {
        for c in &mut d {
            *c *= dist;
        }
    }
    (o, d)
}

/// Moves the origin to a random point of an aperture of diameter `dia` centred on it,
/// keeping the point at the focal distance along the original ray in focus.
fn aperture(view: &View, o: &mut [f64; 3], d: &mut [f64; 3], dia: f64, key: u64) {
    let (mut a, mut b);
    let mut k = 0u64;
    loop {
        a = 0.5 - urand(key ^ (0xA5A5 + 2 * k));
        b = 0.5 - urand(key ^ (0xA5A5 + 2 * k + 1));
        k += 1;
        if a * a + b * b <= 0.25 {
            break;
        }
    }
    a *= dia;
    b *= dia;
    let unit = |v: &[f64; 3]| {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / n, v[1] / n, v[2] / n]
    };
    let (hu, vu) = (unit(&view.hvec), unit(&view.vvec));
    let cosd: f64 = (0..3).map(|i| d[i] * view.vdir[i]).sum();
    let t = if cosd > FTINY {
        view.vdist / cosd
    } else {
        view.vdist
    };
    let focus: Vec<f64> = (0..3).map(|i| o[i] + d[i] * t).collect();
    for i in 0..3 {
        o[i] += a * hu[i] + b * vu[i];
    }
    let mut nd = [focus[0] - o[0], focus[1] - o[1], focus[2] - o[2]];
    let n = (nd[0] * nd[0] + nd[1] * nd[1] + nd[2] * nd[2]).sqrt();
    if n > 0.0 {
        for c in &mut nd {
            *c /= n;
        }
        *d = nd;
    }
}

fn put(out: &mut impl Write, fmt: Fmt, o: &[f64; 3], d: &[f64; 3]) -> std::io::Result<()> {
    match fmt {
        Fmt::Ascii => writeln!(
            out,
            "{} {} {} {} {} {}",
            fmt_e(o[0], 5),
            fmt_e(o[1], 5),
            fmt_e(o[2], 5),
            fmt_e(d[0], 5),
            fmt_e(d[1], 5),
            fmt_e(d[2], 5)
        ),
        Fmt::Float => {
            let mut b = [0u8; 24];
            for (i, v) in o.iter().chain(d.iter()).enumerate() {
                b[i * 4..i * 4 + 4].copy_from_slice(&(*v as f32).to_ne_bytes());
            }
            out.write_all(&b)
        }
        Fmt::Double => {
            let mut b = [0u8; 48];
            for (i, v) in o.iter().chain(d.iter()).enumerate() {
                b[i * 8..i * 8 + 8].copy_from_slice(&v.to_ne_bytes());
            }
            out.write_all(&b)
        }
    }
}

/// Writes the rays of every pixel of `res` in scanline order; with a z-buffer, each ray
/// starts at the surface point its depth gives and points back toward the view.
pub fn put_rays(
    view: &View,
    res: &Resolution,
    mut zbuf: Option<Box<dyn Read>>,
    set: &Settings,
    out: &mut impl Write,
) -> Result<()> {
    let (sl, ns) = (res.scanlen(), res.numscans());
    let mut zline = vec![0f32; sl];
    let mut zbytes = vec![0u8; sl * 4];
    for sc in 0..ns {
        if let Some(z) = zbuf.as_mut() {
            z.read_exact(&mut zbytes)
                .with_context(|| format!("z-buffer ends before scanline {sc} of {ns}"))?;
            for (v, b) in zline.iter_mut().zip(zbytes.chunks_exact(4)) {
                *v = f32::from_ne_bytes([b[0], b[1], b[2], b[3]]);
            }
        }
        for si in 0..sl {
            let base = res.pix2loc(si, sc);
            let pixel = (sc * sl + si) as u64;
            for c in 0..set.repeat.max(0) as u64 {
                let key = pixel.wrapping_mul(0x1_0000_0001).wrapping_add(c << 40);
                let mut loc = base;
                if set.pj > 0.0 {
                    loc[0] += set.pj * (0.5 - urand(key * 2)) / res.xr as f64;
                    loc[1] += set.pj * (0.5 - urand(key * 2 + 1)) / res.yr as f64;
                }
                let (mut o, mut d) = ray_at(view, loc, set, key);
                if zbuf.is_some() && d != [0.0; 3] {
                    let z = zline[si] as f64;
                    for i in 0..3 {
                        o[i] += d[i] * z;
                        d[i] = -d[i];
                    }
                }
                put(out, set.fmt, &o, &d)?;
                if set.unbuffered {
                    out.flush()?;
                }
            }
        }
    }
    Ok(())
}

/// Writes the rays of the pixel positions `x y` read from `input`.
pub fn pix2rays(
    input: &mut impl BufRead,
    view: &View,
    res: &Resolution,
    set: &Settings,
    out: &mut impl Write,
) -> Result<()> {
    let mut text = String::new();
    let mut pending: Vec<String> = Vec::new();
    let mut n: u64 = 0;
    let mut lineno = 0usize;
    loop {
        text.clear();
        let got = input.read_line(&mut text)?;
        lineno += 1;
        if got > 0 {
            pending.extend(text.split_whitespace().map(str::to_string));
        }
        while pending.len() >= 2 {
            let px: f64 = pending[0].parse().map_err(|_| {
                anyhow::anyhow!(
                    "input line {lineno}: expected 'x y' pixel position, got '{}'",
                    pending[0]
                )
            })?;
            let py: f64 = pending[1].parse().map_err(|_| {
                anyhow::anyhow!(
                    "input line {lineno}: expected 'x y' pixel position, got '{}'",
                    pending[1]
                )
            })?;
            pending.drain(..2);
            let loc = [(px + 0.5) / res.xr as f64, (py + 0.5) / res.yr as f64];
            for c in 0..set.repeat.max(0) as u64 {
                let key = n.wrapping_mul(0x1_0000_0001).wrapping_add(c << 40);
                let (o, d) = ray_at(view, loc, set, key);
                put(out, set.fmt, &o, &d)?;
            }
            n += 1;
            if set.unbuffered {
                out.flush()?;
            }
        }
        if got == 0 {
            break;
        }
    }
    if !pending.is_empty() {
        bail!(
            "expected 'x y' pixel position on input, got a lone '{}'",
            pending[0]
        );
    }
    Ok(())
}
