//! pcomb's output: every output pixel the sum of the inputs' (nearest) pixels, or what the
//! expressions make of them, written as an RGBE picture (negatives clipped) or a float
//! matrix.
// Per-channel colour arithmetic reads most clearly with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::io::Write;

use anyhow::{Context, Result};
use fenestra_formats::rgbe;

use super::expr::{ExprInput, Exprs};

/// The output's size and encoding.
#[derive(Debug, Clone, Copy)]
pub struct Output {
    /// Output width.
    pub xres: usize,
    /// Output height.
    pub yres: usize,
    /// `-ff`: a float matrix (no clipping) instead of an RGBE picture.
    pub float_out: bool,
}

/// Writes the output's pixels (after its header) to `out`, top row first; `data` are the
/// inputs (all `xmax × ymax`), `exprs` the compiled expressions, if any.
pub fn write_pixels(
    out: &mut impl Write,
    data: &[ExprInput],
    mut exprs: Option<&mut Exprs>,
    (xmax, ymax): (usize, usize),
    o: Output,
) -> Result<()> {
    let Output {
        xres,
        yres,
        float_out,
    } = o;
    let mut row = vec![[0f32; 3]; xres];
    let mut scan = vec![[0u8; 4]; xres];
    let mut fbuf = Vec::with_capacity(xres * 12);
    for yo in 0..yres {
        // Output row yo from the top; y counts up from the bottom as in Radiance.
        let y = yres - 1 - yo;
        let yin = ((y as f64 + 0.5) * ymax as f64 / yres as f64) as usize;
        let rin = ymax.saturating_sub(1).saturating_sub(yin);
        for (x, px) in row.iter_mut().enumerate() {
            let xin = ((x as f64 + 0.5) * xmax as f64 / xres as f64) as usize;
            let mut sum = [0f64; 3];
            for inp in data {
                let p = inp.pixels[rin * inp.width + xin];
                for k in 0..3 {
                    sum[k] += p[k] as f64;
                }
            }
            if let Some(e) = exprs.as_deref_mut() {
                sum = e
                    .pixel(x, y, sum)
                    .with_context(|| format!("pixel ({x}, {y})"))?;
            }
            for k in 0..3 {
                px[k] = if !float_out && sum[k] < 0.0 {
                    0.0
                } else {
                    sum[k] as f32
                };
            }
        }
        if float_out {
            fbuf.clear();
            for p in &row {
                for v in p {
                    fbuf.extend_from_slice(&v.to_ne_bytes());
                }
            }
            out.write_all(&fbuf)?;
        } else {
            for (s, p) in scan.iter_mut().zip(&row) {
                *s = rgbe::encode(*p);
            }
            fenestra_formats::picture_rle::write_scanline(out, &scan)?;
        }
    }
    Ok(())
}
