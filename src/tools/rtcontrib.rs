//! rtcontrib / rcontrib: trace rays and accumulate what reaches tracked modifiers, per bin
//! (Radiance's contribution tracer). The work is in the fenestra-contrib crate; this module
//! parses the command line (left to right, as Radiance does) and drives the run.

use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_contrib::bins::{is_constant_bin, parse_params, BinRequest, Bins, CalcDefs};
use fenestra_contrib::engine::{Engine, InFormat, InputRay, RayInput, RunOptions, Tracked};
use fenestra_contrib::output::{self, Format, HeaderInfo, ModOut, Spec, Stream};
use fenestra_contrib::run as contrib_run;
use fenestra_trace::{TraceOptions, Tracer};

/// Most bins one modifier may have (2^24: 400 MiB of sums per thread).
const MAX_BINS: usize = 1 << 24;

const USAGE: &str = "[-n N][-v][-V][-I|-i][-c N][-f{a,f,d}{a,f,d,c}][-fo|-r][-x X -y Y][-o spec][-E][-Eo spec][-Eb N][-Er K][-p a=1,..][-e expr][-f file.cal][-b binexpr][-bn N] {-m mod | -M file} .. [-ab N -ad N -lw W -lr N -ds V -dj V -st V -ss V -bv -seed N ..] scene.{oct,rad} ..";

struct ModArg {
    name: String,
    /// rtcontrib without -bn: the bin count is found by a first pass over the input.
    dynamic: bool,
    spec: Option<Spec>,
    err_spec: Option<Spec>,
    params: Vec<(String, f64)>,
    bin: String,
    nbins: usize,
}

/// `-X`, `-X+`, `-X-`, `+X` (and `0`/`1`) forms of a toggle; `None` if `a` is not that toggle.
use fenestra_cli::opts::bool_option as toggle;

fn num(args: &[String], i: usize) -> Result<f64> {
    let w = args
        .get(i)
        .with_context(|| format!("option {} needs a value", args[i - 1]))?;
    fenestra_cli::opts::parse_real(w)
        .with_context(|| format!("option {}: '{w}' is not a number", args[i - 1]))
}

fn word(args: &[String], i: usize) -> Result<&str> {
    args.get(i)
        .map(String::as_str)
        .with_context(|| format!("option {} needs an argument", args[i - 1]))
}

/// Runs rtcontrib (also installed as rcontrib).
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let stdin: Box<dyn std::io::BufRead> = Box::new(std::io::BufReader::with_capacity(
        1 << 16,
        std::io::stdin().lock(),
    ));
    run_with(args, stdin, None)
}

/// A scene loaded by the caller, with the header lines that describe it.
pub struct Preloaded {
    /// The scene.
    pub scene: fenestra_scene::Scene,
    /// Lines written at the top of every output header (e.g. the command that made it).
    pub header: Vec<String>,
}

