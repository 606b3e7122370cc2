//! genklemsamp: Klems-direction ray samples over the window polygons of .rad files (or a
//! parallel-view rectangle), N rays per LBNL/Klems Full patch in patch order, to feed
//! `rtcontrib -c N` (a D matrix: window → sky).

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_calc::format::fmt_g;
use fenestra_cli::opts::{Kind, Opt, Spec};
use fenestra_cli::rays::format_suffix;
use fenestra_contrib::klemsamp::{aperture_from_scene, frame, Aperture, KlemsSampler};
use fenestra_formats::view::View;

use super::view_opts;

fn spec() -> Spec {
    Spec::new(
        "genklemsamp",
        "Rays over a window's area in the directions of the 145 Klems Full patches (N per patch, patch order)",
    )
    .usage("[-c N][-f{a|f|d}][-s seed] [view options] [window.rad ..]")
    .interleaved(true)
    .opts([
        Opt::new("c", Kind::Int, "rays per Klems patch (default 1000)"),
        Opt::new(
            "f",
            Kind::Attached,
            "output format: a ascii (default), f float, d double",
        ),
        Opt::new(
            "s",
            Kind::Int,
            "random seed (fenestra extension; default 0: output is reproducible)",
        ),
    ])
    .opts(
        view_opts::options()
            .into_iter()
            .filter(|o| !matches!(o.key, "vt" | "va" | "vs" | "vl")),
    )
}

/// The `-f` number-stream format (one type for every tool).
type Fmt = fenestra_cli::rays::RayFormat;

/// Runs genklemsamp.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let (hits, files) = spec().parse_apart(&args)?;
    let mut n: i64 = 1000;
    let mut fmt = Fmt::Ascii;
    let mut seed: u64 = 0;
    let mut view = View::default();
    // genklemsamp's defaults: parallel view, fore clip 1e-5 (the offset off the surface)
    view.apply_option(&["-vtl".to_string()])
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    view.apply_option(&["-vo".to_string(), "1e-5".to_string()])
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    for h in &hits {
        match h.key {
            "c" => {
                n = h.positive_int(|n| {
                    format!("-c needs a positive number of rays per patch (got {n})")
                })?;
            }
            "f" => {
                let w = h.word();
                fmt = format_suffix(w).with_context(|| {
                    format!("-f{w}: unknown output format (expected -fa, -ff or -fd)")
                })?;
            }
            "s" => seed = h.int() as u64,
            _ => {
                if !view_opts::apply(&mut view, h, "genklemsamp")? {
                    bail!("unknown option -{}", h.key);
                }
            }
        }
    }
    let n = n as usize;
    let (vd, _, _) = frame(view.vdir, view.vup)?;
    let aperture = if files.is_empty() {
        if view.horiz <= 0.0 || view.vert <= 0.0 {
            bail!("the aperture rectangle needs positive -vh and -vv");
        }
        Aperture::Rect {
            centre: view.vp.into(),
            width: view.horiz,
            height: view.vert,
        }
    } else {
        // as Radiance's genklemsamp: the files' materials do not matter (xform -m void)
        let mut xargs = vec!["xform".to_string(), "-m".to_string(), "void".to_string()];
        xargs.extend(files.iter().cloned());
        let (xo, xfiles) = fenestra_scene::xform::XformOptions::parse(&xargs)?;
        let mut bytes = Vec::new();
        fenestra_scene::xform::xform_files(&xo, &xfiles, &mut bytes)?;
        let text = fenestra_scene::decode_text(bytes);
        let scene = fenestra_scene::parse_str(&text, &files.join(" "))?;
        let (ap, warnings) = aperture_from_scene(&scene, vd)?;
        for w in warnings {
            fenestra_cli::warn(w);
        }
        ap
    };
    let sampler = KlemsSampler::new(view.vdir, view.vup, view.vfore, aperture)?;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::with_capacity(1 << 16, stdout.lock());
    let mut line = String::new();
    for k in 0..sampler.patches() {
        for j in 0..n {
            let (o, d) = sampler.ray(seed, n, k, j);
            let v = [o.x, o.y, o.z, d.x, d.y, d.z];
            match fmt {
                Fmt::Ascii => {
                    line.clear();
                    for (i, x) in v.iter().enumerate() {
                        if i > 0 {
                            line.push('\t');
                        }
                        line.push_str(&fmt_g(*x, 9));
                    }
                    line.push('\n');
                    out.write_all(line.as_bytes())?;
                }
                Fmt::Float => {
                    for x in v {
                        out.write_all(&(x as f32).to_ne_bytes())?;
                    }
                }
                Fmt::Double => {
                    for x in v {
                        out.write_all(&x.to_ne_bytes())?;
                    }
                }
            }
        }
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
