//! pcomb: linear combinations of Radiance pictures (and float RGB matrices).

// Per-channel colour arithmetic reads most clearly with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_cli::opts::{Item, Kind, Opt, Spec};
use fenestra_formats::picture::{capdate_lines, PictureInfo};

use fenestra_records::pcomb::combine::{write_pixels, Output};
use fenestra_records::pcomb::expr::{ExprInput, Exprs};
use fenestra_records::pcomb::input::{read_input, Input};
use fenestra_trace::options::CalSource as Source;
use std::sync::Arc;

fn spec() -> Spec {
    Spec::new(
        "pcomb",
        "Combine Radiance pictures (sum, scale, colour) to the standard output",
    )
    .usage("[-h][-w][-ff][-x xres][-y yres][-e expr][-f file] [[-o][-s factor][-c r g b] input ..]")
    .interleaved(true)
    .opts([
        Opt::new(
            "h",
            Kind::Flag,
            "leave the inputs' headers out of the output header",
        ),
        Opt::new("w", Kind::Flag, "suppress warnings"),
        Opt::new(
            "ff",
            Kind::Flag,
            "write a float RGB matrix (no clipping of negatives)",
        ),
        Opt::new(
            "x",
            Kind::Word,
            "output x resolution (default: the inputs')",
        ),
        Opt::new(
            "y",
            Kind::Word,
            "output y resolution (default: the inputs')",
        ),
        Opt::new(
            "e",
            Kind::Word,
            "expression defining ro go bo (or lo) from ri(n) gi(n) bi(n) li(n), x, y …",
        ),
        Opt::new(
            "f",
            Kind::Word,
            "file of expressions (found through RAYPATH)",
        ),
        Opt::new(
            "o",
            Kind::Flag,
            "use original values of the next input (undo its exposure)",
        ),
        Opt::new("s", Kind::Real, "scale the next input by a factor"),
        Opt::new(
            "c",
            Kind::Words(3),
            "scale the next input's r g b by these factors",
        ),
    ])
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
        let load = |p: &mut fenestra_calc::Program| -> Result<()> {
            let resolver = fenestra_cli::raypath::Resolver::from_env();
            for s in &sources {
                s.load(p, &resolver)?;
            }
            Ok(())
        };
        let mut e = Exprs::new(&load, data.clone(), xres, yres)?;
        // Undefined names surface on the first evaluation: try one pixel before any
        // output is written, so an error leaves no partial picture.
        e.pixel(0, 0, [0.0; 3])?;
        Some(e)
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::with_capacity(1 << 16, stdout.lock());
    out.write_all(&head)?;
    let o = Output {
        xres,
        yres,
        float_out,
    };
    write_pixels(&mut out, &data, exprs.as_mut(), (xmax, ymax), o)?;
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
