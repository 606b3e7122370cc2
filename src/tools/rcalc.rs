//! rcalc: evaluates .cal definitions on records of numbers (columns `$1…$N` in,
//! channels `$1=…` out), as Radiance's rcalc does.

use std::io::{BufRead, Read, Write};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_calc::format::push_g;
use fenestra_calc::{Compiled, Program, State, VarId};
use fenestra_cli::num::atof;
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

/// The `-f` number-stream format (one type for every tool).
type Fmt = fenestra_cli::rays::RayFormat;

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

/// How a record's output line is produced: one per thread.
struct Eval<'c> {
    exe: &'c Compiled,
    st: State,
    /// Whether output channel `k + 1` is defined.
    outs: &'c [bool],
    cond: Option<VarId>,
    /// `recno` and `outno`, set before each record (`None`: no definition uses them).
    counters: Option<(VarId, VarId)>,
    nout: u64,
    nrec: u64,
    ofmt: Fmt,
    sep: &'c [u8],
    warn: bool,
    /// Warning messages of the records evaluated, in order (printed by the caller).
    warnings: Vec<String>,
    scratch: String,
}

impl Eval<'_> {
    /// Evaluates one record (channels already set) and appends its output to `out`.
    fn record(&mut self, out: &mut Vec<u8>) -> Result<()> {
        self.nrec += 1;
        if let Some((recno, outno)) = self.counters {
            self.st.set(recno, self.nrec as f64);
            self.st.set(outno, (self.nout + 1) as f64);
        }
        if let Some(c) = self.cond {
            let v = self.exe.eval_var(&mut self.st, c)?;
            if v <= 0.0 {
                self.take_warnings();
                return Ok(());
            }
        }
        self.nout += 1;
        let mark = out.len();
        for (k, &defined) in self.outs.iter().enumerate() {
            let v = if defined {
                match self.exe.eval_chan(&mut self.st, k as u32 + 1) {
                    Ok(v) => Some(v),
                    Err(e) => {
                        out.truncate(mark);
                        return Err(e.into());
                    }
                }
            } else {
                None
            };
            match self.ofmt {
                Fmt::Ascii => {
                    if k > 0 {
                        out.extend_from_slice(self.sep);
                    }
                    if let Some(v) = v {
                        push_g(out, v, 9, &mut self.scratch);
                    }
                }
                Fmt::Float => out.extend_from_slice(&(v.unwrap_or(0.0) as f32).to_ne_bytes()),
                Fmt::Double => out.extend_from_slice(&v.unwrap_or(0.0).to_ne_bytes()),
            }
        }
        if self.ofmt == Fmt::Ascii {
            out.push(b'\n');
        }
        self.take_warnings();
        Ok(())
    }

    #[inline]
    fn take_warnings(&mut self) {
        if !self.st.has_warnings() {
            return;
        }
        let w = self.st.take_warnings();
        if self.warn && w.any() {
            self.warnings.extend(w.messages());
        }
    }

    fn print_warnings(&mut self) {
        for m in self.warnings.drain(..) {
            fenestra_cli::warn(m);
        }
    }
}

/// How input records are delimited.
#[derive(Clone, Copy)]
enum Framing {
    /// Lines of words (split at white space, or at a separator character).
    Ascii { sep: Option<char>, count: usize },
    /// Fixed-size records of `n` float32 (`size` 4) or float64 (`size` 8) values.
    Binary { n: usize, size: usize },
}

/// `u8::is_ascii_whitespace`, the white space of `str::split_ascii_whitespace`.
#[inline]
fn is_ws(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\x0C' | b'\r')
}

