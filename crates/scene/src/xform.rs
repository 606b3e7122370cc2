//! The `xform` transformer: reads Radiance scene text and writes it transformed, in the
//! layout Radiance's xform prints (reals as `%18.12g`, one vertex per line …).
//! Geometry arguments are transformed; patterns, textures, BSDFs and instances get the
//! transform appended to their string arguments; `-I` inverts surfaces; `-n` prefixes
//! surface names, `-m` replaces surface modifiers; `-a N` makes arrays.

use std::fmt::Write as _;

use anyhow::{anyhow, bail, Context, Result};

use crate::cfmt::g_width;
use crate::transform::Transform;
use crate::words::{parse_count, parse_real, Words};

/// Options of one xform run.
#[derive(Debug, Clone, Default)]
pub struct XformOptions {
    /// Program name as invoked (for the header and `-c` command lines).
    pub argv0: String,
    /// `-I`: invert surface orientation.
    pub invert: bool,
    /// `-n name`: prefix for surface identifiers.
    pub name: Option<String>,
    /// `-m mod`: modifier for all surfaces.
    pub modifier: Option<String>,
    /// Expand `!command` lines (default; `-c` keeps them as commands).
    pub expand: bool,
    /// The transform words (`-t … -rx … -i N -a N …`).
    pub xf_words: Vec<String>,
    /// The tool options as given, in order, with their values (the header repeats them).
    pub given: Vec<(String, Option<String>)>,
    /// A run of one array element: the element's name (`name.k`, `ak` without `-n`), which
    /// the header gives for every `-n` value.
    pub element: Option<String>,
}

/// Types whose string arguments end with an (appended) transform.
const XF_STRING_TYPES: &[&str] = &[
    "instance",
    "mesh",
    "texfunc",
    "texdata",
    "brightfunc",
    "colorfunc",
    "brightdata",
    "colordata",
    "colorpict",
    "mixfunc",
    "mixdata",
    "mixpict",
    "plastic2",
    "metal2",
    "trans2",
    "ashik2",
    "BSDF",
    "aBSDF",
    "plasfunc",
    "metfunc",
    "transfunc",
    "BRTDfunc",
    "plasdata",
    "metdata",
    "transdata",
    "prism1",
    "prism2",
    "WGMDfunc",
    "specfunc",
    "specdata",
    "specpict",
];

impl XformOptions {
    /// Parses xform's command line (`args[0]` = program name): tool options, transform
    /// options, then files. Returns the options and the files.
    pub fn parse(args: &[String]) -> Result<(XformOptions, Vec<String>)> {
        let mut o = XformOptions {
            argv0: args.first().cloned().unwrap_or_else(|| "xform".into()),
            expand: true,
            ..Default::default()
        };
        let mut i = 1;
        while i < args.len() {
            match args[i].as_str() {
                "-c" => o.expand = false,
                "-e" => o.expand = true,
                "-I" => o.invert = !o.invert,
                "-n" | "-m" => {
                    let v = args
                        .get(i + 1)
                        .ok_or_else(|| anyhow!("option {} needs a value", args[i]))?
                        .clone();
                    if args[i] == "-n" {
                        // a second -n extends the prefix (Radiance's: -n a -n b names a.b.x)
                        o.name = Some(match o.name.take() {
                            Some(prev) => format!("{prev}.{v}"),
                            None => v.clone(),
                        });
                    } else if o.modifier.is_none() {
                        // the first -m counts, as Radiance's
                        o.modifier = Some(v.clone());
                    }
                    o.given.push((args[i].clone(), Some(v)));
                    i += 2;
                    continue;
                }
                _ => break,
            }
            o.given.push((args[i].clone(), None));
            i += 1;
        }
        while i < args.len() {
            let n = match args[i].as_str() {
                "-t" => 3,
                "-rx" | "-ry" | "-rz" | "-s" | "-i" | "-a" => 1,
                "-mx" | "-my" | "-mz" => 0,
                a if a.starts_with('-') && a.len() > 1 => {
                    bail!("command line error at '{a}' (xform options -c -e -I -n -m come before the transform)")
                }
                _ => break,
            };
            if n > 0 && i + n >= args.len() {
                bail!("option {} needs {n} value(s)", args[i]);
            }
            o.xf_words.extend_from_slice(&args[i..=i + n]);
            i += n + 1;
        }
        Ok((o, args[i..].to_vec()))
    }

