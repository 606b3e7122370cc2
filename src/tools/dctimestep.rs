//! dctimestep: daylight-coefficient time stepping, `V·T·D·s` or `DC·s`, with the
//! sky given as a vector or a matrix of time steps (see docs/tools/dctimestep.md).

use fenestra_cli::raypath::Resolver;
use std::process::ExitCode;

use anyhow::{bail, Result};
use fenestra_cli::opts::{Kind, Opt, Spec};
use fenestra_dc::errors::Uncertainty;
use fenestra_dc::steps::{load_td, matrix_form, picture_form, read_sky, StepOptions};
use fenestra_formats::matrix::{DataFormat, MatrixReader};

fn spec() -> Spec {
    Spec::new(
        "dctimestep",
        "Multiply daylight-coefficient matrices by sky vectors or sky matrices (time steps)",
    )
    .usage("[-n nsteps][-o ospec][-i{f|d}][-o{f|d|c}][-h][-x xr][-y yr] { DCspec | Vspec Tbsdf Dmat } [skyf]")
    .opts([
        Opt::new(
            "n",
            Kind::Int,
            "number of time steps; the sky is then read without a header",
        ),
        Opt::new(
            "o",
            Kind::Word,
            "output file; a %d field writes one file per time step",
        ),
        Opt::new("oa", Kind::Flag, "ascii output (default)"),
        Opt::new("of", Kind::Flag, "float output"),
        Opt::new("od", Kind::Flag, "double output"),
        Opt::new("oc", Kind::Flag, "RGBE picture output"),
        Opt::new("ia", Kind::Flag, "sky input is ascii"),
        Opt::new("if", Kind::Flag, "sky input is float"),
        Opt::new("id", Kind::Flag, "sky input is double"),
        Opt::new("h", Kind::Flag, "toggle the output header"),
        Opt::new(
            "Ev",
            Kind::Word,
            "standard errors of V (or of DC in the two-phase form), as rtcontrib -E writes them (fenestra)",
        ),
        Opt::new(
            "Ed",
            Kind::Word,
            "standard errors of D, as rtcontrib -E writes them (fenestra)",
        ),
        Opt::new(
            "Rv",
            Kind::Word,
            "replicas of V (or of DC), as rtcontrib -E -Er K writes them: errors with every covariance (fenestra)",
        ),
        Opt::new(
            "Rd",
            Kind::Word,
            "replicas of D, as rtcontrib -E -Er K writes them (fenestra)",
        ),
        Opt::new(
            "Eo",
            Kind::Word,
            "write the standard error of every result value here (needs -Ev/-Rv and/or -Ed/-Rd; fenestra)",
        ),
        Opt::new("x", Kind::Int, "output x resolution (reshape)"),
        Opt::new("y", Kind::Int, "output y resolution (reshape)"),
    ])
}