/// Powers of ten exactly representable as f64.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A plain decimal number (`[+-]digits[.digits]`, at most 18 digits, at most 2^53)
/// at `buf[i..]` ending at white space or at the end of `buf`: its value as one
/// correctly rounded division of two exact numbers (the value `str::parse` gives),
/// and where it ends; `None` for anything else.
#[inline(always)]
fn plain_at(buf: &[u8], mut i: usize) -> Option<(f64, usize)> {
    let n = buf.len();
    // (no branch on the sign: it is unpredictable in typical input)
    let c = buf.get(i).copied().unwrap_or(0);
    let neg = c == b'-';
    i += usize::from(neg | (c == b'+'));
    let (mut m, mut nd, mut frac) = (0u64, 0u32, 0usize);
    // the integer part is usually short: digit by digit
    while i < n && buf[i].is_ascii_digit() && nd < 18 {
        m = m * 10 + u64::from(buf[i] - b'0');
        nd += 1;
        i += 1;
    }
    if i < n && buf[i].is_ascii_digit() {
        i = digit_run(buf, i, &mut m, &mut nd);
    }
    if i < n && buf[i] == b'.' {
        let at = nd;
        i = digit_run(buf, i + 1, &mut m, &mut nd);
        frac = (nd - at) as usize;
    }
    if nd == 0 || nd > 18 || (i < n && !is_ws(buf[i])) || m > 1 << 53 || frac >= POW10.len() {
        return None;
    }
    // (m <= 2^53: converted exactly, through i64 for a single instruction)
    let v = (m as i64) as f64 / POW10[frac];
    Some((f64::from_bits(v.to_bits() | u64::from(neg) << 63), i))
}

/// Reads the digits at `buf[i..]` into `m` (`nd` counts them), eight at a time where
/// eight bytes are there; stops before a 19th digit. Returns where it stopped.
#[inline(always)]
fn digit_run(buf: &[u8], mut i: usize, m: &mut u64, nd: &mut u32) -> usize {
    const POW: [u64; 9] = [
        1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000,
    ];
    while let Some(w) = buf.get(i..i + 8) {
        let v = u64::from_le_bytes(w.try_into().unwrap_or([0; 8]));
        let x = v ^ 0x3030_3030_3030_3030; // digit bytes become their values
        let bad =
            (((x & 0x7F7F_7F7F_7F7F_7F7F) + 0x7676_7676_7676_7676) | x) & 0x8080_8080_8080_8080;
        let k = (bad.trailing_zeros() / 8) as usize; // leading digit bytes
        if k == 0 || *nd + k as u32 > 18 {
            break;
        }
        // the k digits as the last k of eight (zeros in front), combined pairwise
        let mut d = if k == 8 { x } else { x << (8 * (8 - k)) };
        // (the products overflow by design: the bits above 64 are not needed)
        d = (d * 10) + (d >> 8);
        d = ((d & 0x0000_00FF_0000_00FF).wrapping_mul(100 + (1_000_000 << 32)))
            .wrapping_add(((d >> 16) & 0x0000_00FF_0000_00FF).wrapping_mul(1 + (10_000 << 32)))
            >> 32;
        *m = *m * POW[k] + d;
        *nd += k as u32;
        i += k;
        if k < 8 {
            return i;
        }
    }
    while i < buf.len() && buf[i].is_ascii_digit() && *nd < 19 {
        *m = *m * 10 + u64::from(buf[i] - b'0');
        *nd += 1;
        i += 1;
    }
    i
}

/// A plain decimal word (see [`plain_at`]).
#[cfg(test)]
fn parse_plain(w: &[u8]) -> Option<f64> {
    plain_at(w, 0)
        .filter(|&(_, e)| e == w.len())
        .map(|(v, _)| v)
}

/// The columns of the line at the start of `buf`, split at white space; returns the
/// length of the line with its newline.
fn ws_line(buf: &[u8], cols: &mut Vec<f64>) -> Result<usize> {
    cols.clear();
    let n = buf.len();
    let mut i = 0;
    loop {
        while i < n && matches!(buf[i], b' ' | b'\t' | b'\r' | b'\x0C') {
            i += 1;
        }
        if i >= n {
            return Ok(n);
        }
        if buf[i] == b'\n' {
            return Ok(i + 1);
        }
        if let Some((v, e)) = plain_at(buf, i) {
            cols.push(v);
            i = e;
            continue;
        }
        let s = i;
        while i < n && !is_ws(buf[i]) {
            i += 1;
        }
        cols.push(word_value(&buf[s..i])?);
    }
}

