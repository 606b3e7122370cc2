//! rtrace: trace rays (or compute irradiance at points) in a scene.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_trace::waves::Waves;
use fenestra_trace::{DVec3, TraceOptions, Tracer};

const USAGE: &str = "[-I|-i][-o{o,d,v,w,l,L,p,n,N}][-f{a,f,d}{a,f,d}][-h][-x N][-y N][-n N][-ab N][-ad N][-aa V][-ar N][-as N][-av r g b][-lw W][-lr N][-ds V][-dj V][-dc V][-dr N][-dt V][-st V][-ss V][-bv][-u][-v][-full][-seed N] scene.{rad,oct}…";

/// `rtrace --help`: one line per option.
const RTRACE_OPTIONS: &str = "Options:
  -I | -i          irradiance at the input point (input: point normal) | at the first hit of each ray
  -o{o,d,v,w,l,L,p,n,N}  values printed per ray (default -ov: radiance)
  -f{a,f,d}{a,f,d} input / output format: ascii, float, double (default -faa)
  -h               no header;  -w  warnings off;  -v  what the engine switched on and why
  -n N             threads (same output for any N)
  -x N -y N        flush every N records / picture size for -y
  -ab N            ambient bounces (default 0)
  -ad N            ambient divisions: hemisphere samples (default 1024)
  -as N            ambient super-samples (default 512)
  -aa V            ambient accuracy: accepted, no irradiance cache (pure Monte Carlo, as -aa 0)
  -av r g b        ambient value beyond the last bounce (default 0 0 0)
  -lw W            minimum ray weight (default 1e-4);  -lr N  maximum reflections (default -10)
  -dt V -dc V      source thresholding and certainty (default .03, .75)
  -dj V -ds V      source jitter (default 0) and subdivision (default .2);  -dr N  relays
  -st V -ss V      specular threshold (default .15) and sampling (default 1)
  -bv              back faces of emitters visible (default on)
  -e expr -f file  .cal definitions for patterns
  -seed N          random stream seed (fenestra);  -full  no effect selection
  -defaults        print the values in effect;  -version
Full documentation: fenestra doc rtrace (docs/tools/rtrace.md in the source).";

/// The `-f` number-stream format (one type for every tool).
type Fmt = fenestra_cli::rays::RayFormat;

fn fmt_of(c: char) -> Result<Fmt> {
    match Fmt::from_letter(c) {
        Some(f) => Ok(f),
        None => bail!("unsupported data format '{c}' (fenestra supports a, f, d)"),
    }
}

fn num(args: &[String], i: usize) -> Result<f64> {
    let w = args
        .get(i)
        .with_context(|| format!("option {} needs a value", args[i - 1]))?;
    fenestra_cli::opts::parse_real(w)
        .with_context(|| format!("option {}: '{w}' is not a number", args[i - 1]))
}

use fenestra_cli::opts::bool_option as toggle;