    /// The words after the program name in the header: the tool options as given (as
    /// Radiance's: in their order, repeats kept; an array element's name in place of every
    /// `-n` value, or first when there was none), then the transform.
    fn header_words(&self) -> Vec<String> {
        if self.given.is_empty() {
            return self.synthesised_header_words();
        }
        let mut w = Vec::new();
        let has_n = self.given.iter().any(|(o, _)| o == "-n");
        if let (false, Some(e)) = (has_n, &self.element) {
            w.push("-n".into());
            w.push(e.clone());
        }
        for (o, v) in &self.given {
            w.push(o.clone());
            match (v, &self.element) {
                (Some(_), Some(e)) if o == "-n" => w.push(e.clone()),
                (Some(v), _) => w.push(v.clone()),
                (None, _) => {}
            }
        }
        w.extend(self.xf_words.iter().cloned());
        w
    }

    /// Header words of options not parsed from a command line: the options that are set.
    fn synthesised_header_words(&self) -> Vec<String> {
        let mut w = Vec::new();
        if let Some(n) = &self.name {
            w.push("-n".into());
            w.push(n.clone());
        }
        if let Some(m) = &self.modifier {
            w.push("-m".into());
            w.push(m.clone());
        }
        if !self.expand {
            w.push("-c".into());
        }
        if self.invert {
            w.push("-I".into());
        }
        w.extend(self.xf_words.iter().cloned());
        w
    }

    /// The runs an array (`-a N`) expands to; one run without arrays.
    pub fn array_runs(&self) -> Result<ArrayRuns<'_>> {
        let arrays: Vec<(usize, usize)> = self
            .xf_words
            .iter()
            .enumerate()
            .filter(|(_, w)| *w == "-a")
            .map(|(k, _)| {
                let w = &self.xf_words[k + 1];
                // a count of 0 is an error, as Radiance's "missing count for -a option"
                parse_count(w)
                    .filter(|&n| n > 0)
                    .map(|n| (k, n))
                    .ok_or_else(|| {
                        anyhow!("missing count for -a option: expected a positive count, got '{w}'")
                    })
            })
            .collect::<Result<_>>()?;
        let total = if arrays.is_empty() {
            1
        } else {
            arrays
                .iter()
                .try_fold(1usize, |t, a| t.checked_mul(a.1))
                .ok_or_else(|| anyhow!("-a: the arrays hold more copies than can be counted"))?
        };
        Ok(ArrayRuns {
            opts: self,
            arrays,
            next: 0,
            total,
        })
    }
}

/// The runs of an xform command with arrays, made one at a time (`-a 100000000 | head`
/// starts at once and holds one run).
pub struct ArrayRuns<'a> {
    opts: &'a XformOptions,
    arrays: Vec<(usize, usize)>,
    next: usize,
    total: usize,
}

