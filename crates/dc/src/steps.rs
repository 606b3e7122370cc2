//! dctimestep's engine: loading T·D (XML or matrices), reading sky vectors and matrices
//! (streamed, checked against their sizes), the V·(T·D·s) time stepping in blocks of
//! result rows written as they are done, and the picture form (one V picture per sky
//! patch, weighted).

use fenestra_cli::raypath::Resolver;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::process::ExitCode;

use anyhow::{anyhow, bail, Context, Result};
use fenestra_formats::matrix::{format_c_e, DataFormat, Matrix, MatrixInfo, MatrixReader};
use fenestra_formats::picture::{capdate_lines, Picture};
use fenestra_formats::picture_rle::write_scanline;
use fenestra_formats::resolution::Resolution;
use fenestra_formats::rgbe;
use rayon::prelude::*;

use crate::timestep::{multiply, PackedSky, Planar, MR};

/// Values kept in memory per block of result rows (rows × steps × 3).
const BLOCK_VALUES: usize = 4 << 20;
/// Sky panels multiplied at a time inside a block (keeps the partial result in cache).
const PANELS_PER_GROUP: usize = 64;

/// What dctimestep was asked for: input and output formats, output name, reshaping,
/// header, and the command line for the header.
pub struct StepOptions {
    /// `nsteps`.
    pub nsteps: Option<usize>,
    /// `in_fmt`.
    pub in_fmt: Option<DataFormat>,
    /// `out_fmt`.
    pub out_fmt: DataFormat,
    /// `out_spec`.
    pub out_spec: Option<String>,
    /// `xres`.
    pub xres: Option<usize>,
    /// `yres`.
    pub yres: Option<usize>,
    /// `header`.
    pub header: bool,
    /// `command`.
    pub command: String,
}

/// Loads T (XML found through `resolver`, or a matrix) and D, checks their sizes, and
/// returns T·D with the number of rows of T.
pub fn load_td(tname: &str, dname: &str, resolver: &Resolver) -> Result<(Planar, usize)> {
    let t = load_t(tname, resolver)?;
    let d = Matrix::read_reporting(dname, fenestra_cli::warn_note)?;
    if d.nrows != t.cols {
        bail!(
            "{dname} has {} rows, but T ({tname}) has {} columns: the daylight matrix must have one row per column of T",
            d.nrows,
            t.cols
        );
    }
    let d = Planar::from_interleaved(d.nrows, d.ncols, d.ncomp, &d.data)
        .with_context(|| dname.to_string())?;
    let rows = t.rows;
    Ok((t.mul(&d)?, rows))
}

/// T from a BSDF XML file (found through `resolver`, as Radiance builds T from it) or a
/// matrix file.
pub fn load_t(name: &str, resolver: &Resolver) -> Result<Planar> {
    if !name.starts_with('!') && name.to_ascii_lowercase().ends_with(".xml") {
        let path = resolver
            .find(name)
            .unwrap_or_else(|| Path::new(name).into());
        let b = fenestra_bsdf::read_file(&path).map_err(|e| anyhow!("{e}"))?;
        let m =
            fenestra_bsdf::radiance::transmission_matrix(&b).map_err(|e| anyhow!("{name}: {e}"))?;
        let mut p = Planar::zeros(m.rows, m.cols);
        for (i, v) in m.data.iter().enumerate() {
            for (plane, x) in p.data.iter_mut().zip(v) {
                plane[i] = *x;
            }
        }
        return Ok(p);
    }
    let m = Matrix::read_reporting(name, fenestra_cli::warn_note)?;
    Planar::from_interleaved(m.nrows, m.ncols, m.ncomp, &m.data).with_context(|| name.to_string())
}

