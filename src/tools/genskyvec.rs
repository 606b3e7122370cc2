//! genskyvec: Reinhart sky vector of a gensky/gendaylit sky description.

use anyhow::{anyhow, bail, Context, Result};
use fenestra_cli::opts::{Kind, Opt, Spec};
use fenestra_scene::{Parser, Primitive};
use fenestra_sky::cie::SkyBright;
use fenestra_sky::daymtx::fmt_g;
use fenestra_sky::patches::Reinhart;
use fenestra_sky::skyvec::{self, PerezLum, Row, SkyVecOptions, Sun};
use std::io::{Read, Write};
use std::process::ExitCode;

/// The sky function of a description: gensky's and gendaylit's natively, any other
/// brightfunc through the .cal engine.
fn sky_function(p: &Primitive) -> Result<Box<dyn Fn([f64; 3]) -> f64 + Sync>> {
    let a = p.rargs.clone();
    if p.ptype != "brightfunc" {
        bail!(
            "skyfunc is a '{}'; fenestra genskyvec evaluates brightfunc skies only",
            p.ptype
        );
    }
    let file = p
        .sargs
        .get(1)
        .map(|s| s.rsplit('/').next().unwrap_or(s).to_string())
        .unwrap_or_default();
    let func = p.sargs.first().cloned().unwrap_or_default();
    if p.sargs.len() != 2 {
        bail!(
            "skyfunc: transforms after the function file are not supported by fenestra genskyvec"
        );
    }
    match (func.as_str(), file.as_str()) {
        ("skybr", "skybright.cal") => {
            let m = SkyBright::from_args(&a)
                .ok_or_else(|| anyhow!("skyfunc: bad skybright.cal arguments {:?}", p.rargs))?;
            Ok(Box::new(move |d| m.radiance(d)))
        }
        ("skybright", "perezlum.cal") => {
            let m = PerezLum::from_args(&a)
                .ok_or_else(|| anyhow!("skyfunc: perezlum.cal needs 10 real arguments"))?;
            Ok(Box::new(move |d| m.radiance(d)))
        }
        _ => {
            // Any other sky function: through the .cal engine, as Radiance's genskyvec
            // has rtrace evaluate it (rayinit.cal first; a distant glow: N = -D).
            let cal = p.sargs[1].clone();
            let pat = fenestra_trace::pattern::CalPattern::new(
                &[func],
                &cal,
                &a,
                None,
                &p.name,
                &[],
                &fenestra_cli::raypath::Resolver::from_env(),
            )
            .with_context(|| format!("skyfunc '{}' ({cal})", p.name))?;
            Ok(Box::new(move |d| {
                let dir = glam::DVec3::from_array(d);
                let q = fenestra_trace::pattern::PatternInput {
                    dir,
                    point: glam::DVec3::ZERO,
                    normal: -dir,
                    dist: 1e10,
                };
                pat.value(&q).map(|v| v.x).unwrap_or(0.0)
            }))
        }
    }
}

fn spec() -> Spec {
    Spec::new(
        "genskyvec",
        "Reinhart sky vector (ground first) of a sky description (gensky, gendaylit) on standard input",
    )
    .usage("[-h][-m N][-c r g b][-d][-5] < sky.rad")
    .opts([
        Opt::new(
            "m",
            Kind::Int,
            "Reinhart subdivision: 146, 578, 2306 rows for 1, 2, 4 (default 4: match D's -m/MF!)",
        ),
        Opt::new(
            "c",
            Kind::Vec3,
            "sky colour r g b (default 0.960 1.004 1.118)",
        ),
        Opt::new("d", Kind::Flag, "sun only (sky patches zero)"),
        Opt::new(
            "5",
            Kind::Flag,
            "five-phase: the sun into its single nearest patch",
        ),
        Opt::new("h", Kind::Flag, "no header"),
    ])
}

/// Runs genskyvec.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let mut opt = SkyVecOptions::default();
    let mut header = true;
    let (hits, words) = spec().parse_apart(&args)?;
    for o in &hits {
        match o.key {
            "c" => opt.color = o.vec3(),
            "m" => {
                opt.mf =
                    o.positive_int(|v| format!("-m needs a positive integer, got {v}"))? as usize;
            }
            "d" => opt.sky = false,
            "h" => header = false,
            "5" => opt.five_phase = true,
            _ => {}
        }
    }
    if let Some(w) = words.first() {
        bail!("Unexpected command-line argument: {w}");
    }
    let mut text = String::new();
    std::io::stdin()
        .read_to_string(&mut text)
        .context("reading the sky description")?;
    // the scene crate's parser, keeping the real arguments as written (the sun's
    // radiance is printed back verbatim)
    let mut parser = Parser::keeping_real_words();
    parser.add_str(&text, "<stdin>")?;
    let (scene, words) = parser.finish_with_words();
    let prims = &scene.prims;
    let Some(skyfunc) = prims.iter().rev().find(|p| p.name == "skyfunc") else {
        bail!("Bad sky description!");
    };
    let f = sky_function(skyfunc)?;
    // the sun: a 'source' whose modifier is a 'light'
    let mut sun = None;
    for p in prims {
        if p.ptype != "source" {
            continue;
        }
        let Some(m) = p.modifier.filter(|&m| prims[m].ptype == "light") else {
            continue;
        };
        let (l, lw) = (&prims[m], &words[m]);
        if l.rargs.len() < 3 || p.rargs.len() < 4 || lw.len() < 3 {
            bail!(
                "sun '{}': light needs 3 and source 4 real arguments",
                p.name
            );
        }
        sun = Some(Sun {
            radiance: [l.rargs[0], l.rargs[1], l.rargs[2]],
            radiance_words: [lw[0].clone(), lw[1].clone(), lw[2].clone()],
            dir: [p.rargs[0], p.rargs[1], p.rargs[2]],
            diameter: p.rargs[3],
        });
    }
    let rows = skyvec::sky_vector(&opt, &*f, sun.as_ref());
    let mut out = String::new();
    if header {
        out.push_str("#?RADIANCE\n");
        out.push_str(&fenestra_cli::command_line(&args));
        out.push('\n');
        out.push_str(&format!(
            "NROWS={}\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n",
            Reinhart::new(opt.mf).len()
        ));
    }
    for r in &rows {
        match r {
            Row::Mean(v) => out.push_str(&format!(
                "{}\t{}\t{}\n",
                fmt_g(v[0], 9),
                fmt_g(v[1], 9),
                fmt_g(v[2], 9)
            )),
            Row::WithSun(v) => out.push_str(&format!(
                "{}\t{}\t{}\n",
                fmt_g(v[0], 15),
                fmt_g(v[1], 15),
                fmt_g(v[2], 15)
            )),
            Row::Words(w) => out.push_str(&format!("{}\t{}\t{}\n", w[0], w[1], w[2])),
        }
    }
    std::io::stdout().lock().write_all(out.as_bytes())?;
    Ok(ExitCode::SUCCESS)
}
