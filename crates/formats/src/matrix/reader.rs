//! Streaming matrix reader: header first, then one row at a time.

use std::io::{BufRead, Read};

use anyhow::{bail, Context, Result};

use super::{ascii, rgbe, DataFormat, NATIVE_BIG_ENDIAN};
use crate::header::Header;

/// Largest number of values per row accepted (NCOLS × NCOMP): 2^25 values (a 256 MiB row
/// buffer) hold a year of one-minute sky columns 60 times over.
const MAX_ROW_VALUES: usize = 1 << 25;

/// What a matrix header says about its data.
#[derive(Debug, Clone, PartialEq)]
pub struct MatrixInfo {
    /// Rows (`None` when the header has no NROWS and the size cannot be inferred:
    /// rows are then read until the data end).
    pub nrows: Option<usize>,
    /// Columns.
    pub ncols: usize,
    /// Components per element (default 3).
    pub ncomp: usize,
    /// Storage format.
    pub format: DataFormat,
    /// Byte order of binary data.
    pub big_endian: bool,
    /// The whole header as read (empty for headerless input).
    pub header: Header,
}

impl MatrixInfo {
    /// Info for headerless data of known shape (e.g. `dctimestep -n` sky input).
    pub fn headerless(
        nrows: Option<usize>,
        ncols: usize,
        ncomp: usize,
        format: DataFormat,
    ) -> Self {
        MatrixInfo {
            nrows,
            ncols,
            ncomp,
            format,
            big_endian: NATIVE_BIG_ENDIAN,
            header: Header::new(),
        }
    }

    /// Values per row (`ncols × ncomp`).
    pub fn row_len(&self) -> usize {
        self.ncols * self.ncomp
    }

    /// The header lines a matrix tool keeps when it rewrites the data: everything
    /// except the identifier line and the keys that describe the data layout.
    pub fn retained_header(&self) -> Header {
        const DROP: [&str; 8] = [
            "NROWS",
            "NCOLS",
            "NCOMP",
            "FORMAT",
            "EXPOSURE",
            "COLORCORR",
            "WAVELENGTH_SPLITS",
            "BigEndian",
        ];
        let mut h = Header::new();
        for l in &self.header.lines {
            if l.starts_with("#?") {
                continue;
            }
            let key = l.split('=').next().unwrap_or("").trim_end();
            if l.contains('=') && DROP.contains(&key) {
                continue;
            }
            h.push(l.clone());
        }
        h
    }
}

/// Reads a matrix row by row without holding the whole file.
pub struct MatrixReader {
    /// Shape and format from the header.
    pub info: MatrixInfo,
    name: String,
    r: Box<dyn BufRead + Send>,
    rows_read: usize,
    /// Divisor per component (EXPOSURE × COLORCORR), or empty when 1.
    divide: Vec<f64>,
    swap: bool,
    bytes: Vec<u8>,
    pixels: Vec<[u8; 4]>,
    tok: Vec<u8>,
    size_checked: bool,
    warned_nonfinite: bool,
    /// Warnings noticed while reading, for the caller to report ([`Self::take_notes`]).
    notes: Vec<String>,
    /// Where warnings go at once instead ([`Self::report_to`]).
    sink: Option<fn(String)>,
}

impl MatrixReader {
    /// Whether the header's shape was checked against the size of the file (a regular
    /// file): its rows can be allocated at once. Data from a pipe may stop short.
    pub fn size_checked(&self) -> bool {
        self.size_checked
    }

    /// Opens `name`: `-` for stdin, `!command` for a command's output, else a file.
    /// For a file in a binary format without `NROWS=`, the row count is inferred from
    /// its size; a size too small for `NROWS=` is an error at once.
    pub fn open(name: &str) -> Result<MatrixReader> {
        let r = fenestra_io::input::open(name)?;
        let mut m = Self::from_boxed(r, name)?;
        if name != "-" && !name.is_empty() && !name.starts_with('!') {
            if let Ok(meta) = std::fs::metadata(name) {
                if meta.is_file() {
                    m.check_size(meta.len())?;
                }
            }
        }
        Ok(m)
    }

    /// Reads the header from `reader`; `name` is used in messages.
    pub fn from_reader(reader: impl BufRead + Send + 'static, name: &str) -> Result<MatrixReader> {
        Self::from_boxed(Box::new(reader), name)
    }

