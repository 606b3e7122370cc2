//! rmtxop: matrix format conversion, transposition, scaling, component transforms,
//! products and sums, with Radiance's command line (options apply to the next matrix).

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_cli::opts::parse_real;
use fenestra_dc::ops::{is_xml, Mtx, Source, XmlPart};
use fenestra_dc::ops_errors::Tracked;
use fenestra_dc::rmtxop::{
    apply_own, evaluate, load, load_from, load_tracked, propagate, Input, Op,
};
use fenestra_formats::header::Header;
use fenestra_formats::matrix::{AsciiLayout, DataFormat, MatrixWriter, WriteOptions};

const USAGE: &str =
    "Usage: rmtxop [-v][-f{adfc}][-E errfile][-t][-s sf .. | -c ce ..][-rf|-rb][-R replicas] m1 [.+*] .. > mres";

const HELP: &str = "rmtxop: matrix operations on Radiance matrices, BSDF XML files and pictures

Usage: rmtxop [-v][-f{adfc}][-t][-s sf ..][-c ce ..][-rf|-rb] m1 [.+*] m2 .. > mres

Options before a matrix apply to that matrix only:
  -t           transpose it
  -s sf ..     scale it: one factor, or one per (output) component
  -c ce ..     component transform: N x NCOMP coefficients give N components
               (-c 47.435 119.93 11.635 turns RGB irradiance into illuminance)
  -rf, -rb     for an XML BSDF: front or back reflection instead of transmission
  -R file      its replicas, as rtcontrib -E -Er K writes them (fenestra; with -E)
Global options:
  -E file      write the standard error of every result value here, carried from the
               inputs' replicas through every operation (fenestra)
  -fa -ff -fd -fc   output as ascii, float, double or RGBE (default: the first input's format)
  -v           report each operation on stderr
Operators between matrices (evaluated left to right):
  .            matrix product (the default when no operator is given)
  +            sum
  *            element-wise product
Inputs: a file, '-' for the standard input, '!command' for a command's output, or a .xml BSDF.
The result goes to the standard output with the inputs' headers and this command line.
";

struct Parsed {
    verbose: bool,
    /// `-E`: where the result's standard errors go.
    errors: Option<String>,
    format: Option<DataFormat>,
    inputs: Vec<Input>,
    /// `-t -s -c` after the last matrix: applied to the result.
    trailing: Option<Input>,
}

fn parse(args: &[String]) -> Result<Parsed> {
    let mut verbose = false;
    let mut format = None;
    let mut inputs = Vec::new();
    let mut transpose = false;
    let mut scale: Option<Vec<f64>> = None;
    let mut cmat: Option<Vec<f64>> = None;
    let mut part = XmlPart::Transmission;
    let mut op: Option<Op> = None;
    let mut replicas: Option<String> = None;
    let mut errors: Option<String> = None;
    let mut i = 1;
    // Numbers following -s/-c.
    let numbers = |i: &mut usize, opt: &str| -> Result<Vec<f64>> {
        let mut v = Vec::new();
        while *i < args.len() {
            match parse_real(&args[*i]) {
                Some(x) => v.push(x),
                None => break,
            }
            *i += 1;
        }
        if v.is_empty() {
            bail!("option '{opt}' needs at least one number\n{USAGE}");
        }
        Ok(v)
    };
    while i < args.len() {
        let a = args[i].as_str();
        i += 1;
        match a {
            "--help" | "-help" => {
                print!("{HELP}");
                return Err(fenestra_cli::Exit(0).into());
            }
            "." | "+" | "*" | "/" => {
                if inputs.is_empty() || op.is_some() {
                    bail!("operator '{a}' must stand between two matrices\n{USAGE}");
                }
                op = Some(match a {
                    "." => Op::Product,
                    "+" => Op::Sum,
                    "*" => Op::ElemProduct,
                    _ => Op::ElemQuotient,
                });
            }
            "-v" => verbose = true,
            "-t" => transpose = !transpose,
            "-s" => scale = Some(numbers(&mut i, a)?),
            "-c" => cmat = Some(numbers(&mut i, a)?),
            "-R" | "-E" => {
                let Some(f) = args.get(i) else {
                    bail!("option '{a}' needs a file name\n{USAGE}");
                };
                i += 1;
                if a == "-R" {
                    replicas = Some(f.clone());
                } else {
                    errors = Some(f.clone());
                }
            }
            "-rf" => part = XmlPart::ReflectionFront,
            "-rb" => part = XmlPart::ReflectionBack,
            _ if a.starts_with("-f") && a.len() > 2 => {
                format = Some(match &a[2..] {
                    "a" => DataFormat::Ascii,
                    "f" => DataFormat::Float,
                    "d" => DataFormat::Double,
                    "c" => DataFormat::Rgbe,
                    _ => bail!(
                        "unknown output format '{a}' (expected -fa, -ff, -fd or -fc)\n{USAGE}"
                    ),
                })
            }
            _ if a.len() > 1 && a.starts_with('-') && parse_real(a).is_none() => {
                bail!("unknown option '{a}'\n{USAGE}")
            }
            _ => {
                let this_op = if inputs.is_empty() {
                    Op::Product
                } else {
                    op.unwrap_or(Op::Product)
                };
                inputs.push(Input {
                    name: a.to_string(),
                    op: this_op,
                    transpose,
                    scale: scale.take(),
                    cmat: cmat.take(),
                    part,
                    replicas: replicas.take(),
                });
                transpose = false;
                part = XmlPart::Transmission;
                op = None;
            }
        }
    }
    if inputs.is_empty() {
        bail!("no input matrix\n{USAGE}");
    }
    if op.is_some() {
        bail!("missing matrix argument after the last operator\n{USAGE}");
    }
    if replicas.is_some() {
        bail!(
            "-R after the last matrix: it names the replicas of the matrix that follows\n{USAGE}"
        );
    }
    // -t, -s and -c after the last matrix apply to the result (Radiance's trailing ops)
    let trailing = (transpose || scale.is_some() || cmat.is_some()).then(|| Input {
        name: "trailing_ops".into(),
        op: Op::Product,
        transpose,
        scale,
        cmat,
        part: XmlPart::Transmission,
        replicas: None,
    });
    if errors.is_some() && inputs.iter().any(|i| i.op == Op::ElemQuotient) {
        bail!("-E carries errors through '.', '+' and '*', not '/'\n{USAGE}");
    }
    let with_replicas = inputs.iter().any(|i| i.replicas.is_some());
    if errors.is_some() != with_replicas {
        bail!(
            "-E (the result's standard errors) and -R (an input's replicas) go together\n{USAGE}"
        );
    }
    Ok(Parsed {
        verbose,
        errors,
        format,
        inputs,
        trailing,
    })
}

/// Matrices larger than this many values (1 GB in single precision) given alone and not
/// transposed are converted row by row instead of being held in memory
/// (`FENESTRA_RMTXOP_STREAM=values` changes the limit, for tests).
fn stream_values() -> u128 {
    std::env::var("FENESTRA_RMTXOP_STREAM")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1 << 28)
}