impl Iterator for ArrayRuns<'_> {
    type Item = XformOptions;

    fn next(&mut self) -> Option<XformOptions> {
        if self.next >= self.total {
            return None;
        }
        let flat = self.next;
        self.next += 1;
        if self.arrays.is_empty() {
            return Some(self.opts.clone());
        }
        let mut idx = vec![0usize; self.arrays.len()];
        let mut rest = flat;
        for d in (0..self.arrays.len()).rev() {
            idx[d] = rest % self.arrays[d].1;
            rest /= self.arrays[d].1;
        }
        let mut run = self.opts.clone();
        // the element's name: the last -n value's (Radiance's), `ak` without one
        let given_n: Vec<&String> = self
            .opts
            .given
            .iter()
            .filter(|(o, _)| o == "-n")
            .filter_map(|(_, v)| v.as_ref())
            .collect();
        let base = given_n.last().copied().or(self.opts.name.as_ref());
        let mut name = match base {
            Some(n) => format!("{n}.{}", idx[0]),
            None => format!("a{}", idx[0]),
        };
        for k in &idx[1..] {
            let _ = write!(name, ".{k}");
        }
        // Radiance puts the element's name in place of every -n value, and a second -n
        // extends the prefix: -n p -n q -a 2 names q.0.q.0.x (reproduced as such)
        run.name = Some(vec![name.as_str(); given_n.len().max(1)].join("."));
        run.element = Some(name);
        for (d, (pos, _)) in self.arrays.iter().enumerate() {
            run.xf_words[*pos] = "-i".into();
            run.xf_words[*pos + 1] = idx[d].to_string();
        }
        Some(run)
    }
}

/// Runs xform over `files` (standard input, read once, when empty), writing to `sink` as
/// each run (array element) is done.
pub fn xform_files(
    opts: &XformOptions,
    files: &[String],
    sink: &mut dyn std::io::Write,
) -> Result<()> {
    let mut stdin_text: Option<(String, bool)> = None;
    let mut texts: Vec<Option<(String, bool)>> = vec![None; files.len()];
    let mut out = String::new();
    // the first run (array element) is written only once it is whole: every run reads
    // the same input, so an error shows there and leaves no partial output
    let mut first: Option<Vec<u8>> = Some(Vec::new());
    for run in opts.array_runs()? {
        let out = &mut out;
        out.clear();
        let xf = Transform::parse_all(&run.xf_words)?;
        let _ = write!(out, "# {}", run.argv0);
        for w in run.header_words() {
            let _ = write!(out, " {w}");
        }
        out.push('\n');
        let mut x = Xformer {
            o: &run,
            xf,
            depth: 0,
        };
        // each input's part of the output is written in its own encoding (a Latin-1
        // file's comments go out byte for byte)
        let mut put = |out: &mut String, latin1: bool| -> Result<()> {
            let bytes = crate::source::encode_text(out, latin1);
            match first.as_mut() {
                Some(held) => held.extend_from_slice(&bytes),
                None => sink.write_all(&bytes).context("cannot write the output")?,
            }
            out.clear();
            Ok(())
        };
        put(out, false)?;
        if files.is_empty() {
            if stdin_text.is_none() {
                let mut bytes = Vec::new();
                std::io::Read::read_to_end(&mut std::io::stdin(), &mut bytes)
                    .context("cannot read standard input")?;
                stdin_text = Some(crate::source::decode_text_latin1(bytes));
            }
            let (text, latin1) = stdin_text
                .as_ref()
                .map_or(("", false), |(t, l)| (t.as_str(), *l));
            x.text(text, "-", out)?;
            put(out, latin1)?;
        } else {
            for (f, t) in files.iter().zip(texts.iter_mut()) {
                if t.is_none() {
                    *t = Some(crate::source::decode_text_latin1(
                        crate::source::read_text_bytes(f)?,
                    ));
                }
                let (text, latin1) = t.as_ref().map_or(("", false), |(t, l)| (t.as_str(), *l));
                x.text(text, f, out)?;
                put(out, latin1)?;
            }
        }
        if let Some(held) = first.take() {
            sink.write_all(&held).context("cannot write the output")?;
        }
    }
    Ok(())
}