    /// Reads headerless data of the shape given in `info`.
    pub fn headerless(
        reader: impl BufRead + Send + 'static,
        name: &str,
        info: MatrixInfo,
    ) -> Result<MatrixReader> {
        Self::with_info(Box::new(reader), name, info)
    }

    fn from_boxed(mut r: Box<dyn BufRead + Send>, name: &str) -> Result<MatrixReader> {
        let header = Header::read(&mut r, name)?;
        let ctx = |e: anyhow::Error| e.context(format!("{name}: bad matrix header"));
        let format = match header.format() {
            None => DataFormat::Ascii,
            Some(f) => match DataFormat::from_header(f) {
                Some(d) => d,
                None if f == "Radiance_spectra" => {
                    bail!("{name}: FORMAT=Radiance_spectra (spectral matrices) is not supported by fenestra")
                }
                None => bail!("{name}: unknown data format FORMAT={} in header (expected ascii, float, double, 32-bit_rle_rgbe or 32-bit_rle_xyze)", crate::header::printable(f)),
            },
        };
        let nrows = header.nrows().map_err(ctx)?;
        let ncols = header.ncols().map_err(ctx)?;
        let ncomp = header.ncomp().map_err(ctx)?.unwrap_or(3);
        let exposure = header.exposure().map_err(ctx)?;
        let cc = header.colorcorr().map_err(ctx)?;
        let big_endian = header.big_endian().unwrap_or(NATIVE_BIG_ENDIAN);
        let (nrows, ncols) = if format.is_picture() {
            if ncomp != 3 {
                bail!("{name}: {format} data need NCOMP=3 (header says NCOMP={ncomp})");
            }
            match ncols {
                Some(c) => (nrows, c),
                None => {
                    let (y, x) = read_resolution(&mut r, name)?;
                    (Some(y), x)
                }
            }
        } else {
            let c = ncols.with_context(|| format!("{name}: missing NCOLS= in matrix header"))?;
            (nrows, c)
        };
        let info = MatrixInfo {
            nrows,
            ncols,
            ncomp,
            format,
            big_endian,
            header,
        };
        let mut m = Self::with_info(r, name, info)?;
        // one divisor per component, made only once the header's sizes are checked
        if exposure != 1.0 || cc != [1.0; 3] {
            m.divide = (0..ncomp)
                .map(|k| exposure * cc[if k < 3 { k } else { 1 }])
                .collect();
        }
        Ok(m)
    }

    fn with_info(r: Box<dyn BufRead + Send>, name: &str, info: MatrixInfo) -> Result<MatrixReader> {
        if info.ncols == 0 || info.ncomp == 0 {
            bail!("{name}: matrix has no columns or components");
        }
        let row_len = info
            .ncols
            .checked_mul(info.ncomp)
            .filter(|&n| n <= MAX_ROW_VALUES);
        if row_len.is_none() {
            bail!(
                "{name}: NCOLS={} × NCOMP={} is too large for a matrix row",
                info.ncols,
                info.ncomp
            );
        }
        let swap = info.format.value_size().is_some() && info.big_endian != NATIVE_BIG_ENDIAN;
        Ok(MatrixReader {
            info,
            name: name.to_string(),
            r,
            rows_read: 0,
            divide: Vec::new(),
            swap,
            bytes: Vec::new(),
            pixels: Vec::new(),
            tok: Vec::new(),
            size_checked: false,
            warned_nonfinite: false,
            notes: Vec::new(),
            sink: None,
        })
    }

