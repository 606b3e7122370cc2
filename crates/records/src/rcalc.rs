//! rcalc's engine: a compiled program evaluated on every input record (columns `$1…$N`
//! in, channels `$1=…` out) as Radiance's rcalc does; blocks of independent records are
//! evaluated on several threads, output in input order.

use std::io::{BufRead, Read, Write};

use anyhow::{Context, Result};
use fenestra_calc::format::push_g;
use fenestra_calc::{Compiled, Program, State, VarId};

use crate::scan::{line_cols, ws_line};

/// The number-stream format of rcalc's `-i`/`-o` (ascii, float, double).
pub type Fmt = fenestra_cli::rays::RayFormat;

/// rcalc's settings from its command line.
#[derive(Debug, Clone)]
pub struct Settings {
    /// `-i`: input format.
    pub ifmt: Fmt,
    /// `-i` count: columns per record (0: every column of a text line).
    pub icount: usize,
    /// `-o`: output format.
    pub ofmt: Fmt,
    /// `-t`: the column separator (in and out; default white space in, tab out).
    pub sep: Option<String>,
    /// `-u`: flush the output after each record.
    pub flush: bool,
    /// Warnings on (`-w` turns them off).
    pub warn: bool,
    /// Evaluator threads for independent records (1: one thread).
    pub threads: usize,
}

/// Runs `prog` on the records of `files` in turn (`-` is the standard input), or once
/// without input when `files` is `None` (`-n`), writing the records to `out`.
pub fn run(
    prog: Program,
    s: &Settings,
    files: Option<&[String]>,
    out: &mut dyn Write,
) -> Result<()> {
    let (exe, recno, outno, independent) = compile_program(prog)?;
    let maxchan = exe.channels().last().copied().unwrap_or(0) as usize;
    let mut outs = vec![false; maxchan];
    for n in exe.channels() {
        outs[n as usize - 1] = true;
    }
    let cond = exe.var("cond");
    let sep_out = s.sep.clone().unwrap_or_else(|| "\t".into());
    let mk = |counters: bool| Eval {
        exe: &exe,
        st: exe.state(),
        outs: &outs,
        cond,
        counters: counters.then_some((recno, outno)),
        nout: 0,
        nrec: 0,
        ofmt: s.ofmt,
        sep: sep_out.as_bytes(),
        warn: s.warn,
        warnings: Vec::new(),
        scratch: String::new(),
    };
    let Some(files) = files else {
        let mut ev = mk(true);
        let mut buf = Vec::new();
        let r = ev.record(&mut buf);
        out.write_all(&buf)?;
        out.flush()?;
        r?;
        ev.print_warnings();
        return Ok(());
    };
    let framing = match s.ifmt {
        Fmt::Ascii => Framing::Ascii {
            sep: s.sep.as_deref().and_then(|s| s.chars().next()),
            count: s.icount,
        },
        Fmt::Float => Framing::Binary {
            n: s.icount.max(1),
            size: 4,
        },
        Fmt::Double => Framing::Binary {
            n: s.icount.max(1),
            size: 8,
        },
    };
    let threads = s.threads.max(1);
    if threads > 1 && independent && !s.flush {
        let mkp = || mk(false);
        for f in files {
            let input = fenestra_cli::input::open(f)?;
            run_parallel(&mkp, framing, f, input, threads, out)?;
        }
        out.flush()?;
        return Ok(());
    }
    let mut ev = mk(true);
    if !s.flush {
        // one thread, blocks of records
        for f in files {
            let mut input = fenestra_cli::input::open(f)?;
            let mut carry = Vec::new();
            loop {
                let (block, last, err) = next_block(&mut input, framing, &mut carry);
                let mut done = eval_block(&mut ev, framing, f, &block, last);
                if let (None, Some(e)) = (&done.err, err) {
                    done.err = Some(anyhow::Error::new(e).context(format!("reading {f}")));
                }
                emit_block(out, done)?;
                if last {
                    break;
                }
            }
        }
        out.flush()?;
        return Ok(());
    }
    // -u: record by record, the output flushed after each
    let mut buf: Vec<u8> = Vec::new();
    let mut cols: Vec<f64> = Vec::new();
    for f in files {
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
                        flush_record(&mut ev, &cols, &mut buf, out)?;
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
                        flush_record(&mut ev, &cols, &mut buf, out)?;
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
    Ok(())
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

/// `-u`: evaluates one record and writes its output (and warnings) at once.
fn flush_record(ev: &mut Eval, cols: &[f64], buf: &mut Vec<u8>, out: &mut dyn Write) -> Result<()> {
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
    use super::compile_program;

    /// The programs of tests/rcalc.rs's thread test take the parallel path (so that test
    /// compares two paths), and programs with record counters or late constants do not.
    #[test]
    fn independent_records_are_recognised() {
        let lib = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../lib");
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
}