/// Converts a single large input row by row (its size was checked against the header
/// first for files; an error later in the data leaves a partial result on the output).
fn stream(p: &Parsed, mut src: Source, args: &[String]) -> Result<ExitCode> {
    let inp = &p.inputs[0];
    let apply = |m: &mut Mtx| -> Result<()> {
        if inp.cmat.is_some() || inp.scale.is_some() {
            m.transform(inp.cmat.as_deref(), inp.scale.as_deref())
                .with_context(|| inp.name.clone())?;
        }
        Ok(())
    };
    let mut shape = src.shape();
    apply(&mut shape)?;
    let nrows = src
        .reader
        .info
        .nrows
        .context("row count needed to stream")?;
    if p.verbose {
        eprintln!("rmtxop: converting {} row by row ({nrows} rows)", inp.name);
    }
    let opts = output_options(p, &shape, args)?;
    let stdout = std::io::stdout();
    let lock = std::io::BufWriter::with_capacity(1 << 16, stdout.lock());
    let mut w = MatrixWriter::new(lock, Some(nrows), shape.ncols, shape.ncomp, &opts)?;
    let mut one = src.shape();
    one.nrows = 1;
    one.info.clear();
    let mut raw = vec![0.0f32; src.reader.info.row_len()];
    let mut out = Vec::new();
    let mut n = 0;
    while src.read_row(&mut raw)? {
        one.ncomp = src.reader.info.ncomp;
        one.data.clear();
        one.data.extend_from_slice(&raw);
        apply(&mut one)?;
        out.clear();
        out.extend(one.data.iter().map(|&v| v as f64));
        w.write_row(&out)?;
        n += 1;
    }
    src.finish(n)?;
    let mut o = w.finish()?;
    o.flush()?;
    Ok(ExitCode::SUCCESS)
}