/// Reads the sky (vector or matrix) into panels; `rows` is the number of patches
/// the left side needs (0: take the sky's own).
pub fn read_sky(
    name: &str,
    rows: usize,
    o: &StepOptions,
    dname: Option<&str>,
    vname: &str,
) -> Result<PackedSky> {
    let mut r = match o.nsteps {
        Some(n) => {
            let fmt = o.in_fmt.unwrap_or(DataFormat::Ascii);
            if rows == 0 {
                bail!("-n with the picture form needs a matrix left side to know the sky size");
            }
            let info = MatrixInfo::headerless(Some(rows), n, 3, fmt);
            MatrixReader::headerless(fenestra_cli::input::open(name)?, name, info)?
                .report_to(fenestra_cli::warn_note)
        }
        None => {
            let r = MatrixReader::open(name)?.report_to(fenestra_cli::warn_note);
            if let Some(f) = o.in_fmt {
                if f != r.info.format {
                    bail!(
                        "{name}: sky data are {} but -i{} was given",
                        r.info.format,
                        &f.as_str()[..1]
                    );
                }
            }
            r
        }
    };
    let shown = if name == "-" { "<stdin>" } else { name };
    if r.info.ncomp != 3 {
        bail!(
            "{shown}: sky matrix has NCOMP={} (3 components expected)",
            r.info.ncomp
        );
    }
    if rows > 0 {
        if let Some(nr) = r.info.nrows {
            if nr != rows {
                let what = match dname {
                    Some(d) => format!("the daylight matrix {d} has {rows} columns"),
                    None => format!("the matrix {vname} has {rows} columns"),
                };
                bail!("{shown}: sky has {nr} rows (patches), but {what}");
            }
        }
    }
    let steps = r.info.ncols;
    let mut rowbuf = vec![0.0; r.info.row_len()];
    let mut rows_v: Vec<Vec<f64>> = Vec::new();
    // allocated at once when the file's size vouches for the header's shape (or the shape
    // is small); a pipe's rows are gathered as they come
    let small = |nr: usize| (nr as u128) * (r.info.row_len() as u128) <= 1 << 24;
    let mut sky = r
        .info
        .nrows
        .filter(|&nr| r.size_checked() || small(nr))
        .map(|nr| PackedSky::new(nr, steps));
    let mut k = 0;
    while r.read_row(&mut rowbuf)? {
        match sky.as_mut() {
            Some(s) => s.set_row(k, &rowbuf, 3),
            None => rows_v.push(rowbuf.clone()),
        }
        k += 1;
    }
    let sky = match sky {
        Some(s) => s,
        None => {
            if rows > 0 && k != rows {
                bail!("{shown}: sky has {k} rows (patches), {rows} expected");
            }
            if let Some(nr) = r.info.nrows.filter(|&nr| nr != k) {
                bail!("{shown}: sky has {k} rows but its header says NROWS={nr}");
            }
            let mut s = PackedSky::new(k, steps);
            for (i, row) in rows_v.iter().enumerate() {
                s.set_row(i, row, 3);
            }
            s
        }
    };
    if o.nsteps.is_none() && r.has_trailing_data() {
        fenestra_cli::warn(format!("{shown}: data beyond the sky matrix ignored"));
    }
    Ok(sky)
}

/// Output shape after `-x`/`-y` for a result of `nrows × ncols`.
fn reshape(nrows: usize, ncols: usize, o: &StepOptions) -> Result<(usize, usize)> {
    let total = nrows * ncols;
    match (o.xres, o.yres) {
        (None, None) => Ok((nrows, ncols)),
        (Some(x), Some(y)) => {
            if x * y != total {
                bail!("Bad dimensions: {y}x{x} != {nrows}x{ncols}");
            }
            Ok((y, x))
        }
        (Some(x), None) => {
            if total % x != 0 {
                bail!("Bad dimensions: {x} does not divide {nrows}x{ncols} evenly");
            }
            Ok((total / x, x))
        }
        (None, Some(y)) => {
            if total % y != 0 {
                bail!("Bad dimensions: {y} does not divide {nrows}x{ncols} evenly");
            }
            Ok((y, total / y))
        }
    }
}

/// The output header (empty with `-h`).
fn header_bytes(
    o: &StepOptions,
    frame: Option<usize>,
    nrows: usize,
    ncols: usize,
    align_from: Option<u64>,
) -> Vec<u8> {
    let mut h = String::new();
    if o.header {
        h.push_str("#?RADIANCE\n");
        h.push_str(&o.command);
        h.push('\n');
        for l in capdate_lines() {
            h.push_str(&l);
            h.push('\n');
        }
        if let Some(f) = frame {
            h.push_str(&format!("FRAME={f}\n"));
        }
        if o.out_fmt.is_picture() {
            h.push_str("FORMAT=32-bit_rle_rgbe\n\n");
        } else {
            h.push_str(&format!("NROWS={nrows}\nNCOLS={ncols}\nNCOMP=3\n"));
            if o.out_fmt.value_size().is_some() {
                h.push_str(&format!(
                    "BigEndian={}\n",
                    u8::from(fenestra_formats::matrix::NATIVE_BIG_ENDIAN)
                ));
            }
            h.push_str(&format!("FORMAT={}", o.out_fmt.as_str()));
            if let Some(off) = align_from {
                let align = o.out_fmt.alignment() as u64;
                while (off + h.len() as u64 + 2) % align != 0 {
                    h.push(' ');
                }
            }
            h.push_str("\n\n");
        }
    }
    if o.out_fmt.is_picture() {
        h.push_str(&Resolution::standard(ncols, nrows).to_string());
    }
    h.into_bytes()
}

