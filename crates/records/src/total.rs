//! total's engine: sums, means, powers, products and extrema of the columns of text or
//! binary records, as Radiance's total computes and prints them (`%.9g`, products in
//! extended precision).

use std::io::{BufRead, Write};

use anyhow::{bail, Context, Result};
use fenestra_formats::matrix::format_c_g;

#[derive(Debug, Clone, Copy, PartialEq)]
/// What total computes per column.
pub enum Mode {
    /// Sums.
    Sum,
    /// Sums of |x|^E over non-zero x (`-sE`).
    Power(f64),
    /// Products (`-p`).
    Product,
    /// Maxima (`-u`).
    Max,
    /// Minima (`-l`).
    Min,
}

#[derive(Debug, Clone, Copy, PartialEq)]
/// A binary record encoding.
pub enum Binary {
    /// 32-bit floats.
    Float,
    /// 64-bit floats.
    Double,
}

/// total's settings from its command line.
#[derive(Debug, Clone)]
pub struct Settings {
    /// `-m`: means instead of sums (geometric for products, (mean |x|^E)^(1/E) for powers).
    pub mean: bool,
    /// What is computed.
    pub mode: Mode,
    /// `-tC`: the field separator (in and out; default white space in, tab out).
    pub sep: Option<char>,
    /// `-if[N]`/`-id[N]`: binary records of N values (`None`: text).
    pub input: Option<(Binary, usize)>,
    /// `-of`/`-od`: binary output (`None`: text).
    pub output: Option<Binary>,
    /// `-N`: a result every N records (0: one per set).
    pub count: usize,
    /// `-r`: running results.
    pub running: bool,
}

/// Largest magnitude extrema start from (as Radiance's total).
pub const HUGE: f64 = 1e12;

/// C `atof` (fenestra_cli::num::atof), with `nan` counting as 0 (what Radiance's total
/// makes of it in sums).
pub fn atof(s: &str) -> f64 {
    let v = fenestra_cli::num::atof(s);
    if v.is_nan() {
        0.0
    } else {
        v
    }
}

/// Accumulators for one result.
struct Acc {
    mode: Mode,
    vals: Vec<f64>,
    rows: usize,
    /// Columns of the records since the last result (the width printed).
    width: usize,
    /// Products that met an exact zero (printed as +0, as Radiance's total does).
    zero: Vec<bool>,
    /// Low parts of products kept in double-double (Radiance's total multiplies in
    /// extended precision; this reproduces its rounding).
    lo: Vec<f64>,
}

impl Acc {
    fn new(mode: Mode) -> Acc {
        Acc {
            mode,
            vals: Vec::new(),
            rows: 0,
            width: 0,
            zero: Vec::new(),
            lo: Vec::new(),
        }
    }

    fn init(&self) -> f64 {
        match self.mode {
            Mode::Sum | Mode::Power(_) => 0.0,
            Mode::Product => 1.0,
            Mode::Max => -HUGE,
            Mode::Min => HUGE,
        }
    }

    fn reset(&mut self) {
        self.vals.clear();
        self.rows = 0;
        self.width = 0;
        self.zero.clear();
        self.lo.clear();
    }

    /// After a result: start afresh, or (running) only the printed width.
    fn next(&mut self, running: bool) {
        if running {
            self.width = 0;
        } else {
            self.reset();
        }
    }

    fn add(&mut self, row: &[f64]) {
        if row.len() > self.vals.len() {
            let init = self.init();
            self.vals.resize(row.len(), init);
            self.zero.resize(row.len(), false);
            self.lo.resize(row.len(), 0.0);
        }
        let cols = self.vals.iter_mut().zip(row).zip(&mut self.zero);
        for (((a, &x), z), l) in cols.zip(&mut self.lo) {
            match self.mode {
                Mode::Sum => *a += x,
                Mode::Power(e) => {
                    if x != 0.0 {
                        *a += x.abs().powf(e);
                    }
                }
                Mode::Product => {
                    let p = *a * x;
                    if p.is_finite() && p != 0.0 {
                        let e = a.mul_add(x, -p) + *l * x;
                        let hi = p + e;
                        *l = e - (hi - p);
                        *a = hi;
                    } else {
                        *a = p;
                        *l = 0.0;
                    }
                    *z |= x == 0.0;
                }
                Mode::Max => {
                    if x > *a {
                        *a = x
                    }
                }
                Mode::Min => {
                    if x < *a {
                        *a = x
                    }
                }
            }
        }
        self.rows += 1;
        self.width = self.width.max(row.len());
    }

    fn result(&self, mean: bool, out: &mut Vec<f64>) {
        out.clear();
        // Radiance multiplies by the reciprocal of the count.
        let inv = 1.0 / self.rows as f64;
        for (&v, &z) in self.vals[..self.width].iter().zip(&self.zero) {
            let v = if z { 0.0 } else { v };
            out.push(if !mean {
                v
            } else {
                match self.mode {
                    Mode::Sum => v * inv,
                    Mode::Power(e) => (v * inv).powf(1.0 / e),
                    Mode::Product => {
                        if v < 0.0 {
                            -(-v).powf(inv)
                        } else {
                            v.powf(inv)
                        }
                    }
                    Mode::Max | Mode::Min => v,
                }
            });
        }
    }
}