/// Runs rmtxop.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let p = parse(&args)?;
    if let Some(e) = &p.errors {
        // every input loaded once (a coloured XML's dither draws from one sequence), the
        // result from the values as without -E, the errors from the replicas
        let mut tracked = Vec::with_capacity(p.inputs.len());
        for inp in &p.inputs {
            tracked.push(load_tracked(inp, p.verbose)?);
        }
        let mut m = evaluate(
            &p.inputs,
            tracked.iter().map(|t| t.value.clone()).collect(),
            p.verbose,
        )?;
        if let Some(t) = &p.trailing {
            apply_own(t, &mut m)?;
        }
        write_errors(&p, e, tracked, &args)?;
        return write_result(&p, m, &args);
    }
    if p.inputs.len() == 1
        && p.trailing.is_none()
        && !p.inputs[0].transpose
        && !is_xml(&p.inputs[0].name)
    {
        let src = Source::open(&p.inputs[0].name)?;
        let values = src
            .reader
            .info
            .nrows
            .map(|n| n as u128 * src.reader.info.row_len() as u128);
        if values.is_some_and(|v| v > stream_values()) {
            return stream(&p, src, &args);
        }
        let m = load_from(&p.inputs[0], src, p.verbose)?;
        return write_result(&p, m, &args);
    }
    let mut mats = Vec::with_capacity(p.inputs.len());
    for inp in &p.inputs {
        mats.push(load(inp, p.verbose)?);
    }
    let mut m = evaluate(&p.inputs, mats, p.verbose)?;
    if let Some(t) = &p.trailing {
        apply_own(t, &mut m)?;
    }
    write_result(&p, m, &args)
}

/// rmtxop's `-E`: the result's standard errors (carried from the inputs' replicas through
/// every operation, [`propagate`]) written to `err` (the result itself is computed as
/// without `-E`, so its bytes do not change).
fn write_errors(p: &Parsed, err: &str, tracked: Vec<Tracked>, args: &[String]) -> Result<()> {
    let se = propagate(&p.inputs, tracked, p.trailing.as_ref())?;
    let mut opts = output_options(p, &se, args)?;
    if opts.format == DataFormat::Rgbe {
        opts.format = DataFormat::Ascii;
    }
    opts.align_from = Default::default();
    if let Some(h) = opts.header.as_mut() {
        h.push("CONTENTS= Monte Carlo standard error (1 sigma) of each value, from the inputs' replicas");
    }
    let file = fenestra_cli::output::AtomicFile::create(err)?;
    let mut w = MatrixWriter::new(file, Some(se.nrows), se.ncols, se.ncomp, &opts)?;
    let mut row = vec![0.0f64; se.row_len()];
    for r in 0..se.nrows {
        for (d, &s) in row.iter_mut().zip(se.row(r)) {
            *d = f64::from(s);
        }
        w.write_row(&row)?;
    }
    w.finish()?.commit()?;
    Ok(())
}

/// The output header and format for a result shaped like `m`.
fn output_options(p: &Parsed, m: &Mtx, args: &[String]) -> Result<WriteOptions> {
    let format = p.format.unwrap_or(m.format);
    if format.is_picture() && m.ncomp != 3 && m.ncomp != 1 {
        bail!(
            "cannot write a matrix with {} components as an RGBE picture (-fc needs 1 or 3)",
            m.ncomp
        );
    }
    let mut h = Header::radiance();
    h.push(fenestra_cli::command_line(args));
    for l in &m.info {
        h.push(l.clone());
    }
    Ok(WriteOptions {
        format,
        ascii: AsciiLayout::Rmtxop,
        header: Some(h),
        align_from: fenestra_cli::output::stdout_file_offset(),
        ..Default::default()
    })
}

/// Writes a result held in memory.
fn write_result(p: &Parsed, m: Mtx, args: &[String]) -> Result<ExitCode> {
    let opts = output_options(p, &m, args)?;
    // The whole result is in memory: nothing is written unless every input was read.
    let stdout = std::io::stdout();
    let lock = std::io::BufWriter::with_capacity(1 << 16, stdout.lock());
    let mut w = MatrixWriter::new(lock, Some(m.nrows), m.ncols, m.ncomp, &opts)?;
    let mut row = vec![0.0f64; m.row_len()];
    for r in 0..m.nrows {
        for (d, &s) in row.iter_mut().zip(m.row(r)) {
            *d = s as f64;
        }
        w.write_row(&row)?;
    }
    let mut out = w.finish()?;
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