/// Where results go: standard output or an atomically written file.
enum Dest {
    Stdout(BufWriter<std::io::Stdout>),
    File(BufWriter<fenestra_cli::output::AtomicFile>),
}

impl Dest {
    fn open(name: Option<&str>) -> Result<(Dest, Option<u64>)> {
        match name {
            None => {
                let off = fenestra_cli::output::stdout_file_offset();
                Ok((
                    Dest::Stdout(BufWriter::with_capacity(1 << 20, std::io::stdout())),
                    off,
                ))
            }
            Some(n) => Ok((
                Dest::File(BufWriter::with_capacity(
                    1 << 20,
                    fenestra_cli::output::AtomicFile::create(n)?,
                )),
                Some(0),
            )),
        }
    }

    fn w(&mut self) -> &mut dyn Write {
        match self {
            Dest::Stdout(w) => w,
            Dest::File(w) => w,
        }
    }

    fn finish(self) -> Result<()> {
        match self {
            Dest::Stdout(mut w) => {
                w.flush()?;
                Ok(())
            }
            Dest::File(w) => {
                let f = w.into_inner().map_err(|e| anyhow!("{}", e.error()))?;
                f.commit()
            }
        }
    }
}

/// Encodes elements into the output stream, breaking lines (ascii) or scanlines
/// (RGBE) every `ocols` elements.
struct Sink {
    fmt: DataFormat,
    ocols: usize,
    scan: Vec<[u8; 4]>,
}

impl Sink {
    fn new(fmt: DataFormat, ocols: usize) -> Self {
        Sink {
            fmt,
            ocols,
            scan: Vec::with_capacity(ocols),
        }
    }

    /// Encodes `vals` (consecutive elements starting at element `first`) into bytes;
    /// pure, so it may run in parallel.
    fn encode(fmt: DataFormat, ocols: usize, first: usize, vals: &[[f64; 3]]) -> Vec<u8> {
        match fmt {
            DataFormat::Ascii => {
                let mut s = String::with_capacity(vals.len() * 42);
                for (i, v) in vals.iter().enumerate() {
                    for (c, &x) in v.iter().enumerate() {
                        if c > 0 {
                            s.push(' ');
                        }
                        format_c_e(&mut s, x as f32 as f64, 6);
                    }
                    s.push(if (first + i + 1) % ocols == 0 {
                        '\n'
                    } else {
                        '\t'
                    });
                }
                s.into_bytes()
            }
            DataFormat::Float => {
                let mut b = Vec::with_capacity(vals.len() * 12);
                for v in vals {
                    for &x in v {
                        b.extend_from_slice(&(x as f32).to_ne_bytes());
                    }
                }
                b
            }
            DataFormat::Double => {
                let mut b = Vec::with_capacity(vals.len() * 24);
                for v in vals {
                    for &x in v {
                        b.extend_from_slice(&((x as f32) as f64).to_ne_bytes());
                    }
                }
                b
            }
            DataFormat::Rgbe | DataFormat::Xyze => {
                let mut b = Vec::with_capacity(vals.len() * 4);
                for v in vals {
                    b.extend_from_slice(&rgbe::encode([v[0] as f32, v[1] as f32, v[2] as f32]));
                }
                b
            }
        }
    }

    /// Writes encoded bytes of `n` elements.
    fn put(&mut self, w: &mut dyn Write, bytes: &[u8]) -> Result<()> {
        if self.fmt.is_picture() {
            for p in bytes.chunks_exact(4) {
                self.scan.push([p[0], p[1], p[2], p[3]]);
                if self.scan.len() == self.ocols {
                    write_scanline(&mut &mut *w, &self.scan)?;
                    self.scan.clear();
                }
            }
        } else {
            w.write_all(bytes)?;
        }
        Ok(())
    }
}

/// Rows of the left matrix: streamed from its reader, or from memory when the
/// header had no NROWS (the whole matrix is then read first to learn its size).
struct VRows {
    reader: MatrixReader,
    held: Option<(Vec<f64>, usize)>,
}

