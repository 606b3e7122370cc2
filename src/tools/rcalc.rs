//! rcalc: evaluates .cal definitions on records of numbers (columns `$1…$N` in,
//! channels `$1=…` out), as Radiance's rcalc does.

use std::io::{BufRead, Read, Write};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_calc::format::fmt_g;
use fenestra_calc::{Compiled, Program, State, VarId};
use fenestra_cli::opts::{Item, Kind, Opt, Spec};

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

#[derive(Clone, Copy, PartialEq)]
enum Fmt {
    Ascii,
    Float,
    Double,
}

fn parse_fmt(opt: &str, w: &str) -> Result<(Fmt, usize)> {
    let mut ch = w.chars();
    let f = match ch.next() {
        Some('a') => Fmt::Ascii,
        Some('f') => Fmt::Float,
        Some('d') => Fmt::Double,
        None => bail!(
            "option -{opt} with a template file is not supported by fenestra (use -{opt}a, -{opt}f or -{opt}d)"
        ),
        Some(c) => bail!("option -{opt}{w}: unknown format '{c}' (expected a, f or d)"),
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

/// The longest numeric prefix of a word, as C's `atof` reads it (0 when none).
pub fn atof(w: &str) -> f64 {
    if let Ok(v) = w.parse::<f64>() {
        return v;
    }
    let b = w.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let mut digits = 0;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
        digits += 1;
    }
    if i < b.len() && b[i] == b'.' {
        i += 1;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
            digits += 1;
        }
    }
    if digits == 0 {
        return 0.0;
    }
    let mut end = i;
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        let s = j;
        while j < b.len() && b[j].is_ascii_digit() {
            j += 1;
        }
        if j > s {
            end = j;
        }
    }
    w[..end].parse().unwrap_or(0.0)
}

struct Run {
    exe: Compiled,
    st: State,
    outs: Vec<Option<usize>>, // channel n-1 → index in chan list
    cond: Option<VarId>,
    recno: VarId,
    outno: VarId,
    nout: u64,
    nrec: u64,
    ofmt: Fmt,
    sep: String,
    flush: bool,
    warn: bool,
    line: String,
}

impl Run {
    fn record(&mut self, out: &mut dyn Write) -> Result<()> {
        self.nrec += 1;
        self.st.set(self.recno, self.nrec as f64);
        self.st.set(self.outno, (self.nout + 1) as f64);
        if let Some(c) = self.cond {
            let v = self.exe.eval_var(&mut self.st, c)?;
            if v <= 0.0 {
                self.report_warnings();
                return Ok(());
            }
        }
        self.nout += 1;
        self.line.clear();
        for (k, slot) in self.outs.iter().enumerate() {
            let n = k as u32 + 1;
            let v = match slot {
                Some(_) => Some(self.exe.eval_chan(&mut self.st, n)?),
                None => None,
            };
            match self.ofmt {
                Fmt::Ascii => {
                    if k > 0 {
                        self.line.push_str(&self.sep);
                    }
                    if let Some(v) = v {
                        self.line.push_str(&fmt_g(v, 9));
                    }
                }
                Fmt::Float => out.write_all(&(v.unwrap_or(0.0) as f32).to_ne_bytes())?,
                Fmt::Double => out.write_all(&v.unwrap_or(0.0).to_ne_bytes())?,
            }
        }
        if self.ofmt == Fmt::Ascii {
            self.line.push('\n');
            out.write_all(self.line.as_bytes())?;
        }
        self.report_warnings();
        if self.flush {
            out.flush()?;
        }
        Ok(())
    }

    fn report_warnings(&mut self) {
        let w = self.st.take_warnings();
        if self.warn && w.any() {
            for m in w.messages() {
                fenestra_cli::warn(m);
            }
        }
    }
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
    let ids = prog.bind_vars(&["recno", "outno"]);
    let exe = prog.compile().map_err(anyhow::Error::new)?;
    let maxchan = exe.channels().last().copied().unwrap_or(0) as usize;
    let mut outs = vec![None; maxchan];
    for (i, n) in exe.channels().iter().enumerate() {
        outs[*n as usize - 1] = Some(i);
    }
    let cond = exe.var("cond");
    let st = exe.state();
    let mut r = Run {
        exe,
        st,
        outs,
        cond,
        recno: ids[0],
        outno: ids[1],
        nout: 0,
        nrec: 0,
        ofmt,
        sep: sep.clone().unwrap_or_else(|| "\t".into()),
        flush,
        warn,
        line: String::new(),
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::with_capacity(1 << 16, stdout.lock());
    if noinput {
        r.record(&mut out)?;
        out.flush()?;
        return Ok(ExitCode::SUCCESS);
    }
    if files.is_empty() {
        files.push("-".into());
    }
    let in_sep = sep.and_then(|s| s.chars().next());
    for f in &files {
        let mut input = fenestra_cli::input::open(f)?;
        match ifmt {
            Fmt::Ascii => {
                let mut line = String::new();
                let mut cols: Vec<f64> = Vec::new();
                loop {
                    line.clear();
                    if input
                        .read_line(&mut line)
                        .with_context(|| format!("reading {f}"))?
                        == 0
                    {
                        break;
                    }
                    let text = line.trim_end_matches(['\n', '\r']);
                    cols.clear();
                    match in_sep {
                        Some(c) => cols.extend(text.split(c).map(atof)),
                        None => cols.extend(text.split_ascii_whitespace().map(atof)),
                    }
                    if icount > 0 {
                        cols.truncate(icount);
                    }
                    r.st.set_chans(&cols);
                    r.record(&mut out)?;
                }
            }
            Fmt::Float | Fmt::Double => {
                let n = icount.max(1);
                let size = if ifmt == Fmt::Float { 4 } else { 8 };
                let mut buf = vec![0u8; n * size];
                let mut cols = vec![0.0f64; n];
                loop {
                    match read_full(&mut input, &mut buf)? {
                        0 => break,
                        k if k < buf.len() => {
                            fenestra_cli::warn(format!(
                                "{f}: incomplete record at end of input ({k} of {} bytes)",
                                buf.len()
                            ));
                            break;
                        }
                        _ => {}
                    }
                    for (i, c) in cols.iter_mut().enumerate() {
                        let b = &buf[i * size..(i + 1) * size];
                        *c = if size == 4 {
                            f32::from_ne_bytes(b.try_into().unwrap_or([0; 4])) as f64
                        } else {
                            f64::from_ne_bytes(b.try_into().unwrap_or([0; 8]))
                        };
                    }
                    r.st.set_chans(&cols);
                    r.record(&mut out)?;
                }
            }
        }
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

fn read_full(r: &mut dyn Read, buf: &mut [u8]) -> Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        let k = r.read(&mut buf[got..])?;
        if k == 0 {
            break;
        }
        got += k;
    }
    Ok(got)
}

#[cfg(test)]
mod tests {
    use super::atof;

    #[test]
    fn atof_reads_prefixes() {
        assert_eq!(atof("1e3"), 1000.0);
        assert_eq!(atof("-2.5x"), -2.5);
        assert_eq!(atof(".5"), 0.5);
        assert_eq!(atof("a"), 0.0);
        assert_eq!(atof("1,2"), 1.0);
        assert_eq!(atof("3e"), 3.0);
    }
}
