//! mkillum: turns windows and other surfaces into `illum` proxy light sources (the
//! fenestra-illum crate does the work; this module parses the command line and feeds
//! the scene text through the filter).

use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_illum::Filter;
use fenestra_trace::{TraceOptions, Tracer};

const USAGE: &str = "[-n N][-w][-v][-E file][render options] scene.{oct,rad} [< file ..]";

fn num(args: &[String], i: usize) -> Result<f64> {
    let w = args
        .get(i)
        .with_context(|| format!("option {} needs a value", args[i - 1]))?;
    fenestra_cli::opts::parse_real(w)
        .with_context(|| format!("option {}: '{w}' is not a number", args[i - 1]))
}

/// Runs mkillum.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    if fenestra_cli::help_asked(&args, USAGE, "Reads scene text (from the files after '<', or standard input) and replaces the surfaces selected by #@mkillum directives with illum sources whose distribution is sampled through the scene.\nOptions:\n  -n N        threads\n  -w          no warnings\n  -v          effects, rays by kind, time, each surface's mean and standard errors\n  -E file     per surface: mean radiance and each direction's relative standard error\n  -ab -ad -as -lw -lr -dj -ds -dt -dc -st -ss -av -bv -seed ..  render options (defaults -ab 2 -dj .5 -dr 3 over rtrace's)\nDirectives (#@mkillum): o= m= f= a n i= e= b= c=d|a|n d= s= l+ l- u= !, and d=file.xml for BSDF data.\nFull documentation: fenestra doc mkillum (docs/tools/mkillum.md in the source).") {
        return Ok(ExitCode::SUCCESS);
    }
    // mkillum's render defaults: rtrace's, with -dj .5 -dr 3 -ab 2
    let mut o = TraceOptions::rtrace();
    o.dj = 0.5;
    o.dr = 3;
    o.ab = 2;
    let mut nproc = 1usize;
    let mut err_file: Option<String> = None;
    let mut verbose = false;
    let started = std::time::Instant::now();
    let mut i = 1;
    while i < args.len() {
        let a = args[i].as_str();
        if !(a.starts_with('-') || a.starts_with('+')) || a == "-" {
            break;
        }
        if a == "-defaults" {
            print!("{}", fenestra_illum::Settings::default().defaults_text());
            println!("-ab {:<8}\t\t\t# ambient bounces", o.ab);
            println!("-ad {:<8}\t\t\t# ambient divisions", o.ad);
            println!("-lw {:.2e}\t\t\t# limit weight", o.lw);
            println!("-dj {:.6}\t\t\t# direct jitter", o.dj);
            println!("-dr {:<8}\t\t\t# direct relays", o.dr);
            println!("-dt {:.6}\t\t\t# direct threshold", o.dt);
            println!("-st {:.6}\t\t\t# specular threshold", o.st);
            println!("-seed {:<8}\t\t# random stream seed (fenestra)", o.seed);
            return Ok(ExitCode::SUCCESS);
        }
        if let Some(v) = fenestra_cli::opts::bool_option(a, "w", true) {
            fenestra_cli::set_warnings(v);
            i += 1;
            continue;
        }
        if let Some(v) = fenestra_cli::opts::bool_option(a, "v", verbose) {
            verbose = v;
            i += 1;
            continue;
        }
        if let Some(v) = fenestra_cli::opts::bool_option(a, "bv", o.bv) {
            o.bv = v;
            i += 1;
            continue;
        }
        if fenestra_cli::opts::bool_option(a, "u", false).is_some()
            || fenestra_cli::opts::bool_option(a, "dv", true).is_some()
            || fenestra_cli::opts::bool_option(a, "i", false).is_some()
            || fenestra_cli::opts::bool_option(a, "I", false).is_some()
        {
            i += 1;
            continue;
        }
        let name = &a[1..];
        match name {
            "n" => {
                let v = num(&args, i + 1)?;
                if v <= 0.0 {
                    bail!("illegal number of processes");
                }
                nproc = fenestra_cli::threads::worker_count(v)?;
            }
            "E" => {
                err_file = Some(
                    args.get(i + 1)
                        .context("-E needs a file name (the per-direction standard errors)")?
                        .clone(),
                )
            }
            n if TraceOptions::is_number_option(n) => {
                o.set_number(n, num(&args, i + 1)?);
            }
            "dt" => o.dt = num(&args, i + 1)?,
            "as" => o.asamp = num(&args, i + 1)?.max(0.0) as u32,
            "aa" => {
                let v = num(&args, i + 1)?;
                if v > 0.0 {
                    fenestra_cli::warn(format!("-aa {v}: the irradiance cache is not supported; computing as with -aa 0 (pure Monte Carlo)"));
                }
            }
            "dp" | "ar" | "aw" | "mg" | "ms" => {
                num(&args, i + 1)?;
            }
            "af" | "ai" | "ae" | "aI" | "aE" => {
                args.get(i + 1)
                    .with_context(|| format!("option {a} needs a value"))?;
            }
            "av" | "me" | "ma" => {
                let v = [num(&args, i + 1)?, num(&args, i + 2)?, num(&args, i + 3)?];
                if name == "av" {
                    o.av = v;
                } else if v.iter().any(|&x| x != 0.0) {
                    bail!("participating media (-{name}) are not supported by fenestra");
                }
                i += 2;
            }
            _ => bail!(
                "bad render option at '{a}'\nusage: {} {USAGE}",
                fenestra_cli::prog()
            ),
        }
        i += 2;
    }
    if i >= args.len() {
        bail!(
            "missing octree argument\nusage: {} {USAGE}",
            fenestra_cli::prog()
        );
    }
    let scene_file = args[i].clone();
    let header = fenestra_cli::command_line(&args[..=i]);
    let inputs: Vec<String> = match args.get(i + 1) {
        None => Vec::new(),
        Some(lt) if lt == "<" && args.len() > i + 2 => args[i + 2..].to_vec(),
        Some(_) => bail!("use '< file1 file2 ..' for multiple inputs"),
    };
    let scene = fenestra_scene::load(&[scene_file.as_str()])?;
    let tracer = Tracer::new(&scene, &o)?;
    for w in tracer.warnings() {
        fenestra_cli::warn(w);
    }
    let pool = fenestra_cli::threads::pool(nproc)?;
    let progress = fenestra_cli::progress::Progress::new(0, "mkillum");
    pool.install(|| -> Result<()> {
        let mut filter = Filter::new(&tracer, o.seed, header);
        if err_file.is_some() || verbose {
            filter.errors = Some(Vec::new());
        }
        filter.progress = Some(&progress);
        if inputs.is_empty() {
            let mut text = Vec::new();
            std::io::Read::read_to_end(&mut std::io::stdin(), &mut text)
                .context("cannot read standard input")?;
            filter.run_text(&String::from_utf8_lossy(&text), "standard input")?;
        } else {
            for f in &inputs {
                let bytes =
                    std::fs::read(f).with_context(|| format!("cannot open scene file \"{f}\""))?;
                filter.run_text(&String::from_utf8_lossy(&bytes), f)?;
            }
        }
        let errs = filter.errors.take();
        filter.progress = None;
        filter.finish()?;
        if verbose {
            budget(
                &tracer,
                errs.as_deref().unwrap_or(&[]),
                started.elapsed().as_secs_f64(),
            );
        }
        if let (Some(path), Some(errs)) = (&err_file, errs) {
            write_errors(path, &errs)?;
        }
        Ok(())
    })?;
    progress.finish();
    Ok(ExitCode::SUCCESS)
}