/// Runs `xform …` given as a `!command` in-process when it is a plain xform command line
/// (no shell syntax); returns `None` for anything else.
pub fn run_inline(cmd: &str) -> Result<Option<String>> {
    if cmd.chars().any(|c| "|;&<>$`()*?[]{}~\\'\"\n#=".contains(c)) {
        return Ok(None);
    }
    let words: Vec<String> = cmd.split_whitespace().map(String::from).collect();
    if words.first().map(String::as_str) != Some("xform") {
        return Ok(None);
    }
    let (opts, files) = XformOptions::parse(&words)?;
    if files.is_empty() {
        return Ok(None);
    }
    let mut out = Vec::new();
    xform_files(&opts, &files, &mut out)?;
    Ok(Some(crate::source::decode_text(out)))
}

struct Xformer<'a> {
    o: &'a XformOptions,
    xf: Transform,
    depth: usize,
}

fn fmt18(out: &mut String, v: f64) {
    out.push_str(&g_width(v, 18, 12));
}

impl Xformer<'_> {
    fn text(&mut self, text: &str, file: &str, out: &mut String) -> Result<()> {
        let mut w = Words::new(text);
        while let Some(c) = w.skip_space() {
            let line = w.line();
            match c {
                b'#' => {
                    out.push_str(w.rest_of_line());
                    out.push('\n');
                }
                b'!' => {
                    let (cmd, open) = w.command();
                    if open {
                        bail!("{file}:{line}: unterminated !command (the last line ends with '\\' at end of input): !{}", cmd.trim_end());
                    }
                    self.command(&cmd, file, line, out)?;
                }
                _ => self.primitive(&mut w, file, line, out)?,
            }
        }
        Ok(())
    }

    fn command(&mut self, cmd: &str, file: &str, line: u32, out: &mut String) -> Result<()> {
        if !self.o.expand {
            let _ = write!(out, "\n!{cmd} | {} -e", self.o.argv0);
            for w in self.o.header_words() {
                if w != "-c" {
                    let _ = write!(out, " {w}");
                }
            }
            out.push('\n');
            return Ok(());
        }
        if self.depth >= 32 {
            bail!("{file}:{line}: !commands nested too deeply");
        }
        let text =
            crate::source::command_output(cmd).with_context(|| format!("{file}:{line}: !{cmd}"))?;
        self.depth += 1;
        let r = self.text(&text, &format!("!{cmd}"), out);
        self.depth -= 1;
        r
    }

    fn primitive(&mut self, w: &mut Words, file: &str, line: u32, out: &mut String) -> Result<()> {
        let mut word = |what: &str| -> Result<String> {
            match w.word() {
                Ok(Some(s)) => Ok(s),
                Ok(None) => Err(anyhow!(
                    "{file}:{line}: unexpected end of input, expected {what}"
                )),
                Err(e) => Err(anyhow!("{file}:{line}: {e}")),
            }
        };
        let mut modifier = word("a modifier")?;
        let ptype = word("a primitive type")?;
        let mut name = word("an identifier")?;
        if ptype == "alias" {
            let target = word("the aliased name")?;
            let _ = write!(out, "\n{modifier} alias {name}\n\t{target}\n");
            return Ok(());
        }
        let rule = crate::types::rule(&ptype)
            .ok_or_else(|| anyhow!("{file}:{line}: unknown primitive type '{ptype}'"))?;
        let what = format!("{ptype} '{name}'");
        let to_count = |s: String, kind: &str| -> Result<usize> {
            parse_count(&s).ok_or_else(|| {
                anyhow!("{file}:{line}: {what}: expected the {kind}-argument count, got '{s}'")
            })
        };
        let ns = to_count(
            word(&format!("the string-argument count of {what}"))?,
            "string",
        )?;
        let mut sargs = Vec::with_capacity(ns.min(64)); // counts are checked by what follows
        for _ in 0..ns {
            sargs.push(word(&format!("a string argument of {what}"))?);
        }
        let ni = to_count(
            word(&format!("the integer-argument count of {what}"))?,
            "integer",
        )?;
        let mut iargs = Vec::with_capacity(ni.min(64));
        for _ in 0..ni {
            iargs.push(word(&format!("an integer argument of {what}"))?);
        }
        let nr = to_count(word(&format!("the real-argument count of {what}"))?, "real")?;
        let mut rargs = Vec::with_capacity(nr.min(64));
        for _ in 0..nr {
            let s = word(&format!("a real argument of {what}"))?;
            rargs.push(parse_real(&s).ok_or_else(|| {
                anyhow!("{file}:{line}: {what}: real argument is not a number: '{s}'")
            })?);
        }
        crate::types::check(&ptype, ns, ni, nr)
            .map_err(|e| anyhow!("{file}:{line}: {what}: {e}"))?;
        if matches!(ptype.as_str(), "brighttext" | "colortext" | "mixtext") {
            bail!("{file}:{line}: {what}: xform of text patterns is not supported by fenestra");
        }
        if rule.surface {
            if let Some(m) = &self.o.modifier {
                modifier = m.clone();
            }
            if let Some(n) = &self.o.name {
                name = format!("{n}.{name}");
            }
        }
        let xf = self.xf;
        let flip = self.o.invert;
        let sca = xf.sca.abs();
        let mut ptype_out = ptype.clone();
        if flip {
            ptype_out = match ptype.as_str() {
                "sphere" => "bubble",
                "bubble" => "sphere",
                "cone" => "cup",
                "cup" => "cone",
                "cylinder" => "tube",
                "tube" => "cylinder",
                t => t,
            }
            .to_string();
        }
        if XF_STRING_TYPES.contains(&ptype.as_str()) && !self.o.xf_words.is_empty() {
            if self.o.xf_words[0] != "-i" {
                sargs.push("-i".into());
                sargs.push("1".into());
            }
            sargs.extend(self.o.xf_words.iter().cloned());
        }
        let _ = write!(out, "\n{modifier} {ptype_out} {name}\n{}", sargs.len());
        for s in &sargs {
            let _ = write!(out, " {s}");
        }
        let _ = write!(out, "\n{}", iargs.len());
        for s in &iargs {
            let _ = write!(out, " {s}");
        }
        out.push('\n');
        let p3 = |r: &[f64], k: usize| [r[k], r[k + 1], r[k + 2]];
        let row = |out: &mut String, v: &[f64]| {
            out.push('\n');
            for x in v {
                out.push(' ');
                fmt18(out, *x);
            }
        };
        let _ = write!(out, "{nr}");
        match ptype.as_str() {
            "polygon" => {
                let nv = nr / 3;
                let reverse = flip != xf.mirrors();
                for k in 0..nv {
                    let v = if reverse { nv - 1 - k } else { k };
                    row(out, &xf.point(p3(&rargs, 3 * v)));
                }
            }
            "sphere" | "bubble" => {
                let c = xf.point(p3(&rargs, 0));
                for x in [c[0], c[1], c[2], rargs[3] * sca] {
                    out.push(' ');
                    fmt18(out, x);
                }
            }
            "source" => {
                let d = xf.vector(p3(&rargs, 0));
                for x in [d[0], d[1], d[2], rargs[3]] {
                    out.push(' ');
                    fmt18(out, x);
                }
            }
            "cone" | "cup" | "cylinder" | "tube" => {
                row(out, &xf.point(p3(&rargs, 0)));
                row(out, &xf.point(p3(&rargs, 3)));
                let radii: Vec<f64> = rargs[6..].iter().map(|r| r * sca).collect();
                row(out, &radii);
            }
            "ring" => {
                row(out, &xf.point(p3(&rargs, 0)));
                // negated after the transform, as Radiance (the sign of a zero shows)
                let mut n = xf.vector(p3(&rargs, 3));
                if flip {
                    n = n.map(|x| -x);
                }
                row(out, &n);
                row(out, &[rargs[6] * sca, rargs[7] * sca]);
            }
            "glow" => {
                for (k, x) in rargs.iter().enumerate() {
                    out.push(' ');
                    fmt18(out, if k == 3 { x * sca } else { *x });
                }
            }
            "spotlight" => {
                for x in &rargs[..4] {
                    out.push(' ');
                    fmt18(out, *x);
                }
                let d = xf.vector(p3(&rargs, 4));
                out.push_str("\n\t");
                fmt18(out, d[0]);
                out.push(' ');
                fmt18(out, d[1]);
                out.push(' ');
                fmt18(out, d[2]);
            }
            "dielectric" => {
                for (k, x) in rargs.iter().enumerate() {
                    let v = if k < 3 { x.powf(1.0 / sca) } else { *x };
                    let _ = write!(out, " {}", g_width(v, 12, 6));
                }
            }
            "interface" => {
                for half in 0..2 {
                    out.push('\n');
                    for k in 0..4 {
                        let x = rargs[4 * half + k];
                        let v = if k < 3 { x.powf(1.0 / sca) } else { x };
                        if k > 0 {
                            out.push(' ');
                        }
                        out.push_str(&g_width(v, 12, 6));
                    }
                }
            }
            "mist" => {
                for (k, x) in rargs.iter().enumerate() {
                    let v = if k < 3 { x / sca } else { *x };
                    let _ = write!(out, " {}", g_width(v, 12, 6));
                }
            }
            _ => {
                for x in &rargs {
                    out.push(' ');
                    fmt18(out, *x);
                }
            }
        }
        out.push('\n');
        Ok(())
    }
}

