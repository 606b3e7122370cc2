//! dctimestep: daylight-coefficient time stepping, `V·T·D·s` or `DC·s`, with the
//! sky given as a vector or a matrix of time steps (see docs/tools/dctimestep.md).

use std::process::ExitCode;

use anyhow::{bail, Result};
use fenestra_cli::opts::{Item, Kind, Opt, Spec};
use fenestra_dc::steps::{load_td, matrix_form, picture_form, read_sky, StepOptions};
use fenestra_formats::matrix::{DataFormat, MatrixReader};

fn spec() -> Spec {
    Spec::new(
        "dctimestep",
        "Multiply daylight-coefficient matrices by sky vectors or sky matrices (time steps)",
    )
    .usage("[-n nsteps][-o ospec][-i{f|d}][-o{f|d|c}][-h][-x xr][-y yr] { DCspec | Vspec Tbsdf Dmat } [skyf]")
    .opt(Opt::new(
        "n",
        Kind::Int,
        "number of time steps; the sky is then read without a header",
    ))
    .opt(Opt::new(
        "o",
        Kind::Word,
        "output file; a %d field writes one file per time step",
    ))
    .opt(Opt::new("oa", Kind::Flag, "ascii output (default)"))
    .opt(Opt::new("of", Kind::Flag, "float output"))
    .opt(Opt::new("od", Kind::Flag, "double output"))
    .opt(Opt::new("oc", Kind::Flag, "RGBE picture output"))
    .opt(Opt::new("ia", Kind::Flag, "sky input is ascii"))
    .opt(Opt::new("if", Kind::Flag, "sky input is float"))
    .opt(Opt::new("id", Kind::Flag, "sky input is double"))
    .opt(Opt::new("h", Kind::Flag, "toggle the output header"))
    .opt(Opt::new("x", Kind::Int, "output x resolution (reshape)"))
    .opt(Opt::new("y", Kind::Int, "output y resolution (reshape)"))
}

/// Runs dctimestep.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let items = spec().parse(&args)?;
    let mut o = StepOptions {
        nsteps: None,
        in_fmt: None,
        out_fmt: DataFormat::Ascii,
        out_spec: None,
        xres: None,
        yres: None,
        header: true,
        command: fenestra_cli::command_line(&args),
    };
    let mut pos = Vec::new();
    let mut oc_given = false;
    for it in items {
        match it {
            Item::Pos(p) => pos.push(p),
            Item::Opt(h) => match h.key {
                "n" => {
                    let n = h.int();
                    if n <= 0 {
                        bail!("-n {n}: the number of time steps must be positive");
                    }
                    o.nsteps = Some(n as usize);
                }
                "o" => o.out_spec = Some(h.word().to_string()),
                "oa" => o.out_fmt = DataFormat::Ascii,
                "of" => o.out_fmt = DataFormat::Float,
                "od" => o.out_fmt = DataFormat::Double,
                "oc" => {
                    o.out_fmt = DataFormat::Rgbe;
                    oc_given = true;
                }
                "ia" => o.in_fmt = Some(DataFormat::Ascii),
                "if" => o.in_fmt = Some(DataFormat::Float),
                "id" => o.in_fmt = Some(DataFormat::Double),
                "h" => o.header = !o.header,
                "x" | "y" => {
                    let v = h.int();
                    if v <= 0 {
                        bail!("-{} {v}: resolution must be positive", h.key);
                    }
                    if h.key == "x" {
                        o.xres = Some(v as usize);
                    } else {
                        o.yres = Some(v as usize);
                    }
                }
                _ => bail!("unexpected option '{}'", h.text),
            },
        }
    }
    if pos.is_empty() || pos.len() > 4 {
        bail!(
            "usage: dctimestep [options] {{ DCspec | Vspec Tbsdf Dmat }} [skyf] \
             (1 to 4 file arguments, {} given; see --help)",
            pos.len()
        );
    }
    let (vspec, td_specs, sky_spec) = match pos.len() {
        1 => (pos[0].clone(), None, "-".to_string()),
        2 => (pos[0].clone(), None, pos[1].clone()),
        3 => (
            pos[0].clone(),
            Some((pos[1].clone(), pos[2].clone())),
            "-".to_string(),
        ),
        _ => (
            pos[0].clone(),
            Some((pos[1].clone(), pos[2].clone())),
            pos[3].clone(),
        ),
    };
    let picture = fenestra_cli::printf::has_int_field(&vspec);

    // T·D (None for the two-phase form, whose left matrix multiplies the sky directly).
    let td = match &td_specs {
        Some((t, d)) => Some(load_td(t, d)?),
        None => None,
    };
    // The two-phase form learns the sky's size from the left matrix: open it once here
    // and keep the reader (a `-` or `!command` input can be read only once).
    let mut v_reader = None;
    let sky_rows = match &td {
        Some((td, _)) => td.cols,
        None if picture => 0, // learnt from the sky itself
        None => {
            let r = MatrixReader::open(&vspec)?;
            let n = r.info.ncols;
            v_reader = Some(r);
            n
        }
    };
    let sky = read_sky(
        &sky_spec,
        sky_rows,
        &o,
        td_specs.as_ref().map(|s| s.1.as_str()),
        &vspec,
    )?;

    if picture {
        if !oc_given {
            fenestra_cli::warn("changing output type to -oc (a picture V gives pictures, written as RGBE; -oc says so)");
        }
        o.out_fmt = DataFormat::Rgbe;
        // Radiance writes picture headers whatever -h says.
        o.header = true;
        return picture_form(&vspec, td.map(|t| t.0), &sky, &o);
    }
    let td = td.map(|t| t.0);
    matrix_form(v_reader, &vspec, td.as_ref(), td_specs.as_ref(), &sky, &o)?;
    Ok(ExitCode::SUCCESS)
}
