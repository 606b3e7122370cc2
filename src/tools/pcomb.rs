//! pcomb: linear combinations of Radiance pictures (and float RGB matrices).

// Per-channel colour arithmetic reads most clearly with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::io::{BufRead, Read, Write};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_cli::opts::{Item, Kind, Opt, Spec};
use fenestra_formats::picture::{
    capdate_lines, read_header_lines, read_pixels, read_resolution, PictureInfo,
};
use fenestra_formats::rgbe;
use fenestra_formats::view::View;

#[path = "pcomb_expr.rs"]
mod expr;
use expr::{ExprInput, Exprs, Source};
use std::sync::Arc;

fn spec() -> Spec {
    Spec::new(
        "pcomb",
        "Combine Radiance pictures (sum, scale, colour) to the standard output",
    )
    .usage("[-h][-w][-ff][-x xres][-y yres][-e expr][-f file] [[-o][-s factor][-c r g b] input ..]")
    .interleaved(true)
    .opt(Opt::new(
        "h",
        Kind::Flag,
        "leave the inputs' headers out of the output header",
    ))
    .opt(Opt::new("w", Kind::Flag, "suppress warnings"))
    .opt(Opt::new(
        "ff",
        Kind::Flag,
        "write a float RGB matrix (no clipping of negatives)",
    ))
    .opt(Opt::new(
        "x",
        Kind::Word,
        "output x resolution (default: the inputs')",
    ))
    .opt(Opt::new(
        "y",
        Kind::Word,
        "output y resolution (default: the inputs')",
    ))
    .opt(Opt::new(
        "e",
        Kind::Word,
        "expression defining ro go bo (or lo) from ri(n) gi(n) bi(n) li(n), x, y …",
    ))
    .opt(Opt::new(
        "f",
        Kind::Word,
        "file of expressions (found through RAYPATH)",
    ))
    .opt(Opt::new(
        "o",
        Kind::Flag,
        "use original values of the next input (undo its exposure)",
    ))
    .opt(Opt::new(
        "s",
        Kind::Real,
        "scale the next input by a factor",
    ))
    .opt(Opt::new(
        "c",
        Kind::Words(3),
        "scale the next input's r g b by these factors",
    ))
}

/// One input picture or matrix, in its stored scanline order.
struct Input {
    name: String,
    lines: Vec<String>,
    width: usize,
    height: usize,
    pixels: Vec<[f32; 3]>,
    view: Option<View>,
    original: bool,
    exposure: f64,
    aspect: f64,
}

