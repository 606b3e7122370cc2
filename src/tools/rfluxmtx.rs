//! rfluxmtx: flux-transfer matrices between a sender and receivers marked with
//! `#@rfluxmtx` directives. As Radiance's, it screens the options, turns the receivers
//! into rcontrib's bin options and generates the sender's sample rays; unlike Radiance's,
//! the contribution engine runs in this process on the scene loaded here (no rcontrib
//! child, no pipe, no oconv command line, no argument limits).

use std::io::BufRead;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_contrib::rflux::{receiver, surfaces, RayStream, Sampler};

const USAGE: &str = "[-v][-bj frac][rcontrib options] {sender.rad | -} receivers.rad [-i system.oct] [system.rad ..]";

fn usage(bad: Option<&str>) -> anyhow::Error {
    match bad {
        Some(a) => anyhow::anyhow!(
            "unsupported option '{a}'\nusage: {} {USAGE}",
            fenestra_cli::prog()
        ),
        None => anyhow::anyhow!("usage: {} {USAGE}", fenestra_cli::prog()),
    }
}

/// Options screened from the command line.
#[derive(Default)]
struct Screened {
    verbose: bool,
    warnings: bool,
    passed: Vec<String>,
    fmt: (char, char),
    xres: Option<String>,
    yres: Option<String>,
    ld: Option<String>,
    irr: Option<String>,
    count: Option<usize>,
    jitter: Option<String>,
    seed: u64,
}

/// How many words (the option included) an option rcontrib takes passes on; `None` for
/// options rfluxmtx refuses.
fn pass_words(a: &str) -> Option<usize> {
    let b = a.as_bytes();
    let c2 = b.get(2).copied();
    Some(match b[1] {
        b'V' | b'u' | b'h' | b'r' | b'w' => 1,
        b'n' | b's' | b'o' | b't' | b'e' => 2,
        b'b' if c2 == Some(b'v') => 1,
        b'l' => 2,
        b'd' => {
            if c2 == Some(b'v') {
                1
            } else {
                2
            }
        }
        b'a' => {
            if c2 == Some(b'v') {
                4
            } else if c2 == Some(b'p') {
                return None;
            } else {
                2
            }
        }
        b'm' if c2.is_some() => {
            if matches!(c2, Some(b'e') | Some(b'a')) {
                4
            } else {
                2
            }
        }
        // fenestra's standard errors: -E, -Eo spec, -Eb N
        b'E' => match &a[2..] {
            "" | "+" | "-" => 1,
            "o" | "b" => 2,
            _ => return None,
        },
        _ => return None,
    })
}