/// `-v`: the effects switched on, the rays traced by kind and the time, and per surface
/// its mean luminance with the rms and largest relative standard error of its directions.
fn budget(tracer: &Tracer, errs: &[fenestra_illum::filter::SurfaceError], seconds: f64) {
    let p = fenestra_cli::prog();
    for n in &tracer.effects().notes {
        eprintln!("{p}: effect: {n}");
    }
    let r = tracer.ray_counts();
    eprintln!(
        "{p}: {} surfaces in {seconds:.2} s; rays traced: {r}",
        errs.len(),
    );
    if let Some(m) = fenestra_cli::peak_memory_line() {
        eprintln!("{p}: {m}");
    }
    for e in errs {
        let n = e.rel.len().max(1) as f64;
        let rms = (e.rel.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
        let worst = e.rel.iter().fold(0.0f64, |m, x| m.max(*x));
        eprintln!(
            "{p}: surface {}: mean radiance {} (luminance units), standard error of its directions rms {:.2}%, largest {:.2}%",
            e.name,
            fenestra_cfmt::fmt_e(e.mean, 4),
            100.0 * rms,
            100.0 * worst
        );
    }
}

/// The `-E` file: per surface, the mean luminance and each direction's relative standard error.
fn write_errors(path: &str, errs: &[fenestra_illum::filter::SurfaceError]) -> Result<()> {
    use std::io::Write as _;
    let mut f = fenestra_cli::output::AtomicFile::create(path)?;
    writeln!(
        f,
        "# mkillum -E: per surface, the mean radiance (luminance) and the relative standard error of each direction bin (1 sigma, from its rays' spread; altitude-major)"
    )?;
    for e in errs {
        let mut worst = 0.0f64;
        let mut sum = 0.0;
        for r in &e.rel {
            worst = worst.max(*r);
            sum += r * r;
        }
        let rms = (sum / e.rel.len().max(1) as f64).sqrt();
        writeln!(
            f,
            "{}\tmean {:.6e}\trms {:.4}\tmax {:.4}",
            e.name, e.mean, rms, worst
        )?;
        let line: Vec<String> = e.rel.iter().map(|r| format!("{r:.4}")).collect();
        writeln!(f, "{}", line.join(" "))?;
    }
    f.commit()
}
