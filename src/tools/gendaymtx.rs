//! gendaymtx: annual Perez sky matrix from a .wea or .epw weather tape.

use anyhow::{bail, Context, Result};
use fenestra_sky::daymtx::{self, fmt_g, DaymtxOptions};
use fenestra_sky::patches::Reinhart;
use fenestra_sky::weather;
use std::f64::consts::PI;
use std::io::Write;
use std::process::ExitCode;

const USAGE: &str = "[-v][-h][-A][-d|-s|-n][-u][-D file [-M modfile]][-r deg][-m N][-g r g b][-c r g b][-o{f|d}][-O{0|1}][-i min][-5 deg] [tape.wea|tape.epw]";

fn usage() -> anyhow::Error {
    anyhow::anyhow!("usage: {} {USAGE}", fenestra_cli::prog())
}

fn real(args: &[String], i: usize) -> Result<f64> {
    let w = args
        .get(i)
        .ok_or_else(|| anyhow::anyhow!("option {} needs a value", args[i - 1]))?;
    fenestra_cli::opts::parse_real(w)
        .ok_or_else(|| anyhow::anyhow!("option value '{w}' is not a number"))
}

/// Where the sun descriptions of `-D` go.
enum SunOut {
    None,
    Stdout,
    File(String),
}

/// Runs gendaymtx.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    if fenestra_cli::help_asked(&args, USAGE, "Perez all-weather sky matrix (rows = ground + Reinhart patches, columns = time steps).\nOptions:\n  -m N        Reinhart subdivision: 146, 578, 2306 rows for 1, 2, 4 (default 1)\n  -c r g b    sky colour (default 0.960 1.004 1.118)\n  -g r g b    ground reflectance (default 0.2 0.2 0.2)\n  -d | -s     sun only | sky only\n  -D file     write one sun per sunlit step ('-': to standard output, no matrix); -n: no matrix\n  -M file     list the sun modifiers (with -D)\n  -u          only steps with the sun up\n  -A          one column: the average over all steps\n  -r deg      rotate the sky counter-clockwise seen from above\n  -oa|-of|-od ascii | float | double output (default ascii)\n  -O0 | -O1   visible | solar radiance\n  -i min      data interval: steps near sunrise/sunset use their sunlit part\n  -5 deg      the sun into its nearest patch, solid angle from deg (five-phase)\n  -h          no header;  -v  progress and warnings\nFull documentation: fenestra doc gendaymtx (docs/tools/gendaymtx.md in the source).") {
        return Ok(ExitCode::SUCCESS);
    }
    let mut o = DaymtxOptions::default();
    let mut verbose = false;
    let mut header = true;
    let mut outfmt = 'a';
    let mut average = false;
    let mut no_matrix = false;
    let mut suns = SunOut::None;
    let mut mods: Option<String> = None;
    let mut i = 1;
    while i < args.len() && args[i].starts_with('-') && args[i].len() > 1 {
        let a = args[i].as_bytes();
        match a[1] {
            b'g' => {
                for k in 0..3 {
                    o.settings.ground[k] = real(&args, i + 1 + k)? as f32;
                }
                i += 3;
            }
            b'v' => verbose = true,
            b'h' => header = false,
            b'o' => match a.get(2) {
                Some(b'f') | Some(b'd') | Some(b'a') => outfmt = a[2] as char,
                _ => return Err(usage()),
            },
            b'O' => {
                match a.get(2) {
                    Some(b'0') => o.settings.solar_output = false,
                    Some(b'1') => o.settings.solar_output = true,
                    _ => return Err(usage()),
                }
                if a.len() > 3 {
                    return Err(usage());
                }
            }
            b'm' => {
                i += 1;
                let w = args.get(i).ok_or_else(usage)?;
                let mf = fenestra_cli::opts::parse_int(w)
                    .filter(|&v| v >= 1)
                    .ok_or_else(|| anyhow::anyhow!("-m needs a positive integer, got '{w}'"))?;
                o.mf = mf as usize;
            }
            b'c' => {
                for k in 0..3 {
                    o.settings.sky_color[k] = real(&args, i + 1 + k)? as f32;
                }
                i += 3;
            }
            b'D' | b'n' | b'd' => {
                if a[1] == b'D' {
                    i += 1;
                    let f = args.get(i).ok_or_else(usage)?;
                    if f != "-" {
                        suns = SunOut::File(f.clone());
                    } else {
                        suns = SunOut::Stdout;
                    }
                }
                if a[1] == b'n' || (a[1] == b'D' && matches!(suns, SunOut::Stdout)) {
                    no_matrix = true;
                    o.mf = 1;
                }
                if a[1] != b'D' || matches!(suns, SunOut::Stdout) {
                    o.settings.sky_color = [0.0; 3];
                    o.settings.ground = [0.0; 3];
                }
            }
            b'M' => {
                i += 1;
                mods = Some(args.get(i).ok_or_else(usage)?.clone());
            }
            b's' => o.settings.sun_color = [0.0; 3],
            b'u' => o.sun_hours_only = true,
            b'r' => {
                if a.len() > 2 && a[2] != b'z' {
                    return Err(usage());
                }
                i += 1;
                o.rotation = real(&args, i)?;
            }
            b'5' => {
                i += 1;
                let d = real(&args, i).unwrap_or(0.0);
                let mut sa = PI / 360.0 * d;
                if sa <= 0.0 {
                    bail!("missing solar disk size argument for '-5' option (a positive size in degrees)");
                }
                sa = sa * (sa * PI);
                o.settings.nsuns = 1;
                o.settings.fixed_sun_sa = Some(sa);
            }
            b'A' => average = true,
            b'i' => {
                i += 1;
                o.interval = real(&args, i)?;
            }
            _ => return Err(usage()),
        }
        i += 1;
    }
    if i + 1 < args.len() {
        return Err(usage());
    }
    let name = args.get(i).cloned();
    let mut input = fenestra_cli::input::open(name.as_deref().unwrap_or("-"))?;
    let label = name.clone().unwrap_or_else(|| "<stdin>".into());
    let tape = weather::read_tape(&mut input).with_context(|| format!("reading '{label}'"))?;
    for w in &tape.warnings {
        fenestra_cli::warn(format!("{label}: {w}"));
    }
    if mods.is_some() && matches!(suns, SunOut::None) {
        eprintln!(
            "{}: warning -M output will be empty without -D",
            fenestra_cli::prog()
        );
    }
    let basis = Reinhart::new(o.mf);
    if verbose {
        eprintln!(
            "{}: location '{}'",
            fenestra_cli::prog(),
            tape.location.place
        );
        if !no_matrix {
            eprintln!("{}: {} sky patches", fenestra_cli::prog(), basis.len());
        }
    }
    let (steps, warnings) = daymtx::plan(&tape, &o)?;
    for w in &warnings {
        fenestra_cli::warn(w);
    }
    if steps.is_empty() {
        bail!("no valid time steps on input");
    }
    let cols = daymtx::compute(&basis, &o.settings, &steps, no_matrix);
    if !matches!(suns, SunOut::None) {
        let mut text = String::new();
        let mut names = String::new();
        for (k, st) in steps.iter().enumerate() {
            if !st.sun_in_sky {
                continue;
            }
            text.push_str(&daymtx::sun_text(
                st,
                cols.dir_illum[k],
                !st.night,
                o.settings.sun_color,
            ));
            names.push_str(&format!("solar{}\n", st.minute));
        }
        match &suns {
            SunOut::Stdout => std::io::stdout().lock().write_all(text.as_bytes())?,
            SunOut::File(f) => {
                std::fs::write(f, &text).with_context(|| format!("cannot write '{f}'"))?
            }
            SunOut::None => {}
        }
        if let Some(m) = &mods {
            std::fs::write(m, &names).with_context(|| format!("cannot write '{m}'"))?;
        }
    } else if let Some(m) = &mods {
        std::fs::write(m, "").with_context(|| format!("cannot write '{m}'"))?;
    }
    if no_matrix {
        return Ok(ExitCode::SUCCESS);
    }
    let n = cols.n;
    let (data, ncols): (Vec<f32>, usize) = if average && steps.len() > 1 {
        (daymtx::average(&cols, &steps), 1)
    } else if average {
        (cols.data.clone(), 1)
    } else {
        (cols.data, steps.len())
    };
    if verbose {
        eprintln!(
            "{}: writing {}matrix with {} time steps...",
            fenestra_cli::prog(),
            if outfmt == 'a' { "" } else { "binary " },
            ncols
        );
    }
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::with_capacity(1 << 20, stdout.lock());
    if header {
        let site = daymtx::tape_site(&tape);
        let mut h = fenestra_formats::header::Header::radiance();
        h.push(fenestra_cli::command_line(&args));
        h.push(format!(
            "LATLONG= {:.8} {:.8}",
            site.latitude * (180.0 / PI),
            -(site.longitude * (180.0 / PI))
        ));
        let opts = fenestra_formats::WriteOptions {
            format: match outfmt {
                'f' => fenestra_formats::DataFormat::Float,
                'd' => fenestra_formats::DataFormat::Double,
                _ => fenestra_formats::DataFormat::Ascii,
            },
            header: Some(h),
            align_from: fenestra_cli::output::stdout_file_offset(),
            ..Default::default()
        };
        let averaged = if average {
            vec![format!("NAVERAGED={}", steps.len())]
        } else {
            Vec::new()
        };
        let h = fenestra_formats::matrix::header_bytes(Some(n), ncols, 3, &opts, &averaged)?;
        out.write_all(&h)?;
    }
    let m = 3 * n;
    for p in 0..n {
        match outfmt {
            'a' => {
                let mut s = String::with_capacity(ncols * 24);
                for j in 0..ncols {
                    let v = &data[j * m + 3 * p..j * m + 3 * p + 3];
                    s.push_str(&fmt_g(f64::from(v[0]), 3));
                    s.push(' ');
                    s.push_str(&fmt_g(f64::from(v[1]), 3));
                    s.push(' ');
                    s.push_str(&fmt_g(f64::from(v[2]), 3));
                    s.push('\n');
                }
                if ncols > 1 {
                    s.push('\n');
                }
                out.write_all(s.as_bytes())?;
            }
            'f' => {
                let mut b = Vec::with_capacity(ncols * 12);
                for j in 0..ncols {
                    for v in &data[j * m + 3 * p..j * m + 3 * p + 3] {
                        b.extend_from_slice(&v.to_ne_bytes());
                    }
                }
                out.write_all(&b)?;
            }
            _ => {
                let mut b = Vec::with_capacity(ncols * 24);
                for j in 0..ncols {
                    for v in &data[j * m + 3 * p..j * m + 3 * p + 3] {
                        b.extend_from_slice(&f64::from(*v).to_ne_bytes());
                    }
                }
                out.write_all(&b)?;
            }
        }
    }
    out.flush()?;
    if verbose {
        eprintln!("{}: done.", fenestra_cli::prog());
    }
    Ok(ExitCode::SUCCESS)
}