    /// Checks (and for missing NROWS, infers) the row count of binary data from the
    /// file size `len` (header included).
    fn check_size(&mut self, len: u64) -> Result<()> {
        let data = len.saturating_sub(self.info.header.byte_len);
        self.size_checked = true;
        let Some(vs) = self.info.format.value_size() else {
            if self.info.format != DataFormat::Ascii {
                return Ok(());
            }
            // a text value takes at least one character and one separator
            let most = data / 2 + 1;
            let need = self.info.nrows.unwrap_or(1) as u128 * self.info.row_len() as u128;
            if need > most as u128 {
                bail!(
                    "{}: truncated ascii data: header says {}NCOLS={} NCOMP={} ({} values) but the file's {} bytes hold at most {}",
                    self.name,
                    self.info.nrows.map_or(String::new(), |n| format!("NROWS={n} ")),
                    self.info.ncols,
                    self.info.ncomp,
                    need,
                    data,
                    most
                );
            }
            return Ok(());
        };
        let row_bytes = (self.info.row_len() * vs) as u64;
        match self.info.nrows {
            None => {
                if data % row_bytes != 0 {
                    bail!(
                        "{}: {} bytes of {} data is not a whole number of {}-column rows (NROWS missing and cannot be inferred)",
                        self.name, data, self.info.format, self.info.ncols
                    );
                }
                self.info.nrows = Some((data / row_bytes) as usize);
            }
            Some(n) => {
                let need = (n as u128) * row_bytes as u128;
                if (data as u128) < need {
                    bail!(
                        "{}: truncated {} data: header says NROWS={} NCOLS={} NCOMP={} ({} bytes) but the file holds {} bytes",
                        self.name, self.info.format, n, self.info.ncols, self.info.ncomp, need, data
                    );
                }
                if (data as u128) > need {
                    self.note(format!(
                        "{}: {} bytes of data beyond NROWS={} NCOLS={} NCOMP={} ignored",
                        self.name,
                        data as u128 - need,
                        n,
                        self.info.ncols,
                        self.info.ncomp
                    ));
                }
            }
        }
        Ok(())
    }

    /// The warnings noticed so far (data beyond the header's rows, a value that is not a
    /// finite number), taken out for the caller to report: the reader prints nothing.
    pub fn take_notes(&mut self) -> Vec<String> {
        std::mem::take(&mut self.notes)
    }

    /// Hands the warnings to `sink` as they are noticed (those noticed so far at once),
    /// so a caller reports them when they happen, even if reading fails later.
    pub fn report_to(mut self, sink: fn(String)) -> Self {
        for n in self.notes.drain(..) {
            sink(n);
        }
        self.sink = Some(sink);
        self
    }

    /// A warning: to the sink, or kept for [`Self::take_notes`].
    pub(crate) fn note(&mut self, msg: String) {
        match self.sink {
            Some(s) => s(msg),
            None => self.notes.push(msg),
        }
    }

    /// The input's name as given.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Rows read so far.
    pub fn rows_read(&self) -> usize {
        self.rows_read
    }

    /// Reads the next row (`ncols × ncomp` values, components interleaved) into `out`.
    /// Returns `Ok(false)` when all rows have been read; truncated data are an error.
    pub fn read_row(&mut self, out: &mut [f64]) -> Result<bool> {
        let n = self.info.row_len();
        if out.len() != n {
            bail!(
                "{}: row buffer holds {} values, a row has {}",
                self.name,
                out.len(),
                n
            );
        }
        if self.info.nrows.is_some_and(|nr| self.rows_read >= nr) {
            return Ok(false);
        }
        let got = match self.info.format {
            DataFormat::Ascii => self.read_ascii(out)?,
            DataFormat::Float | DataFormat::Double => self.read_binary(out)?,
            DataFormat::Rgbe | DataFormat::Xyze => self.read_rgbe(out)?,
        };
        if !got {
            return match self.info.nrows {
                None => Ok(false),
                Some(nr) => bail!(
                    "{}: unexpected end of data after {} of {} rows (NROWS={} NCOLS={} NCOMP={}, {})",
                    self.name,
                    self.rows_read,
                    nr,
                    nr,
                    self.info.ncols,
                    self.info.ncomp,
                    self.info.format
                ),
            };
        }
        if !self.divide.is_empty() {
            let nc = self.info.ncomp;
            for (i, v) in out.iter_mut().enumerate() {
                *v /= self.divide[i % nc];
            }
        }
        self.rows_read += 1;
        if !self.warned_nonfinite && out.iter().any(|v| !v.is_finite()) {
            // carried through as Radiance does, but never silently
            self.warned_nonfinite = true;
            self.note(format!(
                "{}: row {} holds a value that is not a finite number (nan or inf); results that use it will be too",
                self.name, self.rows_read
            ));
        }
        Ok(true)
    }

    fn partial(&self, what: &str) -> anyhow::Error {
        anyhow::anyhow!(
            "{}: unexpected end of data in row {} ({}; NCOLS={} NCOMP={}, {})",
            self.name,
            self.rows_read + 1,
            what,
            self.info.ncols,
            self.info.ncomp,
            self.info.format
        )
    }