/// Runs rcontrib's command line `args` on rays read from `rays`; with a preloaded scene,
/// the command line names no scene files (rfluxmtx passes its scene and rays this way).
pub fn run_with(
    args: Vec<String>,
    rays: Box<dyn std::io::BufRead>,
    preloaded: Option<Preloaded>,
) -> Result<ExitCode> {
    if fenestra_cli::help_asked(&args, USAGE, "Traces rays read from standard input (origin direction; with -I point normal) and writes, for each record, the contribution coefficients of the tracked modifiers per bin.\nOptions (those of a modifier come before its -m):\n  -m mod / -M file   track a modifier (or those listed in a file)\n  -o spec            output file of the following modifiers (%s: modifier, %d: bin; !cmd: a command)\n  -b expr / -bn N    bin expression and bin count;  -p a=1,..  parameters;  -e expr / -f file.cal  definitions\n  -c N               rays per record (0: one summed record)\n  -I / -i            irradiance from point and normal / at the first surface hit\n  -V                 contributions instead of coefficients\n  -f{a,f,d}{a,f,d,c} input and output formats\n  -x X -y Y          picture output of that size\n  -fo / -r           overwrite outputs / recover an interrupted run\n  -n N               threads;  -h  no headers;  -w  no warnings;  -ld  limit ray length\n  -E, -Eo spec, -Eb N, -Er K   standard errors (their files), replicas per -c 1 record, K replica rows per record (fenestra)\n  -v                 effects, rays by kind, each modifier's total with its standard error (fenestra)\n  -ab -ad -as -lw -lr -dj -ds -dt -dc -st -ss -av -bv -seed ..  render options; -defaults lists them\nFull documentation: fenestra doc rtcontrib (docs/tools/rtcontrib.md in the source).") {
        return Ok(ExitCode::SUCCESS);
    }
    let mut o = TraceOptions::rcontrib();
    let (mut irr, mut value, mut header, mut warnings, mut overwrite, mut errors) =
        (false, false, true, true, false, false);
    let mut recover = false;
    let mut verbose = false;
    let started = std::time::Instant::now();
    let mut irr_hit = false;
    let mut limit_dist = false;
    let mut count = 1usize;
    let (mut xres, mut yres, mut nproc, mut batches) = (0usize, 0usize, 1usize, 4usize);
    let mut replicas = 0usize;
    let (mut fin, mut fout) = (InFormat::Ascii, Format::Ascii);
    let mut defs = CalcDefs::new();
    let mut cur_spec: Option<Spec> = None;
    let mut cur_err: Option<Spec> = None;
    let mut cur_params: Vec<(String, f64)> = Vec::new();
    let mut cur_bin = "0".to_string();
    let mut cur_nbins: Option<usize> = None;
    let mut mods: Vec<ModArg> = Vec::new();
    let mut files: Vec<String> = Vec::new();
    let mut first_file = args.len();
    let mut i = 1;
    let legacy = fenestra_cli::prog() == "rtcontrib";
    let add_mod = |name: &str,
                   mods: &mut Vec<ModArg>,
                   spec: &Option<Spec>,
                   err: &Option<Spec>,
                   params: &[(String, f64)],
                   bin: &str,
                   nb: Option<usize>|
     -> Result<()> {
        if name == "void" {
            bail!("cannot track 'void' modifier");
        }
        if mods.iter().any(|m| m.name == name) {
            bail!("duplicate modifier '{name}'");
        }
        // a constant bin (a number) is one bin whatever -bn says, as Radiance's; its value
        // rounded as (int)(v + 1.5) must give one bin
        if fenestra_cli::opts::parse_real(bin.trim()).is_some() && !is_constant_bin(bin) {
            bail!("illegal non-zero constant for bin ({bin})");
        }
        let (nbins, dynamic) = match nb {
            _ if is_constant_bin(bin) => (1, false),
            Some(n) if n > 0 => (n, false),
            // the older rtcontrib: -bn optional, the count is what the bins reach
            None if legacy => (1, true),
            _ => bail!("unspecified or illegal bin count for modifier '{name}'"),
        };
        mods.push(ModArg {
            name: name.to_string(),
            dynamic,
            spec: spec.clone(),
            err_spec: err.clone(),
            params: params.to_vec(),
            bin: bin.to_string(),
            nbins,
        });
        Ok(())
    };
    while i < args.len() {
        let a = args[i].as_str();
        if !(a.starts_with('-') || a.starts_with('+')) || a == "-" {
            first_file = i;
            files.extend(args[i..].iter().cloned());
            break;
        }
        if a == "-version" {
            println!("fenestra {} rtcontrib", env!("CARGO_PKG_VERSION"));
            return Ok(ExitCode::SUCCESS);
        }
        if a == "-defaults" {
            let pm = |b: bool| if b { '+' } else { '-' };
            let f = |x: InFormat| x.letter();
            let g = match fout {
                Format::Ascii => 'a',
                Format::Float => 'f',
                Format::Double => 'd',
                Format::Rgbe | Format::Xyze => 'c',
            };
            let lines = [
                format!("-c {count:<8}\t\t# accumulated rays per record"),
                format!(
                    "-V{}\t\t\t\t# output {}",
                    pm(value),
                    if value {
                        "contributions"
                    } else {
                        "coefficients"
                    }
                ),
                format!("-n {nproc:<8}\t\t# number of rendering threads"),
                format!("-x {xres:<8}\t\t# x resolution"),
                format!("-y {yres:<8}\t\t# y resolution"),
                format!("-h{}\t\t\t\t# output header", pm(header)),
                format!("-f{}{}\t\t\t\t# format input/output", f(fin), g),
                format!("-w{}\t\t\t\t# warning messages", pm(warnings)),
                format!("-I{}\t\t\t\t# irradiance (point and normal input)", pm(irr)),
                format!("-E{}\t\t\t\t# standard errors (fenestra)", pm(errors)),
                format!(
                    "-v{}\t\t\t\t# report effects, rays and the totals' standard errors (fenestra)",
                    pm(verbose)
                ),
                format!("-Eb {batches:<8}\t\t# replicas per record for -E with -c 1 (fenestra)"),
                format!(
                    "-Er {replicas:<8}\t\t# replica rows written per record, 0: none (fenestra)"
                ),
                format!("-bv{}\t\t\t\t# back face visibility", pm(o.bv)),
                "-dt 0.000000\t\t\t# direct threshold (forced)".to_string(),
                format!("-dc {:.6}\t\t\t# direct certainty (accepted)", o.dc),
                format!("-dj {:.6}\t\t\t# direct jitter", o.dj),
                format!("-ds {:.6}\t\t\t# direct sampling", o.ds),
                format!("-dr {:<8}\t\t# direct relays (accepted)", o.dr),
                format!("-ss {:.6}\t\t\t# specular sampling", o.ss),
                format!("-st {:.6}\t\t\t# specular threshold", o.st),
                format!(
                    "-av {:.6} {:.6} {:.6}\t# ambient value",
                    o.av[0], o.av[1], o.av[2]
                ),
                format!("-ab {:<8}\t\t# ambient bounces", o.ab),
                "-aa 0.000000\t\t\t# ambient accuracy (forced)".to_string(),
                format!("-ad {:<8}\t\t# ambient divisions", o.ad),
                "-as 0\t\t\t\t# ambient super-samples (forced)".to_string(),
                format!("-lr {:<8}\t\t# limit reflection (Russian roulette)", o.lr),
                format!("-lw {:.2e}\t\t\t# limit weight", o.lw),
                format!("-seed {:<8}\t\t# random stream seed (fenestra)", o.seed),
            ];
            for l in lines {
                println!("{l}");
            }
            return Ok(ExitCode::SUCCESS);
        }
        if let Some(v) = toggle(a, "v", verbose) {
            verbose = v;
        } else if let Some(v) = toggle(a, "V", value) {
            value = v;
        } else if let Some(v) = toggle(a, "I", irr) {
            irr = v;
        } else if let Some(v) = toggle(a, "h", header) {
            header = v;
        } else if let Some(v) = toggle(a, "w", warnings) {
            warnings = v;
        } else if let Some(v) = toggle(a, "bv", o.bv) {
            o.bv = v;
        } else if let Some(v) = toggle(a, "fo", overwrite) {
            overwrite = v;
        } else if let Some(v) = toggle(a, "E", errors) {
            errors = v;
        } else if toggle(a, "u", true).is_some() || toggle(a, "dv", true).is_some() {
            // -u: fenestra's random streams are always keyed by the seed and ray index.
        } else if let Some(v) = toggle(a, "i", irr_hit) {
            irr_hit = v;
        } else if let Some(v) = toggle(a, "ld", limit_dist) {
            limit_dist = v;
        } else if let Some(v) = toggle(a, "r", recover) {
            recover = v;
        } else if a == "-f" {
            defs.push_file(word(&args, i + 1)?)?;
            i += 1;
        } else if let Some(f) = a.strip_prefix("-f") {
            let c: Vec<char> = f.chars().collect();
            if c.len() > 2 {
                bail!("Illegal i/o format '{a}'");
            }
            fin = match InFormat::from_letter(c[0]) {
                Some(f) => f,
                None => bail!("Illegal i/o format '{a}' (input: a, f, d)"),
            };
            fout = fenestra_contrib::output::format_of(*c.get(1).unwrap_or(&c[0]), true)?;
        } else {
            let name = &a[1..];
            match name {
                n if fenestra_trace::TraceOptions::is_number_option(n) => {
                    o.set_number(n, num(&args, i + 1)?);
                }
                "n" => nproc = fenestra_cli::threads::worker_count(num(&args, i + 1)?)?,
                "c" => count = num(&args, i + 1)?.max(0.0) as usize,
                "x" => xres = num(&args, i + 1)?.max(0.0) as usize,
                "y" => yres = num(&args, i + 1)?.max(0.0) as usize,
                "t" => {
                    num(&args, i + 1)?;
                }
                "o" => cur_spec = Some(Spec::parse(word(&args, i + 1)?)?),
                "Eo" => cur_err = Some(Spec::parse(word(&args, i + 1)?)?),
                "Eb" => batches = (num(&args, i + 1)?.max(2.0)) as usize,
                "Er" => {
                    let k = num(&args, i + 1)?;
                    if !(2.0..=4096.0).contains(&k) || k.fract() != 0.0 {
                        bail!("-Er: the number of replicas must be a whole number from 2 to 4096, not {k}");
                    }
                    replicas = k as usize;
                }
                "p" => {
                    cur_params = parse_params(word(&args, i + 1)?)?;
                    defs.push_params(&cur_params);
                }
                "e" => defs.push_expr(word(&args, i + 1)?)?,
                "b" => cur_bin = word(&args, i + 1)?.to_string(),
                "bn" => {
                    let w = word(&args, i + 1)?;
                    let v = defs
                        .eval_now(w)
                        .with_context(|| format!("-bn {w} (definitions must come before -bn)"))?;
                    // memory is taken per bin (sums, errors, output items): a count no
                    // run could hold is refused at once, as Radiance's allocation fails
                    if v + 0.5 > MAX_BINS as f64 {
                        bail!("-bn {w}: {v} bins are more than the {MAX_BINS} a modifier may have");
                    }
                    cur_nbins = if v + 0.5 >= 1.0 {
                        Some((v + 0.5) as usize)
                    } else {
                        Some(0)
                    };
                }
                "m" => add_mod(
                    word(&args, i + 1)?,
                    &mut mods,
                    &cur_spec,
                    &cur_err,
                    &cur_params,
                    &cur_bin,
                    cur_nbins,
                )?,
                "M" => {
                    let f = word(&args, i + 1)?;
                    let path = fenestra_cli::raypath::find_or_err(f)?;
                    let text = std::fs::read_to_string(&path).with_context(|| {
                        format!("cannot read modifier file '{}'", path.display())
                    })?;
                    for m in text.split_whitespace() {
                        add_mod(
                            m,
                            &mut mods,
                            &cur_spec,
                            &cur_err,
                            &cur_params,
                            &cur_bin,
                            cur_nbins,
                        )?;
                    }
                }
                "dt" | "dp" | "aa" | "ar" | "as" | "aw" | "mg" | "ms" => {
                    // -dt, -as and -aa are forced to 0 by rcontrib; the others do not apply.
                    num(&args, i + 1)?;
                }
                "af" | "ai" | "ae" | "aI" | "aE" => {
                    word(&args, i + 1)?;
                }
                "av" | "me" | "ma" => {
                    let v = [num(&args, i + 1)?, num(&args, i + 2)?, num(&args, i + 3)?];
                    if name == "av" {
                        o.av = v;
                    } else if v.iter().any(|&x| x != 0.0) {
                        bail!("participating media (-{name}) are not supported by fenestra's rtcontrib");
                    }
                    i += 2;
                }
                "cs" => {
                    if num(&args, i + 1)? != 3.0 {
                        bail!("-cs: only 3 colour samples (RGB) are supported by fenestra");
                    }
                }
                "cw" => {
                    num(&args, i + 1)?;
                    num(&args, i + 2)?;
                    i += 1;
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
    if mods.is_empty() {
        bail!("missing required modifier argument");
    }
    if files.is_empty() && preloaded.is_none() {
        bail!(
            "missing scene file\nusage: {} {USAGE}",
            fenestra_cli::prog()
        );
    }
    o.dt = 0.0;
    if count == 0 {
        xres = 0;
        yres = 0;
    }

    let refs: Vec<&str> = files.iter().map(String::as_str).collect();
    let mut scene_lines = Vec::new();
    let scene = match preloaded {
        Some(p) => {
            scene_lines = p.header;
            p.scene
        }
        None => fenestra_scene::load(&refs)?,
    };
    if files.len() == 1 && files[0] != "-" {
        if let Ok(bytes) = std::fs::read(&files[0]) {
            if fenestra_scene::compiled::is_compiled(&bytes) {
                scene_lines = fenestra_scene::compiled::read(&bytes)?.header;
            }
        }
    }
    let tracer = Tracer::new(&scene, &o)?;
    if warnings {
        for w in tracer.warnings() {
            fenestra_cli::warn(w);
        }
        if !tracer.emits() {
            fenestra_cli::warn("no light sources found (nothing in the scene emits light)");
        }
    }
    let mut tracked = Vec::new();
    for m in &mods {
        let scene_mods: Vec<usize> = scene
            .prims
            .iter()
            .enumerate()
            .filter(|(_, p)| p.name == m.name && !p.is_surface())
            .map(|(k, _)| k)
            .collect();
        if scene_mods.is_empty() && warnings {
            fenestra_cli::warn(format!(
                "modifier '{}' is not in the scene (its values are zero)",
                m.name
            ));
        }
        tracked.push(Tracked {
            scene_mods,
            nbins: m.nbins,
        });
    }
    let reqs: Vec<BinRequest> = mods
        .iter()
        .map(|m| BinRequest {
            expr: &m.bin,
            params: &m.params,
        })
        .collect();
    let bins = Bins::compile(&defs, &reqs)?;
    let dynamic = mods.iter().any(|m| m.dynamic);
    if irr && irr_hit {
        bail!("options -I and -i are mutually exclusive");
    }
    // -ld+ (not with -I, which ignores the length as Radiance does)
    let limit = limit_dist && !irr;
    if replicas > 0 {
        if !errors {
            bail!("-Er writes replicas beside the standard errors: give -E too");
        }
        if count == 0 {
            bail!("-Er with -c 0: the single sum has no replicas (give -c N)");
        }
        if count > 1 && count < replicas {
            bail!(
                "-Er {replicas}: each replica needs at least one of the record's rays (-c {count})"
            );
        }
        if recover {
            bail!("-Er with -r: replicas cannot be continued from an interrupted run");
        }
        if xres > 0 && yres > 0 {
            bail!("-Er: pictures have no replicas (give -x 0 or -y 0)");
        }
    }

    // Input.
    let expect = if yres > 0 {
        Some(yres * xres.max(1) * count.max(1))
    } else {
        None
    };
    let mut input = RayInput::new(rays, fin);
    // Rays are read as they are traced (records stream out, flushed where Radiance
    // flushes), except where the whole input is needed first: bins found by a first pass
    // (rtcontrib without -bn) and the single sum of -c 0.
    let buffered = dynamic || count == 0;
    let rays: Vec<InputRay> = if buffered {
        input.read_all(expect)?
    } else {
        Vec::new()
    };
    let pool = fenestra_cli::threads::pool(nproc)?;

    let opts = RunOptions {
        irradiance_at_hit: irr_hit,
        limit_dist: limit,
        irradiance: irr,
        value,
        count,
        errors,
        batches,
        replicas,
    };
    // rtcontrib without -bn: a first pass over the input finds the bins each such
    // modifier reaches
    if dynamic {
        let flags: Vec<bool> = mods.iter().map(|m| m.dynamic).collect();
        let cx = contrib_run::Context {
            tracer: &tracer,
            bins: &bins,
            nprims: scene.prims.len(),
            pool: &pool,
        };
        contrib_run::probe_bins(&cx, &mut tracked, &flags, &rays, &opts)?;
        for (m, t) in mods.iter_mut().zip(&tracked) {
            m.nbins = t.nbins;
        }
    }

    // Output streams.
    let picture = xres > 0 && yres > 0;
    let outs: Vec<ModOut> = mods
        .iter()
        .map(|m| ModOut {
            name: &m.name,
            spec: m.spec.as_ref(),
            nbins: m.nbins,
        })
        .collect();
    let plans = output::plan(&outs, picture);
    let mut err_specs = Vec::new();
    if errors {
        for m in &mods {
            let s = match (&m.err_spec, &m.spec) {
                (Some(e), _) => e.clone(),
                (None, Some(s)) if !s.text.starts_with('!') => {
                    Spec::parse(&format!("{}.err", s.text))?
                }
                _ => bail!(
                    "-E: the values of modifier '{}' go to {}; name the file of their standard errors with -Eo spec (before -m)",
                    m.name,
                    if m.spec.is_some() { "a command" } else { "the standard output" }
                ),
            };
            err_specs.push(s);
        }
    }
    let err_outs: Vec<ModOut> = mods
        .iter()
        .zip(&err_specs)
        .map(|(m, s)| ModOut {
            name: &m.name,
            spec: Some(s),
            nbins: m.nbins,
        })
        .collect();
    let err_plans = if errors {
        output::plan(&err_outs, picture)
    } else {
        Vec::new()
    };
    // -Er: replicas go beside each error file, its name ending .rep instead of .err
    let rep_specs: Vec<Spec> = if replicas > 0 {
        err_specs
            .iter()
            .map(|e| {
                if e.text.starts_with('!') {
                    bail!("-Er: replicas are written to files; the standard errors go to a command ({})", e.text);
                }
                let base = e.text.strip_suffix(".err").unwrap_or(&e.text);
                Spec::parse(&format!("{base}.rep"))
            })
            .collect::<Result<_>>()?
    } else {
        Vec::new()
    };
    let rep_outs: Vec<ModOut> = mods
        .iter()
        .zip(&rep_specs)
        .map(|(m, s)| ModOut {
            name: &m.name,
            spec: Some(s),
            nbins: m.nbins,
        })
        .collect();
    let rep_plans = output::plan(&rep_outs, false);
    if recover && overwrite {
        bail!("options -r and -fo are mutually exclusive");
    }
    // -r with -c 0: the sums earlier runs wrote are added to this run's (progressive runs)
    let reload = recover && count == 0;
    if reload && errors {
        bail!("-E with -r -c 0: standard errors cannot be continued from the written sums");
    }
    let mut previous: Vec<Option<Vec<[f64; 3]>>> = Vec::new();
    if reload {
        for p in &plans {
            let prev = output::reload_sums(p)?;
            if prev.is_none() && warnings {
                if let Some(n) = p.name.as_deref().filter(|n| !n.starts_with('!')) {
                    fenestra_cli::warn(format!("missing reload file '{n}'"));
                }
            }
            previous.push(prev);
        }
    }
    // -r: what the interrupted run left (per stream), and the records all of them hold
    let mut parts: Vec<Option<output::Partial>> = Vec::new();
    let mut done_records = 0u64;
    if recover && !reload {
        for p in plans.iter().chain(&err_plans) {
            parts.push(output::examine_partial(p, fout)?);
        }
        if parts.iter().all(|p| p.is_some_and(|p| p.complete)) {
            if warnings {
                fenestra_cli::warn("output appears to be complete");
            }
            return Ok(ExitCode::SUCCESS);
        }
        done_records = parts
            .iter()
            .map(|p| p.map_or(0, |p| p.records))
            .min()
            .unwrap_or(0);
    } else if !reload {
        output::check_files(&plans, overwrite)?;
        output::check_files(&err_plans, overwrite)?;
        output::check_files(&rep_plans, overwrite)?;
    }
    for p in err_plans.iter().chain(&rep_plans) {
        if plans
            .iter()
            .chain(&err_plans)
            .any(|q| q.name == p.name && !std::ptr::eq(p, q))
        {
            bail!(
                "-E: the standard errors or replicas would go to '{}', which also receives other values",
                p.name.as_deref().unwrap_or("standard output")
            );
        }
    }

    let info = HeaderInfo {
        scene_lines,
        command: fenestra_cli::command_line(&args[..first_file]),
        xres,
        yres,
        format: fout,
        header,
        extra: Vec::new(),
    };
    let mut err_info = info.clone();
    err_info.extra = vec!["CONTENTS= Monte Carlo standard error (1 sigma) of each value".into()];
    let mut rep_info = info.clone();
    rep_info.extra = vec![
        format!("CONTENTS= {replicas} independent replica estimates per record, one row each; their mean is the value"),
        format!("NREPLICAS={replicas}"),
    ];
    let nplans = plans.len();
    let open = |k: usize, p: output::StreamPlan, info: &HeaderInfo| -> Result<Stream> {
        match parts.get(k).copied().flatten() {
            Some(part) => Stream::resume(p, &part, done_records, fout),
            None => Stream::open(p, info),
        }
    };
    let values: Vec<Stream> = plans
        .into_iter()
        .enumerate()
        .map(|(k, p)| open(k, p, &info))
        .collect::<Result<_>>()?;
    let err_streams: Vec<Stream> = err_plans
        .into_iter()
        .enumerate()
        .map(|(k, p)| open(nplans + k, p, &err_info))
        .collect::<Result<_>>()?;
    let rep_streams: Vec<Stream> = rep_plans
        .into_iter()
        .map(|p| Stream::open(p, &rep_info))
        .collect::<Result<_>>()?;
    let mut out = contrib_run::Outputs {
        values,
        errors: err_streams,
        replicas: rep_streams,
        format: fout,
        budget: Default::default(),
    };

    let engine = Engine::new(&tracer, &bins, scene.prims.len(), &tracked, opts);
    let progress = fenestra_cli::progress::Progress::new(
        expect.unwrap_or(rays.len()) as u64,
        fenestra_cli::prog(),
    );
    let inc = |n: u64| progress.inc(n);
    let mut total_rays = rays.len();
    let mut partial = false;
    if count == 0 {
        if warnings && rays.iter().any(|r| r.dir == fenestra_trace::DVec3::ZERO) {
            fenestra_cli::warn("dummy ray(s) ignored during accumulation");
        }
        contrib_run::sum_run(&engine, &rays, &previous, &pool, &mut out, &inc)?;
    } else if buffered {
        partial = contrib_run::buffered_run(
            &engine,
            &rays,
            count,
            done_records as usize,
            &pool,
            &mut out,
            &inc,
        )?;
    } else {
        let plan = contrib_run::StreamPlan {
            count,
            flush_every: if yres > 0 && xres > 1 { 0 } else { xres },
            expect,
            skip_records: done_records as usize,
        };
        let end = contrib_run::streamed_run(&engine, &mut input, plan, &pool, &mut out, &inc)?;
        total_rays = end.rays;
        partial = end.partial;
    }
    progress.finish();
    if partial && warnings {
        fenestra_cli::warn("partial accumulation in final record");
    }
    if warnings {
        for (_, b) in engine.take_bad_bins() {
            fenestra_cli::warn(format!("bad bin number ({b} ignored)"));
        }
    }
    let budget = std::mem::take(&mut out.budget);
    out.finish()?;
    for msg in input.take_warnings() {
        fenestra_cli::warn(msg);
    }
    if verbose {
        let names: Vec<String> = mods.iter().map(|m| m.name.clone()).collect();
        let secs = started.elapsed().as_secs_f64();
        for l in budget.lines(&names, tracer.ray_counts(), secs, tracer.effects()) {
            eprintln!("{}: {l}", fenestra_cli::prog());
        }
        if let Some(m) = fenestra_cli::peak_memory_line() {
            eprintln!("{}: {m}", fenestra_cli::prog());
        }
    }
    if let Some(e) = expect {
        if total_rays < e {
            bail!("unexpected EOF on input");
        }
    }
    Ok(ExitCode::SUCCESS)
}