fn screen(args: &[String]) -> Result<(Screened, usize)> {
    let mut s = Screened {
        warnings: true,
        fmt: ('a', 'a'),
        ..Default::default()
    };
    let mut a = 1;
    while a + 2 < args.len() {
        let w = args[a].as_str();
        if !w.starts_with('-') || w.len() < 2 {
            break;
        }
        let b = w.as_bytes();
        let need = |k: usize| -> Result<&String> {
            args.get(a + k)
                .with_context(|| format!("option {w} needs a value"))
        };
        match b[1] {
            b'v' if w == "-v" => {
                s.verbose = !s.verbose;
                a += 1;
                continue;
            }
            b'f' => match b.get(2) {
                None => {
                    s.passed.push(w.into());
                    s.passed.push(need(1)?.clone());
                    a += 2;
                    continue;
                }
                Some(&c @ (b'a' | b'f' | b'd' | b'c')) if b.len() <= 4 => {
                    let o = b.get(3).copied().unwrap_or(c);
                    if !matches!(o, b'a' | b'f' | b'd' | b'c') || c == b'c' && b.len() == 4 {
                        return Err(usage(Some(w)));
                    }
                    s.fmt = (c as char, o as char);
                    a += 1;
                    continue;
                }
                _ => return Err(usage(Some(w))),
            },
            b'x' if w == "-x" => {
                s.xres = Some(need(1)?.clone());
                a += 2;
                continue;
            }
            b'y' if w == "-y" => {
                s.yres = Some(need(1)?.clone());
                a += 2;
                continue;
            }
            b'c' => match &w[2..] {
                "" => {
                    let v = need(1)?;
                    match v.trim().parse::<i64>() {
                        Ok(n) if n > 0 => s.count = Some(n as usize),
                        _ => bail!("-c {v}: the sample count must be a positive integer"),
                    }
                    a += 2;
                    continue;
                }
                "s" | "w" => {
                    let n = if w == "-cs" { 2 } else { 3 };
                    for k in 0..n {
                        s.passed
                            .push(args.get(a + k).context("-cs/-cw need values")?.clone());
                    }
                    a += n;
                    continue;
                }
                _ => return Err(usage(Some(w))),
            },
            b'I' | b'i' => {
                s.irr = Some(w.into());
                a += 1;
                continue;
            }
            b'b' if w == "-bj" => {
                let v = need(1)?;
                if fenestra_cli::opts::parse_real(v).is_none() {
                    bail!("-bj {v}: expected a number (the bin jitter, 0..1)");
                }
                s.jitter = Some(v.clone());
                a += 2;
                continue;
            }
            b'l' if b.get(2) == Some(&b'd') => {
                s.ld = Some(w.into());
                a += 1;
                continue;
            }
            b'w' => {
                s.warnings = match b.get(2) {
                    None => !s.warnings,
                    Some(c) => b"+1tTyY".contains(c),
                };
            }
            _ => {}
        }
        let Some(n) = pass_words(w) else {
            return Err(usage(Some(w)));
        };
        if w == "-seed" {
            s.seed = need(1)?
                .trim()
                .parse()
                .with_context(|| format!("-seed {}: expected an integer", args[a + 1]))?;
        }
        for k in 0..n {
            s.passed.push(
                args.get(a + k)
                    .with_context(|| format!("option {w} needs {} value(s)", n - 1))?
                    .clone(),
            );
        }
        a += n;
    }
    if a + 2 > args.len() {
        return Err(usage(None));
    }
    Ok((s, a))
}

/// Loads the system files (with oconv's `-i octree`) and the receivers, receivers last.
fn load_scene(system: &[String], receivers: &str) -> Result<fenestra_scene::Scene> {
    let mut p = fenestra_scene::Parser::new();
    let mut k = 0;
    while k < system.len() {
        let f = system[k].as_str();
        if f == "-i" {
            let oct = system
                .get(k + 1)
                .context("-i needs an octree (rfluxmtx … receivers.rad -i system.oct)")?;
            p.add_path(oct)?;
            k += 2;
            continue;
        }
        if f.starts_with('-') && f != "-" {
            bail!("'{f}': only -i octree may come among the system files");
        }
        p.add_path(f)?;
        k += 1;
    }
    if let Some(cmd) = receivers.strip_prefix('!') {
        let out = fenestra_cfmt::sh_c(cmd)
            .stderr(std::process::Stdio::inherit())
            .output()
            .with_context(|| format!("cannot run '{cmd}'"))?;
        if !out.status.success() {
            bail!("error loading '{receivers}'");
        }
        p.add_str(&String::from_utf8_lossy(&out.stdout), receivers)?;
    } else {
        p.add_path(receivers)?;
    }
    Ok(p.finish())
}