    fn read_ascii(&mut self, out: &mut [f64]) -> Result<bool> {
        for (i, v) in out.iter_mut().enumerate() {
            match ascii::next_number(&mut self.r, &mut self.tok, &self.name)? {
                Some(x) => *v = x,
                None if i == 0 => return Ok(false),
                None => return Err(self.partial(&format!("{i} of {} values", out.len()))),
            }
        }
        Ok(true)
    }

    fn read_binary(&mut self, out: &mut [f64]) -> Result<bool> {
        let vs = self.info.format.value_size().unwrap_or(4);
        let nbytes = out.len() * vs;
        self.bytes.resize(nbytes, 0);
        let got = read_full(&mut self.r, &mut self.bytes)
            .with_context(|| format!("{}: read error", self.name))?;
        if got == 0 {
            return Ok(false);
        }
        if got < nbytes {
            return Err(self.partial(&format!("{got} of {nbytes} bytes")));
        }
        let swap = self.swap;
        if vs == 4 {
            for (v, b) in out.iter_mut().zip(self.bytes.chunks_exact(4)) {
                let mut a = [b[0], b[1], b[2], b[3]];
                if swap {
                    a.reverse();
                }
                *v = f32::from_ne_bytes(a) as f64;
            }
        } else {
            for (v, b) in out.iter_mut().zip(self.bytes.chunks_exact(8)) {
                let mut a = [0u8; 8];
                a.copy_from_slice(b);
                if swap {
                    a.reverse();
                }
                *v = f64::from_ne_bytes(a);
            }
        }
        Ok(true)
    }

    fn read_rgbe(&mut self, out: &mut [f64]) -> Result<bool> {
        let nc = self.info.ncols;
        if self.r.fill_buf().map(|b| b.is_empty()).unwrap_or(false) {
            return Ok(false);
        }
        self.pixels.resize(nc, [0; 4]);
        let row = self.rows_read + 1;
        rgbe::read_scanline(&mut self.r, &mut self.pixels, &self.name)
            .map_err(|e| anyhow::anyhow!("{e:#} (row {row})"))?;
        for (o, p) in out.chunks_exact_mut(3).zip(&self.pixels) {
            o.copy_from_slice(&rgbe::decode(*p));
        }
        Ok(true)
    }

    /// Whether data remain after the rows the header announced (for a warning).
    pub fn has_trailing_data(&mut self) -> bool {
        if self.info.format == DataFormat::Ascii {
            matches!(
                ascii::next_number(&mut self.r, &mut self.tok, &self.name),
                Ok(Some(_)) | Err(_)
            )
        } else {
            self.r.fill_buf().map(|b| !b.is_empty()).unwrap_or(false)
        }
    }
}

/// Reads until `buf` is full or the data end (retrying interrupted reads); returns the
/// bytes read.
pub fn read_full<R: Read + ?Sized>(r: &mut R, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// Reads a standard `-Y N +X M` resolution string.
fn read_resolution<R: BufRead + ?Sized>(r: &mut R, name: &str) -> Result<(usize, usize)> {
    let mut line = Vec::new();
    r.take(64)
        .read_until(b'\n', &mut line)
        .with_context(|| format!("{name}: read error"))?;
    let s = String::from_utf8_lossy(&line);
    let w: Vec<&str> = s.split_whitespace().collect();
    if w.len() == 4 && w[0] == "-Y" && w[2] == "+X" {
        if let (Ok(y), Ok(x)) = (w[1].parse::<usize>(), w[3].parse::<usize>()) {
            if y > 0 && x > 0 {
                return Ok((y, x));
            }
        }
    }
    bail!(
        "{name}: bad resolution string '{}' (matrices need the standard '-Y rows +X columns' order, or NCOLS= in the header)",
        s.trim_end()
    )
}

#[cfg(test)]
mod tests {
    use super::MatrixReader;

    /// A header's component count is checked before anything is sized by it, also when an
    /// exposure asks for one divisor per component (found by tests/fuzz_parsers.rs: an
    /// 8 TB allocation).
    #[test]
    fn huge_ncomp_with_exposure_is_an_error_not_an_allocation() {
        let text =
            "#?RADIANCE\nNROWS=1\nNCOLS=1\nNCOMP=999999999993\nEXPOSURE=2\nFORMAT=ascii\n\n1\n";
        let err = MatrixReader::from_reader(std::io::Cursor::new(text.as_bytes().to_vec()), "m")
            .err()
            .expect("an error");
        assert!(
            format!("{err:#}").contains("too large for a matrix row"),
            "{err:#}"
        );
    }
}
