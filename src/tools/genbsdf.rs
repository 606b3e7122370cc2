//! genBSDF: a device's BSDF from its geometry (Klems full basis), in one process over the
//! library's tracer (fenestra-genbsdf). Command line as Radiance's genBSDF.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_genbsdf::{characterise_with, Options};

const USAGE: &str = "[-q][-v][-k kf|kh|kq][-checkpoint file][-E errors.xml][{+|-}C][-t3 L | -t4 L [-t pct][{+|-}a]][-c Nsamp][-n Nproc][-r 'render opts'][{+|-}f[orward]][{+|-}b[ackward]][{+|-}mgf][{+|-}geom unit][-dim x0 x1 y0 y1 z0 z1] [input ..]";

/// Geometry units genBSDF accepts, with their length in metres.
const UNITS: [(&str, f64); 5] = [
    ("meter", 1.0),
    ("foot", 0.3048),
    ("inch", 0.0254),
    ("centimeter", 0.01),
    ("millimeter", 0.001),
];

/// Runs genBSDF.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    if fenestra_cli::help_asked(&args, USAGE, "Characterises the device geometry (X = width, Y = up, +Z into the room, device at Z <= 0) as a Klems BSDF, or with -t4 L an anisotropic tensor tree (XML on standard output).\nOptions:\n  -c N             samples per incident direction (default 2000; the sample grid rounds it)\n  -k kf|kh|kq      Klems basis: full (default, 145 patches), half (77) or quarter (41)\n  -n N             threads\n  -r 'opts'        render options after genBSDF's -ab 5 -ad 700 -lw 3e-6\n  +f / -f          light from outside (Transmission/Reflection Front) on / off (default off)\n  +b / -b          light from the room (Back) on / off (default on)\n  +C / -C          colour: CIE-X and CIE-Z blocks (trees: CIE-u, CIE-v)\n  -t4 L / -t3 L    anisotropic / isotropic tensor tree, 2^L cells per dimension (2..7)\n  -t pct           tree culling percentile (default 90);  +a / -a  reciprocity averaging\n  +mgf             the inputs are MGF\n  +geom unit       embed the geometry as MGF (default +geom meter); -geom unit: do not; unit of the input\n  -dim x0 x1 y0 y1 z0 z1   the device's extent instead of its bounding box\n  -E file          each element's standard error as a BSDF XML of the same layout (Klems or tree)\n  -checkpoint file resumable run: the same command continues a killed one\n  -q               no summary;  -v  effects, rays by kind, time\nFull documentation: fenestra doc genBSDF (docs/tools/genBSDF.md in the source).") {
        return Ok(ExitCode::SUCCESS);
    }
    let mut o = Options::genbsdf();
    let mut nproc = 1usize;
    let mut mgf = false;
    let mut quiet = false;
    let mut verbose = false;
    let started = std::time::Instant::now();
    let mut error_file: Option<String> = None;
    let mut unit = 1.0;
    // +geom unit (Radiance's default, in metres): the geometry embedded as MGF; -geom: not
    let (mut geout, mut unit_name) = (true, "meter".to_string());
    let mut render: Vec<String> = Vec::new();
    let mut tree: Option<(usize, u32)> = None;
    let mut pctcull = 90.0;
    let mut recip = true;
    let mut recip_given = false;
    let mut files: Vec<String> = Vec::new();
    let mut i = 1;
    let value = |i: usize| -> Result<&String> {
        args.get(i)
            .with_context(|| format!("option {} needs a value", args[i - 1]))
    };
    let number = |i: usize| -> Result<f64> {
        let w = value(i)?;
        fenestra_cli::opts::parse_real(w)
            .with_context(|| format!("option {}: '{w}' is not a number", args[i - 1]))
    };
    while i < args.len() {
        let a = args[i].as_str();
        let plus = a.starts_with('+');
        match a {
            "-v" => verbose = true,
            "-k" => {
                o.basis = match value(i + 1)?.as_str() {
                    "kf" => fenestra_bsdf::KlemsBasis::full(),
                    "kh" => fenestra_bsdf::KlemsBasis::half(),
                    "kq" => fenestra_bsdf::KlemsBasis::quarter(),
                    b => bail!("-k {b}: a Klems basis kf, kh or kq expected"),
                };
                i += 1;
            }
            "-checkpoint" => {
                o.checkpoint = Some(value(i + 1)?.into());
                i += 1;
            }
            "-c" => {
                let n = number(i + 1)?;
                if n.is_nan() || n < 1.0 {
                    bail!("-c {n}: the number of samples must be at least 1");
                }
                o.samples = n as usize;
                i += 1;
            }
            "-n" => {
                nproc = fenestra_cli::threads::worker_count(number(i + 1)?)?;
                i += 1;
            }
            "-r" => {
                render.extend(fenestra_cli::expand::split_words(value(i + 1)?)?);
                i += 1;
            }
            "+f" | "-f" | "+forward" | "-forward" => o.forward = plus,
            "+b" | "-b" | "+backward" | "-backward" => o.backward = plus,
            "+mgf" | "-mgf" => mgf = plus,
            "+geom" | "-geom" => {
                let u = value(i + 1)?;
                let (name, m) = UNITS
                    .iter()
                    .find(|(n, _)| n.eq_ignore_ascii_case(u))
                    .with_context(|| format!("Illegal geometry unit '{u}' (meter, foot, inch, centimeter or millimeter)"))?;
                unit = *m;
                unit_name = name.to_string();
                geout = plus;
                i += 1;
            }
            "-dim" => {
                let mut d = [0.0; 6];
                for (k, v) in d.iter_mut().enumerate() {
                    *v = number(i + 1 + k)?;
                }
                o.dim = Some(d);
                i += 6;
            }
            "+C" | "-C" => o.colour = plus,
            "-t4" | "-t3" => {
                let l = number(i + 1)?;
                if !(2.0..=7.0).contains(&l) || l.fract() != 0.0 {
                    bail!("{a} {l}: the tree resolution must be a whole number from 2 to 7 (2^L cells per dimension)");
                }
                tree = Some((if a == "-t4" { 4 } else { 3 }, l as u32));
                i += 1;
            }
            "-t" => {
                let p = number(i + 1)?;
                if !(0.0..100.0).contains(&p) {
                    bail!("-t {p}: the culling percentile must be at least 0 and below 100");
                }
                pctcull = p;
                i += 1;
            }
            "+a" | "-a" => {
                recip = plus;
                recip_given = true;
            }
            "-recover" => bail!(
                "-recover: fenestra's genBSDF runs in one process and keeps no temporary directory"
            ),
            "-W" => {}
            "-q" => quiet = true,
            "-E" => {
                error_file = Some(value(i + 1)?.clone());
                o.errors = true;
                i += 1;
            }
            "-s" => i += 1,
            _ if a.starts_with('-') && a.len() > 1 || plus => {
                bail!(
                    "unknown option '{a}'\nusage: {} {USAGE}",
                    fenestra_cli::prog()
                )
            }
            _ => files.push(a.to_string()),
        }
        i += 1;
    }
    // render options after genBSDF's own (later ones win)
    let mut k = 0;
    while k < render.len() {
        let name = render[k].trim_start_matches('-').to_string();
        if fenestra_trace::TraceOptions::is_number_option(&name) {
            let v = render
                .get(k + 1)
                .and_then(|w| fenestra_cli::opts::parse_real(w))
                .with_context(|| format!("-r: option -{name} needs a number"))?;
            o.trace.set_number(&name, v);
            k += 2;
        } else {
            bail!(
                "-r: option '{}' is not supported by fenestra's genBSDF",
                render[k]
            );
        }
    }
    if files.is_empty() {
        files.push("-".into());
    }
    let mut parser = fenestra_scene::Parser::new();
    for f in &files {
        if mgf && f != "-" {
            let text = std::fs::read(f).with_context(|| format!("cannot open '{f}'"))?;
            parser.add_mgf(&fenestra_scene::decode_text(text), f)?;
        } else {
            parser.add_path(f)?;
        }
    }
    let scene = parser.finish();
    if !scene
        .prims
        .iter()
        .any(|p| p.modifier.is_some() && fenestra_trace::surface::is_geometry(&p.ptype))
    {
        bail!("no device geometry in the input");
    }
    let pool = fenestra_cli::threads::pool(nproc)?;
    if tree.is_some() && !std::ptr::eq(o.basis, fenestra_bsdf::KlemsBasis::full()) {
        bail!("-k: a Klems basis, not with tensor trees (-t3, -t4)");
    }

    if let Some((rank, l)) = tree {
        // the default reciprocity averaging needs the whole grid, which -t4 7 does not hold
        if fenestra_genbsdf::tree4::streams(rank, l) && recip && !recip_given {
            fenestra_cli::warn(format!(
                "-t4 {l}: reflection not averaged with its reciprocal (+a needs the whole grid in memory)"
            ));
            recip = false;
        }
    }
    let sides = u64::from(o.forward) + u64::from(o.backward);
    let ndir = match tree {
        // a streamed reduction traces every incident cell twice
        Some((4, l)) => {
            (1u64 << (2 * l))
                * sides
                * if fenestra_genbsdf::tree4::streams(4, l) {
                    2
                } else {
                    1
                }
        }
        Some((_, l)) => (1u64 << (l - 1)) * sides,
        None => fenestra_genbsdf::directions(&o),
    };
    let progress = fenestra_cli::progress::Progress::new(ndir, "genBSDF incident directions");
    let got = match tree {
        Some((rank, l)) => fenestra_genbsdf::tree4::characterise(
            &scene,
            &o,
            rank,
            l,
            pctcull,
            recip,
            &pool,
            &|| progress.inc(1),
        )?,
        None => characterise_with(&scene, &o, &pool, &|| progress.inc(1))?,
    };
    progress.finish();
    for w in &got.warnings {
        fenestra_cli::warn(w);
    }
    // sizes in the chosen unit's metres
    let in_metres = |mut b: fenestra_bsdf::Bsdf| {
        b.width = b.width.map(|v| v * unit);
        b.height = b.height.map(|v| v * unit);
        b.thickness = b.thickness.map(|v| v * unit);
        b
    };
    let mut bsdf = in_metres(got.bsdf);
    if geout {
        bsdf.geometry = Some(fenestra_bsdf::Geometry {
            unit: unit_name.clone(),
            mgf: format!(
                "\n{}",
                fenestra_genbsdf::geometry::device_mgf(&scene, &got.dim)
            ),
        });
    }
    let comment = format!(
        "Created by: fenestra genBSDF {} ({} samples per direction)",
        fenestra_cli::command_line(&args),
        got.samples
    );
    let xml = fenestra_bsdf::write::klems_xml(&bsdf, Some(&comment))
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    if let (Some(path), Some(errors)) = (&error_file, got.errors) {
        let text = fenestra_bsdf::write::klems_xml(
            &in_metres(errors),
            Some(&format!(
                "{comment}: standard error of each element (sr^-1)"
            )),
        )
        .map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut f = fenestra_cli::output::AtomicFile::create(path)
            .with_context(|| format!("cannot write '{path}'"))?;
        f.write_all(text.as_bytes())?;
        f.commit()?;
    }
    let mut out = std::io::stdout().lock();
    out.write_all(xml.as_bytes())?;
    out.flush()?;
    if !quiet && tree.is_none() {
        eprint!("{}", fenestra_genbsdf::summary(&bsdf));
    }
    if verbose {
        let p = fenestra_cli::prog();
        for n in &got.effects {
            eprintln!("{p}: effect: {n}");
        }
        let r = got.rays;
        eprintln!(
            "{p}: {ndir} incident directions x {} samples in {:.2} s; rays traced: {r}",
            got.samples,
            started.elapsed().as_secs_f64(),
        );
        if let Some(m) = fenestra_cli::peak_memory_line() {
            eprintln!("{p}: {m}");
        }
    }
    Ok(ExitCode::SUCCESS)
}
