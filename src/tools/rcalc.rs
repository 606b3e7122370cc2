//! rcalc: evaluates .cal definitions on records of numbers (columns `$1…$N` in,
//! channels `$1=…` out), as Radiance's rcalc does.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_calc::Program;
use fenestra_cli::opts::{Item, Kind, Opt, Spec};
use fenestra_records::rcalc::{Fmt, Settings};

fn spec() -> Spec {
    Spec::new(
        "rcalc",
        "Evaluate .cal definitions for each input record: $N on the right is input column N, $N = e defines output column N.",
    )
    .usage("[-b][-l][-n][-p|-P][-w][-u][-tS][-s svar=sval][-e expr][-f source][-i infmt][-o outfmt] [file …]")
    .interleaved(true)
    .opt(Opt::new("e", Kind::Word, "definitions (several -e/-f are read in order)"))
    .opt(Opt::new("f", Kind::Word, "file of definitions (found through RAYPATH)"))
    .opt(Opt::new("n", Kind::Flag, "no input: evaluate once"))
    .opt(Opt::new("l", Kind::Flag, "ignore newlines in input templates (no effect on column input)"))
    .opt(Opt::new("u", Kind::Flag, "flush output after each record"))
    .opt(Opt::new("w", Kind::Flag, "no warnings"))
    .opt(Opt::new("b", Kind::Flag, "exact template matching (accepted; templates are not supported)"))
    .opt(Opt::new("t", Kind::Attached, "column separator character (default: tab out, white space in)"))
    .opt(Opt::new("s", Kind::Word, "string variable svar=sval for templates (accepted, unused)"))
    .opt(Opt::new("i", Kind::Attached, "input format: a (ascii), f (float), d (double), optional count: -if3"))
    .opt(Opt::new("o", Kind::Attached, "output format: a, f, d"))
    .opt(Opt::new("p", Kind::Flag, "passive mode (not supported)"))
    .opt(Opt::new("P", Kind::Flag, "passive mode (not supported)"))
}

fn parse_fmt(opt: &str, w: &str) -> Result<(Fmt, usize)> {
    let mut ch = w.chars();
    let f = match ch.next() {
        None => bail!(
            "option -{opt} with a template file is not supported by fenestra (use -{opt}a, -{opt}f or -{opt}d)"
        ),
        Some(c) => match Fmt::from_letter(c) {
            Some(f) => f,
            None => bail!("option -{opt}{w}: unknown format '{c}' (expected a, f or d)"),
        },
    };
    let rest: String = ch.collect();
    let n = if rest.is_empty() {
        1
    } else {
        rest.parse::<usize>()
            .ok()
            .filter(|&n| n > 0)
            .with_context(|| format!("option -{opt}{w}: bad count '{rest}'"))?
    };
    Ok((f, n))
}

/// Runs rcalc.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let items = spec().parse(&args)?;
    let mut prog = Program::for_rcalc();
    let mut files = Vec::new();
    let (mut noinput, mut flush, mut warn) = (false, false, true);
    let (mut ifmt, mut icount, mut ofmt) = (Fmt::Ascii, 0usize, Fmt::Ascii);
    let mut sep: Option<String> = None;
    for it in items {
        match it {
            Item::Pos(p) => files.push(p),
            Item::Opt(o) => match o.key {
                "e" => prog.load_str("-e", o.word()).map_err(anyhow::Error::new)?,
                "f" => {
                    let path = fenestra_cli::raypath::find_or_err(o.word())?;
                    prog.load_file(&path).map_err(anyhow::Error::new)?;
                }
                "n" => {
                    // as Radiance's rcalc: definitions after -n keep their literal
                    // constants unfolded
                    noinput = true;
                    prog.set_parse_constants(false);
                }
                "u" => flush = true,
                "w" => warn = false,
                "l" | "b" | "s" => {}
                "t" => {
                    let w = o.word();
                    if w.is_empty() {
                        bail!("option -t needs a separator character (e.g. -t,)");
                    }
                    sep = Some(w.chars().next().map(String::from).unwrap_or_default());
                }
                "i" => {
                    let (f, n) = parse_fmt("i", o.word())?;
                    ifmt = f;
                    icount = if o.word().len() > 1 { n } else { 0 };
                }
                "o" => ofmt = parse_fmt("o", o.word())?.0,
                "p" | "P" => bail!(
                    "option -{} (passive mode) is not supported by fenestra",
                    o.key
                ),
                _ => {}
            },
        }
    }
    // FENESTRA_RCALC_THREADS: evaluator threads (1: one thread, records in turn)
    let threads = std::env::var("FENESTRA_RCALC_THREADS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .unwrap_or_else(|| {
            std::thread::available_parallelism()
                .map_or(1, |n| n.get())
                .min(4)
        })
        .max(1);
    let settings = Settings {
        ifmt,
        icount,
        ofmt,
        sep,
        flush,
        warn,
        threads,
    };
    if files.is_empty() {
        files.push("-".into());
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let files = (!noinput).then_some(files.as_slice());
    fenestra_records::rcalc::run(prog, &settings, files, &mut out)?;
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