/// A word's value as C's `atof` reads it (called where [`plain_at`] did not read it).
fn word_value(w: &[u8]) -> Result<f64> {
    let s = std::str::from_utf8(w)
        .map_err(|_| anyhow::anyhow!("stream did not contain valid UTF-8"))?;
    Ok(atof(s))
}

/// The columns of one input line (without its newline).
fn line_cols(line: &[u8], sep: Option<char>, count: usize, cols: &mut Vec<f64>) -> Result<()> {
    let mut end = line.len();
    while end > 0 && line[end - 1] == b'\r' {
        end -= 1;
    }
    let line = &line[..end];
    cols.clear();
    match sep {
        None => {
            // (a carriage return is white space)
            ws_line(line, cols)?;
        }
        Some(c) => {
            let text = std::str::from_utf8(line)
                .map_err(|_| anyhow::anyhow!("stream did not contain valid UTF-8"))?;
            cols.extend(text.split(c).map(atof));
        }
    }
    if count > 0 {
        cols.truncate(count);
    }
    Ok(())
}

/// What a block of input gave: its output, the warnings in order, and the error that
/// stopped it (after the output of the records before).
struct Done {
    out: Vec<u8>,
    warnings: Vec<String>,
    err: Option<anyhow::Error>,
}

/// Writes a block's output and warnings; its error, if any, after flushing what came before.
fn emit_block(out: &mut (impl Write + ?Sized), done: Done) -> Result<()> {
    out.write_all(&done.out)?;
    for m in done.warnings {
        fenestra_cli::warn(m);
    }
    if let Some(e) = done.err {
        out.flush()?;
        return Err(e);
    }
    Ok(())
}

/// Evaluates the records of a block of whole records.
fn eval_block(ev: &mut Eval, framing: Framing, fname: &str, block: &[u8], last: bool) -> Done {
    let mut out = Vec::with_capacity(block.len() / 2);
    let mut cols = Vec::new();
    let err = (|| -> Result<()> {
        match framing {
            Framing::Ascii { sep, count } => {
                let mut at = 0;
                while at < block.len() {
                    let len = match sep {
                        None => {
                            // parsed straight into the state's channels
                            let chans = ev.st.chans_mut();
                            let len = ws_line(&block[at..], chans)
                                .with_context(|| format!("reading {fname}"))?;
                            if count > 0 {
                                chans.truncate(count);
                            }
                            ev.st.touch();
                            at += len;
                            ev.record(&mut out)?;
                            continue;
                        }
                        Some(_) => {
                            let rest = &block[at..];
                            let len = rest
                                .iter()
                                .position(|&b| b == b'\n')
                                .map_or(rest.len(), |i| i + 1);
                            let line = rest[..len].strip_suffix(b"\n").unwrap_or(&rest[..len]);
                            line_cols(line, sep, count, &mut cols)
                                .with_context(|| format!("reading {fname}"))?;
                            len
                        }
                    };
                    at += len;
                    ev.st.set_chans(&cols);
                    ev.record(&mut out)?;
                }
            }
            Framing::Binary { n, size } => {
                let rec = n * size;
                let whole = block.len() / rec * rec;
                for r in block[..whole].chunks_exact(rec) {
                    binary_cols(r, size, &mut cols);
                    ev.st.set_chans(&cols);
                    ev.record(&mut out)?;
                }
                if last && whole < block.len() {
                    ev.warnings.push(format!(
                        "{fname}: incomplete record at end of input ({} of {rec} bytes)",
                        block.len() - whole
                    ));
                }
            }
        }
        Ok(())
    })()
    .err();
    Done {
        out,
        warnings: std::mem::take(&mut ev.warnings),
        err,
    }
}

fn binary_cols(r: &[u8], size: usize, cols: &mut Vec<f64>) {
    cols.clear();
    cols.extend(r.chunks_exact(size).map(|b| {
        if size == 4 {
            f32::from_ne_bytes(b.try_into().unwrap_or([0; 4])) as f64
        } else {
            f64::from_ne_bytes(b.try_into().unwrap_or([0; 8]))
        }
    }));
}

/// Size of the blocks of input evaluated in parallel.
const BLOCK: usize = 1 << 18;

