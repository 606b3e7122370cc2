//! `oconv`: compile scene files (.rad, .mgf) into fenestra's compiled-scene format.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_cli::opts::{Kind, Opt, Spec};
use fenestra_scene::{compiled, Parser};

fn spec() -> Spec {
    Spec::new(
        "oconv",
        "compile Radiance scene files (.rad, .mgf) into a fenestra compiled scene on stdout",
    )
    .usage("[-i scene.oct] [-f] [-w] [-n objlim] [-r maxres] [-b xmin ymin zmin size] file.rad … > scene.oct")
    .opts([
        Opt::new(
            "i",
            Kind::Word,
            "start from this compiled scene (fenestra oconv output)",
        ),
        Opt::new(
            "f",
            Kind::Flag,
            "accepted for compatibility (the whole scene is always stored)",
        ),
        Opt::new(
            "w",
            Kind::Flag,
            "accepted for compatibility (no warnings are issued)",
        ),
        Opt::new(
            "n",
            Kind::Int,
            "accepted for compatibility (octree leaf limit; unused)",
        ),
        Opt::new(
            "r",
            Kind::Int,
            "accepted for compatibility (octree resolution; unused)",
        ),
        Opt::new(
            "b",
            Kind::Words(4),
            "accepted for compatibility (octree bounds; unused)",
        ),
    ])
}

/// Runs oconv.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let (hits, files) = spec().parse_apart(&args)?;
    let mut parser = Parser::new();
    let mut inputs = Vec::new();
    for o in hits.iter().filter(|o| o.key == "i") {
        let path = o.word();
        let head = std::fs::read(path).with_context(|| format!("cannot open octree '{path}'"))?;
        if fenestra_scene::compiled::is_radiance_octree(&head) {
            // Radiance's octree: its objects (or files) through the scene reader
            parser.add_path(path)?;
            inputs.push(path.to_string());
        } else {
            let c = compiled::read(&head).with_context(|| path.to_string())?;
            inputs.extend(c.inputs);
            parser.add_scene(c.scene)?;
        }
    }
    for p in &files {
        parser.add_path(p)?;
        inputs.push(p.clone());
    }
    if inputs.is_empty() {
        bail!("no scene files given (usage: oconv file.rad … > scene.oct)");
    }
    let scene = parser.finish();
    // the tracer's own geometry rules: what rtrace would refuse is refused here, what it
    // would ignore is reported here
    for p in &scene.prims {
        if p.modifier.is_some() && fenestra_trace::surface::is_geometry(&p.ptype) {
            match fenestra_trace::surface::shape_of(p)? {
                fenestra_trace::surface::Built::Shape(_, Some(w))
                | fenestra_trace::surface::Built::Ignored(w) => fenestra_cli::warn(w),
                fenestra_trace::surface::Built::Shape(_, None) => {}
            }
        }
    }
    let mut buf = Vec::new();
    compiled::write(
        &mut buf,
        &scene,
        &inputs,
        &fenestra_cli::command_line(&args),
        &[],
    )?;
    let mut out = std::io::stdout().lock();
    out.write_all(&buf)
        .context("cannot write the compiled scene")?;
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