impl VRows {
    fn new(mut reader: MatrixReader) -> Result<Self> {
        let mut held = None;
        if reader.info.nrows.is_none() {
            let len = reader.info.row_len();
            let mut all = Vec::new();
            let mut row = vec![0.0; len];
            let mut n = 0;
            while reader.read_row(&mut row)? {
                all.extend_from_slice(&row);
                n += 1;
            }
            reader.info.nrows = Some(n);
            held = Some((all, 0));
        }
        Ok(VRows { reader, held })
    }

    fn nrows(&self) -> usize {
        self.reader.info.nrows.unwrap_or(0)
    }

    /// Reads up to `max` rows into `buf`; returns the number read.
    fn read(&mut self, buf: &mut Vec<f64>, max: usize) -> Result<usize> {
        let len = self.reader.info.row_len();
        if let Some((all, pos)) = self.held.as_mut() {
            let n = ((all.len() / len) - *pos).min(max);
            buf.clear();
            buf.extend_from_slice(&all[*pos * len..(*pos + n) * len]);
            *pos += n;
            return Ok(n);
        }
        buf.resize(max * len, 0.0);
        let mut n = 0;
        while n < max && self.reader.read_row(&mut buf[n * len..(n + 1) * len])? {
            n += 1;
        }
        buf.truncate(n * len);
        Ok(n)
    }
}

/// `V·(T·D)·S` (or `DC·S`) with V streamed in blocks of rows.
pub fn matrix_form(
    opened: Option<MatrixReader>,
    vname: &str,
    td: Option<&Planar>,
    td_names: Option<&(String, String)>,
    sky: &PackedSky,
    o: &StepOptions,
) -> Result<()> {
    let vr = match opened {
        Some(r) => r,
        None => MatrixReader::open(vname)?.report_to(fenestra_cli::warn_note),
    };
    let need = td.map(|m| m.rows).unwrap_or(sky.patches());
    if vr.info.ncols != need {
        match td_names {
            Some((t, _)) => bail!(
                "{vname} has {} columns, but T ({t}) has {need} rows",
                vr.info.ncols
            ),
            None => bail!(
                "{vname} has {} columns, but the sky has {need} rows (patches)",
                vr.info.ncols
            ),
        }
    }
    if vr.info.ncomp != 3 && vr.info.ncomp != 1 {
        bail!(
            "{vname}: NCOMP={} (1 or 3 components expected)",
            vr.info.ncomp
        );
    }
    let ncomp = vr.info.ncomp;
    let steps = sky.steps();
    let per_step = match (o.out_spec.as_deref(), steps) {
        (Some(s), n) if n > 1 && fenestra_cli::printf::has_int_field(s) => Some(s.to_string()),
        _ => None,
    };
    let left = |vbuf: &[f64], n: usize| -> Result<Planar> {
        match td {
            Some(m) => m.left_mul_rows(vbuf, n, ncomp),
            None => Ok(Planar::from_interleaved(n, need, ncomp, vbuf)?.padded_rows()),
        }
    };
    let mut vbuf = Vec::new();

    if let Some(pattern) = per_step {
        // One file per time step: all of W first, then groups of steps.
        let mut vr = VRows::new(vr)?;
        let mut w = Planar::zeros(0, sky.patches());
        let mut nrows = 0;
        loop {
            let n = vr.read(&mut vbuf, 1024)?;
            if n == 0 {
                break;
            }
            let b = left(&vbuf, n)?;
            for c in 0..3 {
                w.data[c].truncate(nrows * w.cols);
                w.data[c].extend_from_slice(&b.data[c]);
            }
            nrows += n;
            w.rows = nrows;
        }
        check_rows(&vr, nrows, vname)?;
        let w = w.padded_rows();
        let (orows, ocols) = reshape(nrows, 1, o)?;
        let group = (BLOCK_VALUES / (w.rows.max(1) * 3 * crate::timestep::PANEL)).max(1);
        let mut p = 0;
        while p < sky.panels() {
            let p1 = (p + group).min(sky.panels());
            let res = multiply(&w, sky, p..p1)?;
            res.steps()
                .into_par_iter()
                .try_for_each(|t| -> Result<()> {
                    let name = fenestra_cli::printf::format_int_field(&pattern, t)?;
                    let (mut dest, off) = Dest::open(Some(&name))?;
                    dest.w()
                        .write_all(&header_bytes(o, Some(t), orows, ocols, off))?;
                    let mut sink = Sink::new(o.out_fmt, ocols);
                    let vals: Vec<[f64; 3]> = (0..nrows)
                        .map(|r| [res.get(r, t, 0), res.get(r, t, 1), res.get(r, t, 2)])
                        .collect();
                    let bytes = Sink::encode(o.out_fmt, ocols, 0, &vals);
                    sink.put(dest.w(), &bytes)?;
                    dest.finish().with_context(|| format!("writing {name}"))
                })?;
            p = p1;
        }
        return Ok(());
    }

    let out_name = o
        .out_spec
        .as_deref()
        .map(|s| fenestra_cli::printf::format_int_field(s, 0))
        .transpose()?;
    let mut vr = VRows::new(vr)?;
    let nrows = vr.nrows();
    let (orows, ocols) = reshape(nrows, steps, o)?;
    let (mut dest, off) = Dest::open(out_name.as_deref())?;
    dest.w()
        .write_all(&header_bytes(o, None, orows, ocols, off))?;
    let mut sink = Sink::new(o.out_fmt, ocols);
    let block = (BLOCK_VALUES / (steps.max(1) * 3)).clamp(MR, 4096) / MR * MR;
    let mut done = 0;
    loop {
        let n = vr.read(&mut vbuf, block)?;
        if n == 0 {
            break;
        }
        let w = left(&vbuf, n)?;
        // Groups of time steps small enough for the cache, gathered into sensor rows.
        let mut rows = vec![[0.0f64; 3]; n * steps];
        let mut p = 0;
        while p < sky.panels() {
            let p1 = (p + PANELS_PER_GROUP).min(sky.panels());
            let res = multiply(&w, sky, p..p1)?;
            let st = res.steps();
            rows.par_chunks_mut(steps)
                .enumerate()
                .for_each(|(r, row)| res.row_into(r, &mut row[st.clone()]));
            p = p1;
        }
        let encoded: Vec<Vec<u8>> = rows
            .par_chunks(steps)
            .enumerate()
            .map(|(r, vals)| Sink::encode(o.out_fmt, ocols, (done + r) * steps, vals))
            .collect();
        for e in &encoded {
            sink.put(dest.w(), e)?;
        }
        done += n;
    }
    check_rows(&vr, done, vname)?;
    dest.finish()
}