struct Printer<W: Write> {
    w: W,
    output: Option<Binary>,
    sep: char,
    text: String,
    buf: Vec<f64>,
}

impl<W: Write> Printer<W> {
    fn print(&mut self, acc: &Acc, mean: bool) -> Result<()> {
        acc.result(mean, &mut self.buf);
        match self.output {
            None => {
                self.text.clear();
                for (i, &v) in self.buf.iter().enumerate() {
                    if i > 0 {
                        self.text.push(self.sep);
                    }
                    format_c_g(&mut self.text, v, 9);
                }
                self.text.push('\n');
                self.w.write_all(self.text.as_bytes())?;
            }
            Some(Binary::Float) => {
                for &v in &self.buf {
                    self.w.write_all(&(v as f32).to_ne_bytes())?;
                }
            }
            Some(Binary::Double) => {
                for &v in &self.buf {
                    self.w.write_all(&v.to_ne_bytes())?;
                }
            }
        }
        Ok(())
    }
}

/// Adds a record; with `-N`, prints the result when `N` records are pending.
fn add_counted<W: Write>(
    acc: &mut Acc,
    row: &[f64],
    pending: &mut usize,
    o: &Settings,
    p: &mut Printer<W>,
) -> Result<()> {
    acc.add(row);
    *pending += 1;
    if o.count > 0 && *pending == o.count {
        p.print(acc, o.mean)?;
        *pending = 0;
        acc.next(o.running);
    }
    Ok(())
}

/// Totals one input.
fn total_one<W: Write>(
    r: &mut dyn BufRead,
    name: &str,
    o: &Settings,
    p: &mut Printer<W>,
) -> Result<()> {
    let mut acc = Acc::new(o.mode);
    let mut row: Vec<f64> = Vec::new();
    match o.input {
        Some((kind, n)) => {
            let size = match kind {
                Binary::Float => 4,
                Binary::Double => 8,
            };
            let mut bytes = vec![0u8; size * n];
            let mut pending = 0;
            let mut rec = 0usize;
            loop {
                let got = fenestra_formats::matrix::read_full(r, &mut bytes)
                    .with_context(|| format!("{name}: read error"))?;
                if got == 0 {
                    break;
                }
                if got < bytes.len() {
                    bail!(
                        "{name}: {got} bytes at the end do not make a whole record of {n} {} (after {rec} records)",
                        if kind == Binary::Float { "floats" } else { "doubles" }
                    );
                }
                row.clear();
                for c in bytes.chunks_exact(size) {
                    row.push(if size == 4 {
                        f32::from_ne_bytes([c[0], c[1], c[2], c[3]]) as f64
                    } else {
                        f64::from_ne_bytes(c.try_into().unwrap_or([0; 8]))
                    });
                }
                rec += 1;
                add_counted(&mut acc, &row, &mut pending, o, p)?;
            }
            if pending > 0 {
                p.print(&acc, o.mean)?;
            }
        }
        None => {
            let mut line = Vec::new();
            let mut lineno = 0usize;
            'sets: loop {
                let mut pending = 0;
                let mut eof = false;
                loop {
                    line.clear();
                    let n = r
                        .read_until(b'\n', &mut line)
                        .with_context(|| format!("{name}: read error after line {lineno}"))?;
                    if n == 0 {
                        eof = true;
                        break;
                    }
                    lineno += 1;
                    let text = String::from_utf8_lossy(&line);
                    if text.trim().is_empty() {
                        break;
                    }
                    row.clear();
                    match o.sep {
                        Some(c) if !c.is_whitespace() => {
                            row.extend(text.trim_end_matches(['\n', '\r']).split(c).map(atof))
                        }
                        _ => row.extend(text.split_whitespace().map(atof)),
                    }
                    add_counted(&mut acc, &row, &mut pending, o, p)?;
                }
                if pending == 0 {
                    break 'sets;
                }
                p.print(&acc, o.mean)?;
                acc.next(o.running);
                if eof {
                    break;
                }
            }
        }
    }
    Ok(())
}

/// Totals each input of `files` in turn (`-` is the standard input), writing the results
/// to `out`.
pub fn run(o: &Settings, files: &[String], out: impl Write) -> Result<()> {
    let mut p = Printer {
        w: std::io::BufWriter::with_capacity(1 << 16, out),
        output: o.output,
        sep: o.sep.unwrap_or('\t'),
        text: String::new(),
        buf: Vec::new(),
    };
    for f in files {
        let mut r = fenestra_cli::input::open(f)?;
        let name = if f == "-" { "<stdin>" } else { f.as_str() };
        total_one(&mut *r, name, o, &mut p)?;
    }
    p.w.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atof_is_c_atof_with_nan_as_zero() {
        // the numeric prefixes themselves are tested in fenestra_cli::num
        for (s, v) in [("12abc", 12.0), ("0x10", 16.0), ("abc", 0.0), ("nan", 0.0)] {
            assert_eq!(atof(s), v, "{s}");
        }
        assert_eq!(atof("-inf"), f64::NEG_INFINITY);
        assert_eq!(atof("INF"), f64::INFINITY);
    }
}