/// Applies a transform to a parsed primitive in place, as xform does to its text
/// (geometry transformed, transform appended to pattern/BSDF/instance strings).
pub fn transform_primitive(p: &mut crate::Primitive, xf: &Transform, xf_words: &[String]) {
    let sca = xf.sca.abs();
    let r = &mut p.rargs;
    let p3 = |r: &[f64], k: usize| [r[k], r[k + 1], r[k + 2]];
    let put = |r: &mut Vec<f64>, k: usize, v: [f64; 3]| r[k..k + 3].copy_from_slice(&v);
    match p.ptype.as_str() {
        "polygon" => {
            let nv = r.len() / 3;
            let mut pts: Vec<[f64; 3]> = (0..nv).map(|k| xf.point(p3(r, 3 * k))).collect();
            if xf.mirrors() {
                pts.reverse();
            }
            for (k, v) in pts.into_iter().enumerate() {
                put(r, 3 * k, v);
            }
        }
        "sphere" | "bubble" => {
            let c = xf.point(p3(r, 0));
            put(r, 0, c);
            r[3] *= sca;
        }
        "source" => {
            let d = xf.vector(p3(r, 0));
            put(r, 0, d);
        }
        "cone" | "cup" | "cylinder" | "tube" => {
            let a = xf.point(p3(r, 0));
            let b = xf.point(p3(r, 3));
            put(r, 0, a);
            put(r, 3, b);
            for x in &mut r[6..] {
                *x *= sca;
            }
        }
        "ring" => {
            let c = xf.point(p3(r, 0));
            let n = xf.vector(p3(r, 3));
            put(r, 0, c);
            put(r, 3, n);
            r[6] *= sca;
            r[7] *= sca;
        }
        "glow" => r[3] *= sca,
        "spotlight" => {
            let d = xf.vector(p3(r, 4));
            put(r, 4, d);
        }
        "dielectric" => {
            for x in &mut r[..3] {
                *x = x.powf(1.0 / sca);
            }
        }
        "interface" => {
            for k in [0, 1, 2, 4, 5, 6] {
                r[k] = r[k].powf(1.0 / sca);
            }
        }
        "mist" => {
            for x in &mut r[..3] {
                *x /= sca;
            }
        }
        t if XF_STRING_TYPES.contains(&t) && !xf_words.is_empty() => {
            if xf_words[0] != "-i" {
                p.sargs.push("-i".into());
                p.sargs.push("1".into());
            }
            p.sargs.extend(xf_words.iter().cloned());
        }
        _ => {}
    }
}