fn check_rows(vr: &VRows, got: usize, vname: &str) -> Result<()> {
    let n = vr.nrows();
    if n != got {
        bail!("{vname}: {got} rows read, header says NROWS={n}");
    }
    Ok(())
}

/// Coefficient of component picture r, step t, channel c.
type CoefFn<'a> = dyn Fn(usize, usize, usize) -> f64 + 'a;

/// Picture form: each time step's result is the sum of the component pictures
/// `vspec % r` weighted by the coefficients `(T·D·S)[r]` (or `S[r]`).
pub fn picture_form(
    vspec: &str,
    td: Option<Planar>,
    sky: &PackedSky,
    o: &StepOptions,
) -> Result<ExitCode> {
    let steps = sky.steps();
    let (nimg, coef): (usize, Box<CoefFn>) = match td {
        Some(m) => {
            let n = m.rows;
            let res = multiply(&m.padded_rows(), sky, 0..sky.panels())?;
            (n, Box::new(move |r, t, c| res.get(r, t, c)))
        }
        None => (sky.patches(), Box::new(|r, t, c| sky.get(c, r, t))),
    };
    let mut cache: Vec<Option<Picture>> = Vec::new();
    cache.resize_with(nimg, || None);
    let mut dims: Option<(Resolution, String)> = None;
    let per_step = o
        .out_spec
        .as_deref()
        .filter(|s| steps > 1 && fenestra_cli::printf::has_int_field(s))
        .map(str::to_string);
    let mut stdout_dest: Option<(Dest, Option<u64>)> = None;
    for t in 0..steps {
        let mut sum: Vec<[f64; 3]> = Vec::new();
        let mut any = false;
        for (r, slot) in cache.iter_mut().enumerate() {
            let c = [coef(r, t, 0), coef(r, t, 1), coef(r, t, 2)];
            let last = r + 1 == nimg;
            if c == [0.0; 3] && !(last && !any && dims.is_none()) {
                continue;
            }
            if slot.is_none() {
                let name = fenestra_cli::printf::format_int_field(vspec, r)?;
                let mut rd = fenestra_cli::input::open(&name)?;
                let p = Picture::read(&mut rd, "dctimestep").map_err(|e| anyhow!("{name}: {e}"))?;
                match &dims {
                    Some((res, first)) if *res != p.res => bail!(
                        "{name}: picture size {} x {} differs from {first}'s {} x {}",
                        p.res.scanlen(),
                        p.res.numscans(),
                        res.scanlen(),
                        res.numscans()
                    ),
                    Some(_) => {}
                    None => dims = Some((p.res, name.clone())),
                }
                *slot = Some(p);
            }
            let p = slot.as_ref().expect("cached picture");
            if sum.is_empty() {
                sum = vec![[0.0; 3]; p.pixels.len()];
            }
            any = true;
            for (s, px) in sum.iter_mut().zip(&p.pixels) {
                for k in 0..3 {
                    s[k] += c[k] * px[k] as f64;
                }
            }
        }
        let (res, _) = dims
            .as_ref()
            .ok_or_else(|| anyhow!("no component picture read"))?;
        if sum.is_empty() {
            sum = vec![[0.0; 3]; res.scanlen() * res.numscans()];
        }
        let (w, h) = (res.scanlen(), res.numscans());
        // -x/-y do not apply to the picture form (Radiance ignores them there too).
        let frame = (steps > 1).then_some(t);
        let mut hb = if per_step.is_none() && t > 0 && o.header {
            // Later frames in one stream: Radiance writes only FRAME, FORMAT and the resolution.
            let mut b = format!("FRAME={t}\nFORMAT=32-bit_rle_rgbe\n\n").into_bytes();
            b.extend_from_slice(Resolution::standard(w, h).to_string().as_bytes());
            b
        } else {
            header_bytes(o, frame, h, w, None)
        };
        // Keep the pictures' own orientation.
        let std = Resolution::standard(w, h).to_string();
        if hb.ends_with(std.as_bytes()) {
            hb.truncate(hb.len() - std.len());
            hb.extend_from_slice(res.to_string().as_bytes());
        }
        // A picture file named *.exr is written as OpenEXR (one file per time step).
        let exr_name = match (&per_step, o.out_spec.as_deref()) {
            (Some(p), _) => Some(fenestra_cli::printf::format_int_field(p, t)?),
            (None, Some(spec)) if steps == 1 => {
                Some(fenestra_cli::printf::format_int_field(spec, 0)?)
            }
            _ => None,
        }
        .filter(|n| fenestra_formats::exr::is_exr_path(n));
        if let Some(name) = exr_name {
            if res.to_string() != Resolution::standard(w, h).to_string() {
                bail!("{name}: OpenEXR output needs component pictures in standard orientation");
            }
            let px: Vec<[f32; 3]> = sum
                .iter()
                .map(|v| [v[0] as f32, v[1] as f32, v[2] as f32])
                .collect();
            let head = fenestra_formats::picture::PictureHeader {
                command: Some(o.command.clone()),
                ..Default::default()
            };
            fenestra_formats::exr::write_picture_file(&name, Some(&head), w, h, &px)?;
            continue;
        }
        let enc = Sink::encode(DataFormat::Rgbe, w, 0, &sum);
        match &per_step {
            Some(p) => {
                let name = fenestra_cli::printf::format_int_field(p, t)?;
                let (mut d, _) = Dest::open(Some(&name))?;
                d.w().write_all(&hb)?;
                let mut sink = Sink::new(DataFormat::Rgbe, w);
                sink.put(d.w(), &enc)?;
                d.finish()?;
            }
            None => {
                if stdout_dest.is_none() {
                    let name = o
                        .out_spec
                        .as_deref()
                        .map(|s| fenestra_cli::printf::format_int_field(s, 0))
                        .transpose()?;
                    stdout_dest = Some(Dest::open(name.as_deref())?);
                }
                let (d, _) = stdout_dest.as_mut().expect("destination");
                d.w().write_all(&hb)?;
                let mut sink = Sink::new(DataFormat::Rgbe, w);
                sink.put(d.w(), &enc)?;
            }
        }
        if cache.iter().flatten().count() * sum.len() * 12 > (1 << 30) {
            cache.iter_mut().for_each(|c| *c = None);
        }
    }
    if let Some((d, _)) = stdout_dest {
        d.finish()?;
    }
    Ok(ExitCode::SUCCESS)
}
