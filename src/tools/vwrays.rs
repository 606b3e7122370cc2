//! vwrays: ray origins and directions for every pixel of a view or picture.

use std::io::{Read, Write};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_cli::opts::{Kind, Opt, Spec};
use fenestra_cli::rays::format_suffix;
use fenestra_formats::picture::{read_header_lines, read_resolution, PictureInfo};
use fenestra_formats::resolution::Resolution;
use fenestra_formats::view::{normaspect, View, FTINY};
use fenestra_formats::view_rays::{pix2rays, put_rays, Fmt, Settings};

use super::view_opts;

fn spec() -> Spec {
    Spec::new(
        "vwrays",
        "Compute the ray through each pixel of a view or picture",
    )
    .usage("[-i -u -f{a|f|d} -c N | -d] [-x X -y Y -pa A -pj J -pd D] { view options | picture [zbuf] }")
    .opts([
        Opt::new("x", Kind::Int, "target x resolution (default 512)"),
        Opt::new("y", Kind::Int, "target y resolution (default 512)"),
        Opt::new(
            "pa",
            Kind::Real,
            "pixel aspect ratio; 0 keeps -x -y (default 1)",
        ),
        Opt::new("pj", Kind::Real, "pixel jitter fraction (default 0)"),
        Opt::new(
            "pd",
            Kind::Real,
            "aperture diameter for depth of field (default 0)",
        ),
        Opt::new(
            "c",
            Kind::Int,
            "repeat each ray N times (pairs with rtcontrib -c N)",
        ),
        Opt::new(
            "f",
            Kind::Attached,
            "output format: a ascii, f float, d double",
        ),
        Opt::new(
            "i",
            Kind::Flag,
            "read pixel positions 'x y' from standard input",
        ),
        Opt::new("u", Kind::Flag, "flush output after each ray"),
        Opt::new(
            "d",
            Kind::Flag,
            "print the resolution (-x X -y Y [-ld+]) and stop",
        ),
    ])
    .opts(view_opts::options())
}

/// Runs vwrays.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let (hits, pos) = spec().parse_apart(&args)?;
    let (mut xres, mut yres, mut pa) = (512i64, 512i64, 1.0f64);
    let mut set = Settings {
        fmt: Fmt::Ascii,
        repeat: 1,
        pj: 0.0,
        pd: 0.0,
        unbuffered: false,
    };
    let (mut from_stdin, mut getdim) = (false, false);
    let mut view = View::default();
    for h in &hits {
        match h.key {
            "x" => xres = h.positive_int(|x| format!("bad x resolution {x}"))?,
            "y" => yres = h.positive_int(|y| format!("bad y resolution {y}"))?,
            "pa" => pa = h.real(),
            "pj" => set.pj = h.real(),
            "pd" => set.pd = h.real(),
            "c" => set.repeat = h.int(),
            "f" => {
                let w = h.word();
                set.fmt = format_suffix(w).with_context(|| {
                    format!("unknown output format '-f{w}' (expected -fa, -ff or -fd)")
                })?;
            }
            "i" => from_stdin = true,
            "u" => set.unbuffered = true,
            "d" => getdim = true,
            _ => {
                if !view_opts::apply(&mut view, h, "vwrays")? {
                    bail!("unexpected option '{}'", h.text);
                }
            }
        }
    }
    if pos.len() > 2 {
        bail!("too many arguments: expected a picture and optionally its z-buffer");
    }
    let mut zbuf: Option<Box<dyn Read>> = None;
    let res = if let Some(pic) = pos.first() {
        let f = std::fs::File::open(pic).with_context(|| format!("cannot open picture '{pic}'"))?;
        let mut r = std::io::BufReader::new(f);
        let lines = read_header_lines(&mut r).with_context(|| format!("picture '{pic}'"))?;
        let info = PictureInfo::from_lines(&lines, "vwrays")
            .with_context(|| format!("picture '{pic}'"))?;
        let Some(v) = info.view else {
            bail!("{pic}: no view in picture");
        };
        view = v;
        let res = read_resolution(&mut r).with_context(|| format!("picture '{pic}'"))?;
        if let Some(z) = pos.get(1) {
            let f =
                std::fs::File::open(z).with_context(|| format!("cannot open z-buffer '{z}'"))?;
            zbuf = Some(Box::new(std::io::BufReader::new(f)));
        }
        Some(res)
    } else {
        None
    };
    view.setup().map_err(|e| anyhow::anyhow!("{e}"))?;
    // the resolution: the picture's, or the one asked for as the view's aspect leaves it
    // (which can be no row or column)
    let (xr, yr) = match &res {
        Some(r) => (r.xr as i64, r.yr as i64),
        None => {
            normaspect(view.aspect(), &mut pa, &mut xres, &mut yres);
            (xres.max(0), yres.max(0))
        }
    };
    if getdim {
        // Radiance prints even an empty resolution (also with -i)
        println!(
            "-x {xr} -y {yr}{}",
            if view.vaft > FTINY { " -ld+" } else { "" }
        );
        return Ok(ExitCode::SUCCESS);
    }
    let res = match res {
        Some(r) => r,
        None if xr > 0 && yr > 0 => Resolution::standard(xr as usize, yr as usize),
        None => {
            // Radiance writes no rays and succeeds; rays for pixel positions read (-i)
            // would be NaN there, so that stays an error
            if from_stdin {
                bail!("view aspect reduces the resolution to {xres} x {yres}");
            }
            fenestra_cli::warn(format!(
                "view aspect reduces the resolution to {xres} x {yres}: no rays"
            ));
            return Ok(ExitCode::SUCCESS);
        }
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::with_capacity(1 << 16, stdout.lock());
    if from_stdin {
        let stdin = std::io::stdin();
        pix2rays(&mut stdin.lock(), &view, &res, &set, &mut out)?;
    } else {
        put_rays(&view, &res, zbuf, &set, &mut out)?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