/// Runs dctimestep.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let (hits, pos) = spec().parse_apart(&args)?;
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
    let mut oc_given = false;
    let (mut ev, mut ed, mut eo): (Option<String>, Option<String>, Option<String>) =
        (None, None, None);
    let (mut rv, mut rd): (Option<String>, Option<String>) = (None, None);
    for h in &hits {
        match h.key {
            "n" => {
                let n = h.positive_int(|n| {
                    format!("-n {n}: the number of time steps must be positive")
                })?;
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
            "Ev" => ev = Some(h.word().to_string()),
            "Ed" => ed = Some(h.word().to_string()),
            "Eo" => eo = Some(h.word().to_string()),
            "Rv" => rv = Some(h.word().to_string()),
            "Rd" => rd = Some(h.word().to_string()),
            "x" | "y" => {
                let v =
                    h.positive_int(|v| format!("-{} {v}: resolution must be positive", h.key))?;
                if h.key == "x" {
                    o.xres = Some(v as usize);
                } else {
                    o.yres = Some(v as usize);
                }
            }
            _ => bail!("unexpected option '{}'", h.text),
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
        Some((t, d)) => Some(load_td(t, d, &Resolver::from_env())?),
        None => None,
    };
    // The two-phase form learns the sky's size from the left matrix: open it once here
    // and keep the reader (a `-` or `!command` input can be read only once).
    let mut v_reader = None;
    let sky_rows = match &td {
        Some((td, _)) => td.cols,
        None if picture => 0, // learnt from the sky itself
        None => {
            let r = MatrixReader::open(&vspec)?.report_to(fenestra_cli::warn_note);
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
    if eo.is_none() && (ev.is_some() || ed.is_some() || rv.is_some() || rd.is_some()) {
        bail!("-Ev/-Ed/-Rv/-Rd describe the inputs' errors: give -Eo for the result's");
    }
    if ev.is_some() && rv.is_some() {
        bail!("-Ev and -Rv both describe V's errors: give one (-Rv, the replicas, is exact)");
    }
    if ed.is_some() && rd.is_some() {
        bail!("-Ed and -Rd both describe D's errors: give one (-Rd, the replicas, is exact)");
    }
    if let Some(out) = &eo {
        if ev.is_none() && ed.is_none() && rv.is_none() && rd.is_none() {
            bail!("-Eo needs the inputs' errors (-Ev or -Rv for V or DC, -Ed or -Rd for D)");
        }
        if ["-", ""].contains(&vspec.as_str()) || vspec.starts_with('!') {
            bail!("-Eo needs V (or DC) as a file: it is read twice");
        }
        let ins = ErrorInputs {
            ev: ev.as_deref(),
            ed: ed.as_deref(),
            rv: rv.as_deref(),
            rd: rd.as_deref(),
        };
        write_errors(out, &vspec, td_specs.as_ref(), &ins, &sky, &o)?;
    }
    matrix_form(v_reader, &vspec, td.as_ref(), td_specs.as_ref(), &sky, &o)?;
    Ok(ExitCode::SUCCESS)
}

/// A matrix file as a planar matrix.
fn planar(name: &str) -> Result<fenestra_dc::timestep::Planar> {
    let m = fenestra_formats::matrix::Matrix::read_reporting(name, fenestra_cli::warn_note)?;
    fenestra_dc::timestep::Planar::from_interleaved(m.nrows, m.ncols, m.ncomp, &m.data)
        .map_err(|e| anyhow::anyhow!("{name}: {e:#}"))
}

/// The files that describe V's and D's errors (`-Ev -Ed -Rv -Rd`).
struct ErrorInputs<'a> {
    ev: Option<&'a str>,
    ed: Option<&'a str>,
    rv: Option<&'a str>,
    rd: Option<&'a str>,
}

/// A matrix's errors from its standard-error file or its replica file.
fn uncertainty(se: Option<&str>, rep: Option<&str>) -> Result<Uncertainty> {
    if let Some(name) = rep {
        let (m, k) = fenestra_dc::replicas::read(name)?;
        let all =
            fenestra_dc::timestep::Planar::from_interleaved(m.nrows, m.ncols, m.ncomp, &m.data)
                .map_err(|e| anyhow::anyhow!("{name}: {e:#}"))?;
        return Uncertainty::replicas(&all, k, name);
    }
    Ok(match se {
        Some(name) => Uncertainty::Independent(planar(name)?),
        None => Uncertainty::Exact,
    })
}

/// The standard errors of the result (fenestra's `-Eo`), same shape as the result.
fn write_errors(
    out: &str,
    vspec: &str,
    td: Option<&(String, String)>,
    ins: &ErrorInputs,
    sky: &fenestra_dc::timestep::PackedSky,
    o: &StepOptions,
) -> Result<()> {
    use fenestra_formats::matrix::{MatrixWriter, WriteOptions};
    let v = planar(vspec)?;
    let uv = uncertainty(ins.ev, ins.rv)?;
    let e = match td {
        Some((tname, dname)) => {
            let t = fenestra_dc::steps::load_t(tname, &Resolver::from_env())?;
            let d = planar(dname)?;
            let ud = uncertainty(ins.ed, ins.rd)?;
            fenestra_dc::errors::three_phase(&v, &uv, &t, &d, &ud, sky)?
        }
        None => {
            if ins.ed.is_some() || ins.rd.is_some() {
                bail!(
                    "-Ed/-Rd: the two-phase form DC·s has no D (give DC's errors with -Ev or -Rv)"
                );
            }
            fenestra_dc::errors::two_phase(&v, &uv, sky)?
        }
    };
    let model = match (
        ins.rv.is_some() || ins.rd.is_some(),
        ins.ev.is_some() || ins.ed.is_some(),
    ) {
        (true, false) => "from replicas",
        (true, true) => "from replicas and independent elements",
        _ => "independent V and D elements: an upper bound",
    };
    let format = match o.out_fmt {
        DataFormat::Float | DataFormat::Double => o.out_fmt,
        _ => DataFormat::Ascii,
    };
    let mut wo = WriteOptions::with_command(format, &o.command);
    if let Some(h) = wo.header.as_mut() {
        h.push(format!(
            "CONTENTS= Monte Carlo standard error (1 sigma) of each value ({model})"
        ));
    }
    let file = fenestra_cli::output::AtomicFile::create(out)?;
    let mut w = MatrixWriter::new(file, Some(e.rows), e.cols, 3, &wo)?;
    let mut row = vec![0.0; e.cols * 3];
    for r in 0..e.rows {
        for k in 0..e.cols {
            for c in 0..3 {
                row[k * 3 + c] = e.get(c, r, k);
            }
        }
        w.write_row(&row)?;
    }
    w.finish()?.commit()?;
    Ok(())
}
