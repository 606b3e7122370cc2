//! `xform`: transform a Radiance scene description (Radiance's xform command line).

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;
use fenestra_scene::xform::{xform_files, XformOptions};

const HELP: &str = "xform - transform a Radiance scene description

Usage: xform [-c|-e] [-I] [-n name] [-m mod] [transform] [file.rad ...]

Options (before the transform):
  -c          keep !command lines as commands (piped through xform -e)
  -e          expand !command lines (default)
  -I          invert surfaces (sphere<->bubble, cone<->cup, cylinder<->tube,
              polygon vertex order, ring normal)
  -n name     prefix surface identifiers with 'name.'
  -m mod      use modifier 'mod' for every surface
Transform (applied in the order given):
  -t dx dy dz   translate          -rx|-ry|-rz deg   rotate (right-hand rule)
  -s f          scale              -mx|-my|-mz       mirror
  -i N          repeat the following options N times
  -a N          array: N copies, copy k gets the following options k times
Reads standard input when no file is given; writes standard output.
";

/// Runs xform.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    if args.iter().skip(1).any(|a| a == "--help") {
        print!("{HELP}");
        return Ok(ExitCode::SUCCESS);
    }
    let (opts, files) = XformOptions::parse(&args)?;
    let mut so = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
    xform_files(&opts, &files, &mut so)?;
    so.flush()?;
    Ok(ExitCode::SUCCESS)
}