/// Runs pcomb.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let items = spec().parse(&args)?;
    let (mut echo, mut float_out) = (true, false);
    let (mut xopt, mut yopt) = (None, None);
    let mut coef = [1f32; 3];
    let mut original = false;
    let mut inputs: Vec<Input> = Vec::new();
    let mut sources: Vec<Source> = Vec::new();
    let (mut xword, mut yword) = (None, None);
    for it in &items {
        match it {
            Item::Opt(h) => match h.key {
                "h" => echo = !echo,
                "w" => {}
                "ff" => float_out = true,
                "x" => xword = Some(h.word().to_string()),
                "y" => yword = Some(h.word().to_string()),
                "e" => sources.push(Source::Expr(h.word().to_string())),
                "f" => sources.push(Source::File(h.word().to_string())),
                "o" => original = true,
                "s" => {
                    let s = h.real();
                    for c in &mut coef {
                        *c = (*c as f64 * s) as f32;
                    }
                }
                "c" => {
                    let v = h.reals()?;
                    for k in 0..3 {
                        coef[k] = (coef[k] as f64 * v[k]) as f32;
                    }
                }
                _ => bail!("unexpected option '{}'", h.text),
            },
            Item::Pos(name) => {
                let mut inp = read_input(name)?;
                let mut c = coef;
                if original {
                    let info = PictureInfo::from_lines(&inp.lines, "pcomb")
                        .with_context(|| format!("input '{name}'"))?;
                    for k in 0..3 {
                        let e = (info.exposure * info.colorcorr[k]) as f32;
                        c[k] /= e;
                    }
                }
                for p in &mut inp.pixels {
                    for k in 0..3 {
                        p[k] *= c[k];
                    }
                }
                if let Some(first) = inputs.first() {
                    if (inp.width, inp.height) != (first.width, first.height) {
                        bail!(
                            "{name}: resolution mismatch ({} x {}, but {} is {} x {})",
                            inp.width,
                            inp.height,
                            first.name,
                            first.width,
                            first.height
                        );
                    }
                }
                inp.original = original;
                inputs.push(inp);
                coef = [1.0; 3];
                original = false;
            }
        }
    }
    let (xmax, ymax) = inputs
        .first()
        .map(|i| (i.width, i.height))
        .unwrap_or((0, 0));
    if let Some(w) = &xword {
        xopt = Some(parse_res(w, "x", &sources, xmax, ymax)?);
    }
    if let Some(w) = &yword {
        yopt = Some(parse_res(w, "y", &sources, xmax, ymax)?);
    }
    let xres = xopt.unwrap_or(xmax);
    let yres = yopt.unwrap_or(ymax);
    if xres == 0 || yres == 0 {
        bail!("illegal output resolution (give -x and -y when there are no inputs)");
    }

    let mut info = fenestra_formats::header::Header::radiance();
    for l in capdate_lines() {
        info.push(l);
    }
    if echo {
        for inp in &inputs {
            info.push(format!("{}:", inp.name));
            for l in &inp.lines {
                if l.starts_with("#?")
                    || l.starts_with("FORMAT=")
                    || l.starts_with("NROWS=")
                    || l.starts_with("NCOLS=")
                    || l.starts_with("BigEndian=")
                    || (inp.original && (l.starts_with("EXPOSURE=") || l.starts_with("COLORCORR=")))
                {
                    continue;
                }
                info.push(format!("\t{l}"));
            }
        }
    }
    info.push(fenestra_cli::command_line(&args));
    if let Some(v) = inputs.iter().find_map(|i| i.view.as_ref()) {
        info.push(v.header_line());
    }
    // one header writer for every matrix and picture (the picture's resolution line is ours)
    let opts = fenestra_formats::WriteOptions {
        format: if float_out {
            fenestra_formats::DataFormat::Float
        } else {
            fenestra_formats::DataFormat::Rgbe
        },
        header: Some(info),
        ..Default::default()
    };
    let mut head = fenestra_formats::matrix::header_bytes(Some(yres), xres, 3, &opts, &[])?;
    if !float_out {
        head.extend_from_slice(
            fenestra_formats::resolution::Resolution::standard(xres, yres)
                .to_string()
                .as_bytes(),
        );
    }

    let data: Arc<Vec<ExprInput>> = Arc::new(
        inputs
            .into_iter()
            .map(|i| ExprInput {
                width: i.width,
                height: i.height,
                pixels: i.pixels,
                // -o undoes the exposure, and le(n) then reports 1 (as Radiance's).
                exposure: if i.original { 1.0 } else { i.exposure },
                aspect: i.aspect,
            })
            .collect(),
    );
    let mut exprs = if sources.is_empty() {
        None
    } else {
        let mut e = Exprs::new(&sources, data.clone(), xres, yres)?;
        // Undefined names surface on the first evaluation: try one pixel before any
        // output is written, so an error leaves no partial picture.
        e.pixel(0, 0, [0.0; 3])?;
        Some(e)
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::with_capacity(1 << 16, stdout.lock());
    out.write_all(&head)?;
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
            for inp in data.iter() {
                let p = inp.pixels[rin * inp.width + xin];
                for k in 0..3 {
                    sum[k] += p[k] as f64;
                }
            }
            if let Some(e) = exprs.as_mut() {
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
            fenestra_formats::picture_rle::write_scanline(&mut out, &scan)?;
        }
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

/// An output resolution: an integer, or an expression over `xmax`/`ymax` and the
/// `-e`/`-f` definitions (as Radiance's pcomb evaluates `-x`/`-y`).
fn parse_res(w: &str, axis: &str, sources: &[Source], xmax: usize, ymax: usize) -> Result<usize> {
    if let Some(v) = fenestra_cli::opts::parse_int(w) {
        if v > 0 {
            return Ok(v as usize);
        }
        bail!("-{axis} {w}: the resolution must be positive");
    }
    let mut p = fenestra_calc::Program::new();
    p.set_number("xmax", xmax as f64);
    p.set_number("ymax", ymax as f64);
    p.set_number("PI", std::f64::consts::PI);
    let resolver = fenestra_cli::raypath::Resolver::from_env();
    for s in sources {
        s.load(&mut p, &resolver)?;
    }
    let e = p
        .add_expr(&format!("-{axis}"), w)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let exe = p.compile().map_err(|e| anyhow::anyhow!("{e}"))?;
    let v = exe
        .eval_expr(&mut exe.state(), e)
        .map_err(|e| anyhow::anyhow!("-{axis} {w}: {e}"))?;
    if (0.5..1e8).contains(&v) {
        Ok((v + 0.5) as usize)
    } else {
        bail!("-{axis} {w}: the resolution evaluates to {v}")
    }
}

/// Reads a picture (any orientation; kept in stored scanline order, as Radiance's pcomb
/// does) or a float/double RGB matrix.
fn read_input(name: &str) -> Result<Input> {
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
