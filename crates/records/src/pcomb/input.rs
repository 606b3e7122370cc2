//! pcomb's inputs: Radiance pictures (any orientation, kept in stored scanline order) and
//! float or double RGB matrices.

use std::io::{BufRead, Read};

use anyhow::{bail, Context, Result};

use fenestra_formats::picture::{read_header_lines, read_pixels, read_resolution, PictureInfo};
use fenestra_formats::view::View;

/// One input picture or matrix, in its stored scanline order.
pub struct Input {
    /// The name shown in the header (`<stdin>`, `<Command>` or the file name).
    pub name: String,
    /// Its header lines.
    pub lines: Vec<String>,
    /// Width (pixels per scanline).
    pub width: usize,
    /// Height (scanlines).
    pub height: usize,
    /// Pixels, in stored scanline order.
    pub pixels: Vec<[f32; 3]>,
    /// Its view, if the header gives a valid one.
    pub view: Option<View>,
    /// `-o`: exposure and colour correction undone.
    pub original: bool,
    /// `EXPOSURE` product of its header.
    pub exposure: f64,
    /// `PIXASPECT` of its header.
    pub aspect: f64,
}

/// Reads a picture (any orientation; kept in stored scanline order, as Radiance's pcomb
/// does) or a float/double RGB matrix.
pub fn read_input(name: &str) -> Result<Input> {
    let mut r = fenestra_cli::input::open(name)?;
    let lines = read_header_lines(&mut r).with_context(|| format!("input '{name}'"))?;
    let format = lines
        .iter()
        .find_map(|l| l.strip_prefix("FORMAT="))
        .map(|f| f.trim().to_string());
    let shown = if name == "-" {
        "<stdin>"
    } else if name.starts_with('!') {
        "<Command>"
    } else {
        name
    }
    .to_string();
    match format.as_deref() {
        Some("float") | Some("double") => {
            let (w, h, px) = read_matrix(&mut r, &lines, format.as_deref() == Some("double"))
                .with_context(|| format!("input '{name}'"))?;
            let info = PictureInfo::from_lines(
                &lines
                    .iter()
                    .filter(|l| !l.starts_with("FORMAT="))
                    .cloned()
                    .collect::<Vec<_>>(),
                "pcomb",
            )
            .with_context(|| format!("input '{name}'"))?;
            Ok(Input {
                name: shown,
                lines,
                width: w,
                height: h,
                pixels: px,
                exposure: info.exposure,
                aspect: info.pixaspect,
                view: info.view,
                original: false,
            })
        }
        _ => {
            let info = PictureInfo::from_lines(&lines, "pcomb")
                .with_context(|| format!("input '{name}'"))?;
            let res = read_resolution(&mut r).with_context(|| format!("input '{name}'"))?;
            let pixels = read_pixels(&mut r, &res).with_context(|| format!("input '{name}'"))?;
            let (exposure, aspect) = (info.exposure, info.pixaspect);
            let mut view = info.view;
            if let Some(v) = view.as_mut() {
                if v.setup().is_err() {
                    view = None;
                }
            }
            Ok(Input {
                name: shown,
                lines,
                width: res.scanlen(),
                height: res.numscans(),
                pixels,
                view,
                original: false,
                exposure,
                aspect,
            })
        }
    }
}

fn read_matrix(
    r: &mut impl BufRead,
    lines: &[String],
    double: bool,
) -> Result<(usize, usize, Vec<[f32; 3]>)> {
    let key = |k: &str| -> Option<i64> {
        lines
            .iter()
            .find_map(|l| l.strip_prefix(k))
            .and_then(|v| v.trim().parse().ok())
    };
    let (Some(rows), Some(cols)) = (key("NROWS="), key("NCOLS=")) else {
        bail!("float matrix input needs NROWS and NCOLS in its header");
    };
    let ncomp = key("NCOMP=").unwrap_or(3);
    if ncomp != 3 {
        bail!("pcomb needs 3 components (RGB) per element, header says NCOMP={ncomp}");
    }
    if rows <= 0 || cols <= 0 {
        bail!("bad matrix size NROWS={rows} NCOLS={cols}");
    }
    let big = lines
        .iter()
        .find_map(|l| l.strip_prefix("BigEndian="))
        .map(|v| v.trim() == "1")
        .unwrap_or(cfg!(target_endian = "big"));
    let (rows, cols) = (rows as usize, cols as usize);
    let size = if double { 8 } else { 4 };
    let n = rows
        .checked_mul(cols)
        .and_then(|v| v.checked_mul(3 * size))
        .context("matrix too large")?;
    let mut data = Vec::new();
    r.take(n as u64).read_to_end(&mut data)?;
    if data.len() != n {
        bail!(
            "truncated matrix data: {} of {n} bytes for {rows} x {cols} RGB",
            data.len()
        );
    }
    let px = data
        .chunks_exact(3 * size)
        .map(|c| {
            let mut p = [0f32; 3];
            for k in 0..3 {
                let b = &c[k * size..(k + 1) * size];
                p[k] = if double {
                    let a: [u8; 8] = b.try_into().unwrap_or([0; 8]);
                    (if big {
                        f64::from_be_bytes(a)
                    } else {
                        f64::from_le_bytes(a)
                    }) as f32
                } else {
                    let a: [u8; 4] = b.try_into().unwrap_or([0; 4]);
                    if big {
                        f32::from_be_bytes(a)
                    } else {
                        f32::from_le_bytes(a)
                    }
                };
            }
            p
        })
        .collect();
    Ok((cols, rows, px))
}