/// Runs rfluxmtx.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    if fenestra_cli::help_asked(&args, USAGE, "Computes the flux-transfer matrix from a sender (or rays on standard input with '-') to the receivers marked with #@rfluxmtx directives (h=u|kf|kh|kq|rN|scN|cie, u=, o=).\nOptions:\n  -v          the equivalent rcontrib command, sender directions, and at the end the run's budget\n  -bj frac    bin jitter: ,JTR=frac appended to every receiver's -p parameters\n  -i oct      the system scene as an octree\n  -c N        rays per sender bin (default 10000);  -n N  threads\n  -I / -i     rays on standard input are points and normals (with sender '-')\n  -f{a,f,d}{a,f,d,c}, -o spec, -x X -y Y, -E, -Er K, -ab -ad -lw .. as rcontrib's (docs/tools/rtcontrib.md)\nFull documentation: fenestra doc rfluxmtx (docs/tools/rfluxmtx.md in the source).") {
        return Ok(ExitCode::SUCCESS);
    }
    let (s, a) = screen(&args)?;
    let sender_spec = args[a].as_str();
    let receivers_spec = args[a + 1].as_str();
    let system = &args[a + 2..];
    let passthrough = sender_spec == "-";
    if sender_spec.starts_with('-') && !passthrough {
        return Err(usage(Some(sender_spec)));
    }
    let mut rc: Vec<String> = vec!["rcontrib".into(), "-fo+".into()];
    rc.extend(s.passed.iter().cloned());
    let count;
    let mut fmt = s.fmt;
    if passthrough {
        if let Some(i) = &s.irr {
            rc.push(i.clone());
        }
        if let Some(x) = &s.xres {
            rc.push("-x".into());
            rc.push(x.clone());
        }
        if let Some(y) = &s.yres {
            rc.push("-y".into());
            rc.push(y.clone());
        }
        if let Some(l) = &s.ld {
            rc.push(l.clone());
        }
        count = s.count.unwrap_or(1);
    } else {
        if s.irr.is_some() {
            bail!("-i, -I supported for pass-through only");
        }
        fmt.0 = 'd';
        count = s.count.unwrap_or(10_000);
    }
    rc.push(format!("-f{}{}", fmt.0, fmt.1));
    rc.push("-c".into());
    rc.push(count.to_string());
    let mut warnings = Vec::new();
    let groups = surfaces::receivers(receivers_spec, &mut warnings)?;
    let mut cals = receiver::CalFiles::default();
    for g in &groups {
        receiver::push_args(g, s.jitter.as_deref(), &mut cals, &mut rc)?;
    }
    let input: Box<dyn BufRead>;
    let mut sampled = None;
    if passthrough {
        input = Box::new(std::io::BufReader::with_capacity(
            1 << 16,
            std::io::stdin().lock(),
        ));
    } else {
        let sender = surfaces::sender(sender_spec, &mut warnings)?;
        if sender.params.out.is_some() {
            warnings.push(format!(
                "ignoring output file in sender ('{}')",
                sender.params.out.as_deref().unwrap_or_default()
            ));
        }
        let sampler = Sampler::new(&sender, count, s.seed)?;
        rc.push("-y".into());
        rc.push(sampler.bins().to_string());
        sampled = Some((sampler.bins(), sampler.surfaces()));
        input = Box::new(std::io::BufReader::with_capacity(
            1 << 16,
            RayStream::new(sampler),
        ));
    }
    if s.warnings {
        for w in &warnings {
            fenestra_cli::warn(w);
        }
    }
    if s.verbose {
        let mut line = fenestra_cli::command_line(&rc);
        line.push_str(" [scene:");
        for f in system {
            line.push(' ');
            line.push_str(f);
        }
        line.push(' ');
        line.push_str(receivers_spec);
        line.push(']');
        eprintln!("{line}");
        if let Some((n, m)) = sampled {
            if m > 1 {
                eprintln!(
                    "{}: sampling {n} directions ({m} elements)",
                    fenestra_cli::prog()
                );
            } else {
                eprintln!("{}: sampling {n} directions", fenestra_cli::prog());
            }
        }
    }
    // -v: the engine's budget at the end too (effects, rays by kind, totals' errors)
    if s.verbose {
        rc.insert(1, "-v".to_string());
    }
    let scene = super::rtcontrib::Preloaded {
        scene: load_scene(system, receivers_spec)?,
        header: vec![fenestra_cli::command_line(&args)],
    };
    super::rtcontrib::run_with(rc, input, Some(scene))
}