/// Runs rtrace.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    if args.iter().skip(1).any(|a| a == "--help") {
        println!("{} {USAGE}\nTraces rays read from standard input (origin, direction) and prints values.\n{RTRACE_OPTIONS}", fenestra_cli::prog());
        return Ok(ExitCode::SUCCESS);
    }
    let mut o = TraceOptions::rtrace();
    let (mut irr, mut irr_hit, mut header, mut verbose) = (false, false, true, false);
    let mut outspec = "v".to_string();
    let (mut fin, mut fout) = (Fmt::Ascii, Fmt::Ascii);
    let (mut xres, mut yres, mut nproc) = (0usize, 0usize, 1usize);
    let mut aa: Option<f64> = None;
    let mut files = Vec::new();
    let mut i = 1;
    while i < args.len() {
        let a = args[i].as_str();
        if !(a.starts_with('-') || a.starts_with('+')) || a == "-" {
            files.extend(args[i..].iter().cloned());
            break;
        }
        if a == "-version" {
            println!(
                "fenestra {} rtrace (Radiance 6.0a compatible)",
                env!("CARGO_PKG_VERSION")
            );
            return Ok(ExitCode::SUCCESS);
        }
        if a == "-defaults" {
            // Radiance's layout, with the values in effect (those given before it)
            let pm = |b: bool| if b { '+' } else { '-' };
            let fc = |f: Fmt| f.letter();
            let lines = [
                format!(
                    "-w{}\t\t\t\t# warning messages {}",
                    pm(fenestra_cli::warnings_on()),
                    if fenestra_cli::warnings_on() {
                        "on"
                    } else {
                        "off"
                    }
                ),
                format!("-n {nproc:<8}\t\t\t# number of rendering threads"),
                format!("-x {xres:<8}\t\t\t# flush interval"),
                format!("-y {yres:<8}\t\t\t# y resolution"),
                format!("-h{}\t\t\t\t# output header", pm(header)),
                format!("-f{}{}\t\t\t\t# format input/output", fc(fin), fc(fout)),
                format!("-o{outspec:<8}\t\t\t# output value"),
                format!("-I{}\t\t\t\t# irradiance at the input point", pm(irr)),
                format!(
                    "-i{}\t\t\t\t# irradiance calculation {}",
                    pm(irr_hit),
                    if irr_hit { "on" } else { "off" }
                ),
                format!(
                    "-bv{}\t\t\t\t# back face visibility {}",
                    pm(o.bv),
                    if o.bv { "on" } else { "off" }
                ),
                format!("-dt {:.6}\t\t\t# direct threshold", o.dt),
                format!("-dc {:.6}\t\t\t# direct certainty", o.dc),
                format!("-dj {:.6}\t\t\t# direct jitter", o.dj),
                format!("-ds {:.6}\t\t\t# direct sampling", o.ds),
                format!("-dr {:<8}\t\t\t# direct relays", o.dr),
                format!("-ss {:.6}\t\t\t# specular sampling", o.ss),
                format!("-st {:.6}\t\t\t# specular threshold", o.st),
                format!(
                    "-av {:.6} {:.6} {:.6}\t# ambient value",
                    o.av[0], o.av[1], o.av[2]
                ),
                format!("-ab {:<8}\t\t\t# ambient bounces", o.ab),
                "-aa 0.000000\t\t\t# ambient accuracy (fenestra: no irradiance cache)".to_string(),
                format!("-ad {:<8}\t\t\t# ambient divisions", o.ad),
                format!("-as {:<8}\t\t\t# ambient super-samples", o.asamp),
                format!("-lr {:<8}\t\t\t# limit reflection (Russian roulette)", o.lr),
                format!("-lw {:.2e}\t\t\t# limit weight", o.lw),
                format!("-seed {:<8}\t\t# random stream seed (fenestra)", o.seed),
            ];
            for l in lines {
                println!("{l}");
            }
            return Ok(ExitCode::SUCCESS);
        }
        if let Some(v) = toggle(a, "I", irr) {
            irr = v;
        } else if let Some(v) = toggle(a, "i", irr_hit) {
            irr_hit = v;
        } else if let Some(v) = toggle(a, "h", header) {
            header = v;
        } else if let Some(v) = toggle(a, "bv", o.bv) {
            o.bv = v;
        } else if let Some(v) = toggle(a, "u", false) {
            let _ = v;
        } else if let Some(v) = toggle(a, "w", true) {
            fenestra_cli::set_warnings(v);
        } else if a == "-full" {
            o.full = true;
        } else if a == "-v" {
            verbose = true;
        } else if let Some(spec) = a.strip_prefix("-o") {
            outspec = spec.to_string();
        } else if let Some(f) = a
            .strip_prefix("-f")
            .filter(|f| !f.is_empty() && f.len() <= 2 && f.chars().all(|c| "afd".contains(c)))
        {
            let c: Vec<char> = f.chars().collect();
            fin = fmt_of(c[0])?;
            fout = fmt_of(*c.get(1).unwrap_or(&c[0]))?;
        } else {
            let name = &a[1..];
            match name {
                n if fenestra_trace::TraceOptions::is_number_option(n) => {
                    o.set_number(n, num(&args, i + 1)?);
                }
                "dt" => o.dt = num(&args, i + 1)?,
                "dp" => {}
                "aa" => aa = Some(num(&args, i + 1)?),
                "as" => o.asamp = num(&args, i + 1)?.max(0.0) as u32,
                "ar" | "aw" => {
                    num(&args, i + 1)?;
                }
                "af" | "ai" | "ae" | "aI" | "aE" => {
                    args.get(i + 1)
                        .with_context(|| format!("option {a} needs a value"))?;
                }
                "x" => xres = num(&args, i + 1)?.max(0.0) as usize,
                "y" => yres = num(&args, i + 1)?.max(0.0) as usize,
                "n" => nproc = fenestra_cli::threads::worker_count(num(&args, i + 1)?)?,
                "av" => {
                    o.av = [num(&args, i + 1)?, num(&args, i + 2)?, num(&args, i + 3)?];
                    i += 2;
                }
                "e" | "f" => {
                    let v = args
                        .get(i + 1)
                        .with_context(|| format!("option {a} needs an argument"))?
                        .clone();
                    o.cal.push(if name == "e" {
                        fenestra_trace::options::CalSource::Expr(v)
                    } else {
                        fenestra_trace::options::CalSource::File(v)
                    });
                }
                _ => bail!(
                    "unknown option '{a}'\nusage: {} {USAGE}",
                    fenestra_cli::prog()
                ),
            }
            i += 1;
        }
        i += 1;
    }
    if files.is_empty() {
        bail!(
            "missing scene file\nusage: {} {USAGE}",
            fenestra_cli::prog()
        );
    }
    // the irradiance cache is not implemented: a warning when asked for, a note with -v
    match aa {
        Some(a) if a > 0.0 => fenestra_cli::warn(format!("-aa {a}: the irradiance cache is not supported; computing as with -aa 0 (pure Monte Carlo)")),
        _ if verbose => eprintln!("{}: no irradiance cache (-aa 0): indirect light by pure Monte Carlo", fenestra_cli::prog()),
        _ => {}
    }
    for c in outspec.chars() {
        if !"odvVwlLpnN".contains(c) {
            bail!("output specification -o{outspec}: '{c}' is not supported by fenestra (use o d v w l L p n N)");
        }
    }
    let refs: Vec<&str> = files.iter().map(String::as_str).collect();
    let scene = fenestra_scene::load(&refs)?;
    let tracer = Tracer::new(&scene, &o)?;
    for w in tracer.warnings() {
        fenestra_cli::warn(w);
    }
    // With source thresholding the statistics are carried over the run, deterministically
    // for any -n (fenestra_trace::waves)
    let mut waves = Waves::new(&tracer, o.ab);
    let (thresholding, block) = (waves.thresholding(), waves.block());
    if verbose {
        for n in &tracer.effects().notes {
            eprintln!("{}: {n}", fenestra_cli::prog());
        }
        if thresholding {
            let growing: Vec<String> = (0..)
                .map(fenestra_trace::waves::wave_width)
                .take_while(|&w| w < fenestra_trace::waves::WAVE_MAX)
                .map(|w| w.to_string())
                .collect();
            eprintln!(
                "{}: source thresholding: hit statistics and obstructor caches carried over the run, in blocks of {block} record(s) traced in waves of {}, then {} blocks (each block starts from all earlier waves)",
                fenestra_cli::prog(),
                growing.join(", "),
                fenestra_trace::waves::WAVE_MAX
            );
        }
    }
    if (irr || irr_hit) && !outspec.chars().any(|c| "rRxXvVlnW".contains(c)) {
        bail!("-I+ and -i+ options require some value output");
    }
    if !tracer.emits() && !outspec.chars().all(|c| "odlLpnN".contains(c)) {
        fenestra_cli::warn("no light sources found (nothing in the scene emits light)");
    }
    let expect = if yres > 0 { xres.max(1) * yres } else { 0 };
    let out = std::io::stdout();
    let mut w = std::io::BufWriter::with_capacity(1 << 16, out.lock());
    if header {
        let mut h = String::from("#?RADIANCE\n");
        h.push_str(&fenestra_cli::command_line(&args));
        h.push_str("\nSOFTWARE= fenestra\n");
        // numbers per record, as Radiance counts them
        let ncomp: usize = outspec
            .chars()
            .map(|c| match c {
                'o' | 'd' | 'v' | 'V' | 'p' | 'n' | 'N' | 'W' | 'r' | 'x' => 3,
                'c' => 2,
                '~' => 0,
                _ => 1,
            })
            .sum();
        if ncomp > 0 {
            h.push_str(&format!("NCOMP={ncomp}\n"));
        }
        h.push_str(match fout {
            Fmt::Ascii => "FORMAT=ascii\n",
            Fmt::Float => "FORMAT=float\n",
            Fmt::Double => "FORMAT=double\n",
        });
        h.push('\n');
        if xres > 0 && yres > 0 {
            h.push_str(&format!("-Y {yres} +X {xres}\n"));
        }
        w.write_all(h.as_bytes())?;
    }
    // Radiance's flushing: every -x records unless -y makes a picture of -x > 1 records a
    // line; a ray with a zero direction flushes too
    let flush_every = if yres == 0 || xres <= 1 { xres } else { 0 };
    if flush_every > 0 {
        w.flush()?;
    }
    let pool = fenestra_cli::threads::pool(nproc)?;
    let progress = fenestra_cli::progress::Progress::new(expect as u64, "rtrace");
    let wants_hit = outspec.chars().any(|c| "lLpnN".contains(c));
    let record = |k: usize, (org, dir): (DVec3, DVec3), st: &mut fenestra_trace::DirectState| {
        let mut rec = Vec::new();
        let hit = if wants_hit {
            Some(tracer.first_hit(org, dir))
        } else {
            None
        };
        for c in outspec.chars() {
            match c {
                'o' => rec.extend(org.to_array()),
                'd' => rec.extend(dir.normalize_or_zero().to_array()),
                'v' | 'V' => {
                    let v = if dir == DVec3::ZERO {
                        [0.0; 3]
                    } else if irr {
                        // Radiance's -I point: 1e-4 along the normal
                        let n = dir.normalize_or_zero();
                        let q = Tracer::rtrace_irradiance_point(org, n);
                        tracer.irradiance_with(st, k as u64, q, n)
                    } else if irr_hit {
                        tracer.irradiance_at_hit_with(st, k as u64, org, dir)
                    } else {
                        tracer.radiance_with(st, k as u64, org, dir)
                    };
                    rec.extend(v);
                }
                'w' => rec.push(1.0),
                'l' | 'L' => rec.push(hit.map_or(0.0, |h| h.t)),
                'p' => rec.extend(hit.map_or([0.0; 3], |h| h.point.to_array())),
                'N' => rec.extend(hit.map_or([0.0; 3], |h| h.geometric.to_array())),
                _ => rec.extend(hit.map_or([0.0; 3], |h| h.normal.to_array())),
            }
        }
        rec
    };
    // Rays are read and traced in batches; a batch ends early where Radiance flushes.
    let batch_max = waves.batch_max();
    let stdin = std::io::stdin();
    let mut reader = fenestra_cli::rays::RayReader::new(
        std::io::BufReader::with_capacity(1 << 16, stdin.lock()),
        fin,
    );
    let mut k0 = 0usize;
    let mut schedule = fenestra_cli::rays::FlushSchedule::new(flush_every);
    let mut bad_rays = 0usize;
    let mut batch: Vec<(DVec3, DVec3)> = Vec::new();
    loop {
        batch.clear();
        let mut flush = false;
        while batch.len() < batch_max && (expect == 0 || k0 + batch.len() < expect) {
            let Some((org, dir)) = reader.next_ray()? else {
                break;
            };
            let (org, dir) = (DVec3::from(org), DVec3::from(dir));
            let dummy = if org.is_finite() && dir.is_finite() {
                batch.push((org, dir));
                dir == DVec3::ZERO
            } else {
                // answered with zeros (and a warning), never traced into a NaN
                bad_rays += 1;
                batch.push((DVec3::ZERO, DVec3::ZERO));
                false
            };
            if schedule.record_done(dummy) {
                flush = true;
                break;
            }
        }
        if batch.is_empty() {
            break;
        }
        let n = batch.len();
        waves.run(
            &pool,
            &batch,
            |k, &ray, st| record(k, ray, st),
            |recs| {
                for rec in &recs {
                    write_record(&mut w, fout, rec)?;
                }
                progress.inc(recs.len() as u64);
                Ok(())
            },
        )?;
        k0 += n;
        if flush {
            w.flush()?;
        }
        if expect > 0 && k0 >= expect {
            break;
        }
    }
    progress.finish();
    w.flush()?;
    if let Some(msg) = reader.take_warning() {
        fenestra_cli::warn(msg);
    }
    if bad_rays > 0 {
        fenestra_cli::warn(format!(
            "{bad_rays} input ray(s) with a value that is not finite (nan, inf) answered with zeros"
        ));
    }
    if verbose {
        let c = tracer.ray_counts();
        eprintln!(
            "{}: {} rays traced for {k0} input records: {c}",
            fenestra_cli::prog(),
            tracer.rays_traced(),
        );
        if let Some(m) = fenestra_cli::peak_memory_line() {
            eprintln!("{}: {m}", fenestra_cli::prog());
        }
    }
    if expect > 0 && k0 < expect {
        bail!("unexpected EOF on input");
    }
    Ok(ExitCode::SUCCESS)
}

/// Writes one record's values in the output format.
fn write_record(w: &mut impl Write, fout: Fmt, rec: &[f64]) -> Result<()> {
    match fout {
        Fmt::Ascii => {
            let mut s = String::new();
            for v in rec {
                s.push_str(&format!("{}\t", fenestra_cfmt::fmt_e(*v, 6)));
            }
            s.push('\n');
            w.write_all(s.as_bytes())?;
        }
        Fmt::Float => {
            for v in rec {
                w.write_all(&(*v as f32).to_ne_bytes())?;
            }
        }
        Fmt::Double => {
            for v in rec {
                w.write_all(&v.to_ne_bytes())?;
            }
        }
    }
    Ok(())
}