/// Reads the next block of whole records (what is left of an incomplete one is kept
/// in `carry`), and whether it is the last; an empty block at the end of the input.
/// A read error ends the input: the block read before it is returned as the last,
/// with the error, to be reported after the block's records (as reading record by
/// record would).
fn next_block(
    input: &mut dyn Read,
    framing: Framing,
    carry: &mut Vec<u8>,
) -> (Vec<u8>, bool, Option<std::io::Error>) {
    let mut block = Vec::with_capacity(BLOCK + carry.len() + 4096);
    block.append(carry);
    let want = BLOCK.max(block.len() + 4096);
    let mut eof = false;
    while block.len() < want {
        let at = block.len();
        block.resize(want, 0);
        let k = loop {
            match input.read(&mut block[at..]) {
                Ok(k) => break k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    block.truncate(at);
                    return (block, true, Some(e));
                }
            }
        };
        block.truncate(at + k);
        if k == 0 {
            eof = true;
            break;
        }
    }
    if !eof {
        let cut = match framing {
            Framing::Ascii { .. } => block.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1),
            Framing::Binary { n, size } => block.len() / (n * size) * (n * size),
        };
        carry.extend_from_slice(&block[cut..]);
        block.truncate(cut);
    }
    (block, eof, None)
}

/// Evaluates one input with `threads` evaluators on blocks of records, output in
/// input order.
fn run_parallel<'c>(
    mk: &(dyn Fn() -> Eval<'c> + Sync),
    framing: Framing,
    fname: &str,
    mut input: Box<dyn BufRead + Send>,
    threads: usize,
    out: &mut dyn Write,
) -> Result<()> {
    use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
    type Block = std::result::Result<(Vec<u8>, bool), String>;
    std::thread::scope(|sc| -> Result<()> {
        let mut to_workers: Vec<SyncSender<Block>> = Vec::new();
        let mut from_workers: Vec<Receiver<Done>> = Vec::new();
        for _ in 0..threads {
            let (btx, brx) = sync_channel::<Block>(2);
            let (dtx, drx) = sync_channel::<Done>(2);
            to_workers.push(btx);
            from_workers.push(drx);
            let worker = std::thread::Builder::new().stack_size(fenestra_cli::threads::STACK_BYTES);
            worker.spawn_scoped(sc, move || {
                let mut ev = mk();
                while let Ok(b) = brx.recv() {
                    let done = match b {
                        Ok((block, last)) => eval_block(&mut ev, framing, fname, &block, last),
                        Err(e) => Done {
                            out: Vec::new(),
                            warnings: Vec::new(),
                            err: Some(anyhow::anyhow!("{e}")),
                        },
                    };
                    let stop = done.err.is_some();
                    if dtx.send(done).is_err() || stop {
                        break;
                    }
                }
            })?;
        }
        sc.spawn(move || {
            let mut carry = Vec::new();
            let mut i = 0usize;
            loop {
                let (block, last, err) = next_block(&mut input, framing, &mut carry);
                if to_workers[i % to_workers.len()]
                    .send(Ok((block, last)))
                    .is_err()
                {
                    break;
                }
                i += 1;
                if let Some(e) = err {
                    let _ =
                        to_workers[i % to_workers.len()].send(Err(format!("reading {fname}: {e}")));
                }
                if last {
                    break;
                }
            }
        });
        let mut i = 0usize;
        while let Ok(done) = from_workers[i % threads].recv() {
            emit_block(out, done)?;
            i += 1;
        }
        Ok(())
    })
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
    let (exe, recno, outno, independent) = compile_program(prog)?;
    let maxchan = exe.channels().last().copied().unwrap_or(0) as usize;
    let mut outs = vec![false; maxchan];
    for n in exe.channels() {
        outs[n as usize - 1] = true;
    }
    let cond = exe.var("cond");
    let sep_out = sep.clone().unwrap_or_else(|| "\t".into());
    let mk = |counters: bool| Eval {
        exe: &exe,
        st: exe.state(),
        outs: &outs,
        cond,
        counters: counters.then_some((recno, outno)),
        nout: 0,
        nrec: 0,
        ofmt,
        sep: sep_out.as_bytes(),
        warn,
        warnings: Vec::new(),
        scratch: String::new(),
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if noinput {
        let mut ev = mk(true);
        let mut buf = Vec::new();
        let r = ev.record(&mut buf);
        out.write_all(&buf)?;
        out.flush()?;
        r?;
        ev.print_warnings();
        return Ok(ExitCode::SUCCESS);
    }
    if files.is_empty() {
        files.push("-".into());
    }
    let framing = match ifmt {
        Fmt::Ascii => Framing::Ascii {
            sep: sep.and_then(|s| s.chars().next()),
            count: icount,
        },
        Fmt::Float => Framing::Binary {
            n: icount.max(1),
            size: 4,
        },
        Fmt::Double => Framing::Binary {
            n: icount.max(1),
            size: 8,
        },
    };
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
    if threads > 1 && independent && !flush {
        let mkp = || mk(false);
        for f in &files {
            let input = fenestra_cli::input::open(f)?;
            run_parallel(&mkp, framing, f, input, threads, &mut out)?;
        }
        out.flush()?;
        return Ok(ExitCode::SUCCESS);
    }
    let mut ev = mk(true);
    if !flush {
        // one thread, blocks of records
        for f in &files {
            let mut input = fenestra_cli::input::open(f)?;
            let mut carry = Vec::new();
            loop {
                let (block, last, err) = next_block(&mut input, framing, &mut carry);
                let mut done = eval_block(&mut ev, framing, f, &block, last);
                if let (None, Some(e)) = (&done.err, err) {
                    done.err = Some(anyhow::Error::new(e).context(format!("reading {f}")));
                }
                emit_block(&mut out, done)?;
                if last {
                    break;
                }
            }
        }
        out.flush()?;
        return Ok(ExitCode::SUCCESS);
    }
    // -u: record by record, the output flushed after each
    let mut buf: Vec<u8> = Vec::new();
    let mut cols: Vec<f64> = Vec::new();
    for f in &files {
        let mut input = fenestra_cli::input::open(f)?;
        let r = (|| -> Result<()> {
            match framing {
                Framing::Ascii { sep, count } => {
                    let mut line = Vec::new();
                    loop {
                        line.clear();
                        if input
                            .read_until(b'\n', &mut line)
                            .with_context(|| format!("reading {f}"))?
                            == 0
                        {
                            break;
                        }
                        let text = line.strip_suffix(b"\n").unwrap_or(&line);
                        line_cols(text, sep, count, &mut cols)
                            .with_context(|| format!("reading {f}"))?;
                        flush_record(&mut ev, &cols, &mut buf, &mut out)?;
                    }
                }
                Framing::Binary { n, size } => {
                    let mut rec = vec![0u8; n * size];
                    loop {
                        match read_full(&mut input, &mut rec)? {
                            0 => break,
                            k if k < rec.len() => {
                                fenestra_cli::warn(format!(
                                    "{f}: incomplete record at end of input ({k} of {} bytes)",
                                    rec.len()
                                ));
                                break;
                            }
                            _ => {}
                        }
                        binary_cols(&rec, size, &mut cols);
                        flush_record(&mut ev, &cols, &mut buf, &mut out)?;
                    }
                }
            }
            Ok(())
        })();
        if let Err(e) = r {
            out.write_all(&buf)?;
            out.flush()?;
            return Err(e);
        }
    }
    out.write_all(&buf)?;
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

/// `-u`: evaluates one record and writes its output (and warnings) at once.
fn flush_record(
    ev: &mut Eval,
    cols: &[f64],
    buf: &mut Vec<u8>,
    out: &mut impl Write,
) -> Result<()> {
    ev.st.set_chans(cols);
    ev.record(buf)?;
    ev.print_warnings();
    out.write_all(buf)?;
    buf.clear();
    out.flush()?;
    Ok(())
}

/// Compiles rcalc's program with `recno` and `outno` bound; also says whether its records
/// are independent (so blocks of them may be evaluated on several threads): not when a
/// definition counts them or a `:` constant keeps the value of the first record.
fn compile_program(mut prog: Program) -> Result<(Compiled, VarId, VarId, bool)> {
    let ids = prog.bind_vars(&["recno", "outno"]);
    let exe = prog.compile().map_err(anyhow::Error::new)?;
    let (recno, outno) = (ids[0], ids[1]);
    let independent =
        !exe.references_var(recno) && !exe.references_var(outno) && !exe.has_late_constants();
    Ok((exe, recno, outno, independent))
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
    use super::{atof, compile_program, parse_plain};

    /// The programs of tests/rcalc.rs's thread test take the parallel path (so that test
    /// compares two paths), and programs with record counters or late constants do not.
    #[test]
    fn independent_records_are_recognised() {
        let lib = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("lib");
        let cases: [(&[&str], bool); 6] = [
            (&["MF:2;Dx=$1;Dy=$2;Dz=$3;$1=rbin;$2=1/$1;$3=in(0)"], true),
            (&["$1=select($1,1,2);$2=$2;cond=$3+1"], true),
            (&["$1=$1*$2+$3;$3=sqrt($2)"], true),
            (&["$1=if($1-3.3333, f(1), $1)"], true),
            (&["$1=recno"], false),
            (&["first:$1;$1=$1-first"], false),
        ];
        for (k, (src, want)) in cases.into_iter().enumerate() {
            let mut p = fenestra_calc::Program::for_rcalc();
            if k == 0 {
                // as the thread test's `-f reinhart.cal -e …`
                p.load_file(&lib.join("reinhart.cal")).unwrap();
            }
            for e in src {
                p.load_str("-e", e).unwrap();
            }
            let (_, _, _, independent) = compile_program(p).unwrap();
            assert_eq!(independent, want, "{src:?}");
        }
    }

    #[test]
    fn plain_decimals_parse_as_str_parse_does() {
        let mut s = 7u64;
        let mut n = 0;
        for _ in 0..200_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let int = (s >> 20) % 10u64.pow(((s >> 8) % 12) as u32);
            let frac = (s >> 40) % 1_000_000;
            let w = format!(
                "{}{int}.{frac:0w$}",
                ["", "-", "+"][(s % 3) as usize],
                w = ((s >> 4) % 7) as usize
            );
            let want: f64 = w.parse().unwrap();
            if let Some(v) = parse_plain(w.as_bytes()) {
                assert_eq!(v.to_bits(), want.to_bits(), "{w}");
                n += 1;
            }
        }
        assert!(n > 150_000, "{n} plain words");
        for w in [
            "",
            "-",
            ".",
            "1e3",
            "1.5.",
            "0x1",
            "nan",
            "1 ",
            "99999999999999999999",
        ] {
            assert_eq!(parse_plain(w.as_bytes()), None, "{w}");
        }
        assert_eq!(
            parse_plain(b"-0.000").map(f64::to_bits),
            Some((-0.0f64).to_bits())
        );
        assert_eq!(parse_plain(b"5."), Some(5.0));
        assert_eq!(parse_plain(b".25"), Some(0.25));
        // whole lines (eight digits at a time where eight bytes follow)
        let mut line = String::new();
        let mut words = Vec::new();
        for _ in 0..50_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let int = (s >> 20) % 10u64.pow(((s >> 8) % 13) as u32);
            let frac = (s >> 40) % 10u64.pow(((s >> 2) % 12) as u32);
            let w = match s % 5 {
                0 => format!("{int}"),
                1 => format!("-{int}.{frac}"),
                2 => format!("{int}.{frac:09}"),
                3 => format!("{int}.{frac}e{}", (s >> 30) % 7),
                _ => format!("+{int}.{frac}x"),
            };
            line += &w;
            line.push([' ', '\t', ' '][(s >> 50) as usize % 3]);
            words.push(w);
        }
        let mut cols = Vec::new();
        let len = super::ws_line(line.as_bytes(), &mut cols).unwrap();
        assert_eq!(len, line.len());
        assert_eq!(cols.len(), words.len());
        for (w, v) in words.iter().zip(&cols) {
            assert_eq!(v.to_bits(), atof(w).to_bits(), "{w}");
        }
    }

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
