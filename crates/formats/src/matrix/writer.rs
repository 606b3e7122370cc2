//! Writing matrices with Radiance's headers and layouts.

use std::io::Write;

use anyhow::{bail, Result};

use super::{ascii::format_c_e, rgbe, DataFormat, NATIVE_BIG_ENDIAN};
use crate::header::Header;

/// How ascii numbers are laid out (all verified against Radiance's writers).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AsciiLayout {
    /// rmtxop: `" %.7e"` per component, a TAB after each element, newline per row.
    #[default]
    Rmtxop,
    /// dctimestep: `"%.6e %.6e %.6e"`, TAB between elements, newline per row.
    Dctimestep,
    /// rcontrib: `"%.6e\t"` per component, newline per row.
    Rcontrib,
}

/// Options for [`MatrixWriter`].
#[derive(Debug, Clone, PartialEq)]
pub struct WriteOptions {
    /// Output format.
    pub format: DataFormat,
    /// Text layout when `format` is ascii.
    pub ascii: AsciiLayout,
    /// Byte order for float/double (default: native).
    pub big_endian: bool,
    /// Header lines to write before the shape lines (a `#?RADIANCE` line is put first
    /// when missing); `None` writes no header at all (`-h`).
    pub header: Option<Header>,
    /// Stream offset where the header starts, when the output is a seekable file:
    /// the FORMAT line is then padded with blanks so binary data start aligned, as
    /// Radiance does. `None` (pipes) writes no padding.
    pub align_from: Option<u64>,
    /// Whether to write `NROWS=` (Radiance's matrix writers do, except for RGBE).
    pub write_nrows: bool,
}

impl Default for WriteOptions {
    fn default() -> Self {
        WriteOptions {
            format: DataFormat::Ascii,
            ascii: AsciiLayout::Rmtxop,
            big_endian: NATIVE_BIG_ENDIAN,
            header: Some(Header::radiance()),
            align_from: None,
            write_nrows: true,
        }
    }
}

impl WriteOptions {
    /// Options for `format` with a header holding `#?RADIANCE` and `command`.
    pub fn with_command(format: DataFormat, command: &str) -> Self {
        let mut h = Header::radiance();
        h.push(command);
        WriteOptions {
            format,
            header: Some(h),
            ..Default::default()
        }
    }
}

/// The header every fenestra tool writes before matrix (or picture) data: the information
/// lines (`#?RADIANCE` first if missing), then for a matrix `NROWS` (unless not asked or
/// unknown), `NCOLS`, the lines `after_ncols` (gendaymtx's `NAVERAGED`), `NCOMP`; then
/// `BigEndian` for binary values, `FORMAT` (padded with `align_from` so the data start
/// aligned) and the blank line. A picture's resolution line is the caller's. Empty without
/// `opts.header`.
pub fn header_bytes(
    nrows: Option<usize>,
    ncols: usize,
    ncomp: usize,
    opts: &WriteOptions,
    after_ncols: &[String],
) -> Result<Vec<u8>> {
    let Some(h) = &opts.header else {
        return Ok(Vec::new());
    };
    let format = opts.format;
    let mut text = Vec::with_capacity(256);
    if !h.lines.first().is_some_and(|l| l.starts_with("#?")) {
        text.extend_from_slice(b"#?RADIANCE\n");
    }
    h.write_lines(&mut text)?;
    if !format.is_picture() {
        if opts.write_nrows {
            if let Some(n) = nrows {
                writeln!(text, "NROWS={n}")?;
            }
        }
        writeln!(text, "NCOLS={ncols}")?;
        for l in after_ncols {
            writeln!(text, "{l}")?;
        }
        writeln!(text, "NCOMP={ncomp}")?;
    }
    if format.value_size().is_some() {
        writeln!(text, "BigEndian={}", opts.big_endian as u8)?;
    }
    write!(text, "FORMAT={}", format.as_str())?;
    if let Some(off) = opts.align_from {
        let align = format.alignment() as u64;
        while (off + text.len() as u64 + 2) % align != 0 {
            text.push(b' ');
        }
    }
    text.extend_from_slice(b"\n\n");
    Ok(text)
}

/// Writes a matrix row by row.
pub struct MatrixWriter<W: Write> {
    w: W,
    format: DataFormat,
    layout: AsciiLayout,
    swap: bool,
    ncols: usize,
    ncomp: usize,
    nrows: Option<usize>,
    rows: usize,
    text: String,
    bytes: Vec<u8>,
    pixels: Vec<[u8; 4]>,
}

impl<W: Write> MatrixWriter<W> {
    /// Writes the header (unless `opts.header` is `None`) and returns a writer for rows.
    pub fn new(
        mut w: W,
        nrows: Option<usize>,
        ncols: usize,
        ncomp: usize,
        opts: &WriteOptions,
    ) -> Result<Self> {
        let format = opts.format;
        if format.is_picture() && ncomp != 3 && ncomp != 1 {
            bail!("{format} output needs 1 or 3 components per element, the matrix has {ncomp}");
        }
        if opts.header.is_some() {
            if format.is_picture() && nrows.is_none() {
                bail!("{format} output needs the row count in advance");
            }
            let mut text = header_bytes(nrows, ncols, ncomp, opts, &[])?;
            if format.is_picture() {
                writeln!(text, "-Y {:8} +X {:8}", nrows.unwrap_or(0), ncols)?;
            }
            w.write_all(&text)?;
        } else if format.is_picture() && nrows.is_none() {
            bail!("{format} output needs the row count in advance");
        }
        Ok(MatrixWriter {
            w,
            format,
            layout: opts.ascii,
            swap: format.value_size().is_some() && opts.big_endian != NATIVE_BIG_ENDIAN,
            ncols,
            ncomp,
            nrows,
            rows: 0,
            text: String::new(),
            bytes: Vec::new(),
            pixels: Vec::new(),
        })
    }

    /// Writes one row of `ncols × ncomp` values.
    pub fn write_row(&mut self, row: &[f64]) -> Result<()> {
        if row.len() != self.ncols * self.ncomp {
            bail!(
                "row of {} values written to a matrix with {} columns of {} components",
                row.len(),
                self.ncols,
                self.ncomp
            );
        }
        if self.nrows.is_some_and(|n| self.rows >= n) {
            bail!(
                "more rows written than the {} announced",
                self.nrows.unwrap_or(0)
            );
        }
        match self.format {
            DataFormat::Ascii => self.write_ascii(row)?,
            DataFormat::Float => {
                self.bytes.clear();
                for &v in row {
                    let mut b = (v as f32).to_ne_bytes();
                    if self.swap {
                        b.reverse();
                    }
                    self.bytes.extend_from_slice(&b);
                }
                self.w.write_all(&self.bytes)?;
            }
            DataFormat::Double => {
                self.bytes.clear();
                for &v in row {
                    let mut b = v.to_ne_bytes();
                    if self.swap {
                        b.reverse();
                    }
                    self.bytes.extend_from_slice(&b);
                }
                self.w.write_all(&self.bytes)?;
            }
            DataFormat::Rgbe | DataFormat::Xyze => {
                self.pixels.clear();
                if self.ncomp == 3 {
                    for c in row.chunks_exact(3) {
                        self.pixels.push(rgbe::encode([c[0], c[1], c[2]]));
                    }
                } else {
                    for &v in row {
                        self.pixels.push(rgbe::encode([v, v, v]));
                    }
                }
                rgbe::write_scanline(&mut self.w, &self.pixels)?;
            }
        }
        self.rows += 1;
        Ok(())
    }

    fn write_ascii(&mut self, row: &[f64]) -> Result<()> {
        let t = &mut self.text;
        t.clear();
        let nc = self.ncomp;
        match self.layout {
            AsciiLayout::Rmtxop => {
                for el in row.chunks_exact(nc) {
                    for &v in el {
                        t.push(' ');
                        format_c_e(t, v, 7);
                    }
                    t.push('\t');
                }
            }
            AsciiLayout::Dctimestep => {
                for (i, el) in row.chunks_exact(nc).enumerate() {
                    if i > 0 {
                        t.push('\t');
                    }
                    for (k, &v) in el.iter().enumerate() {
                        if k > 0 {
                            t.push(' ');
                        }
                        format_c_e(t, v, 6);
                    }
                }
            }
            AsciiLayout::Rcontrib => {
                for &v in row {
                    format_c_e(t, v, 6);
                    t.push('\t');
                }
            }
        }
        t.push('\n');
        self.w.write_all(t.as_bytes())?;
        Ok(())
    }

    /// Rows written so far.
    pub fn rows_written(&self) -> usize {
        self.rows
    }

    /// Checks the announced row count was written, flushes, and returns the stream.
    pub fn finish(mut self) -> Result<W> {
        if let Some(n) = self.nrows {
            if self.rows != n {
                bail!("{} rows written, {} announced", self.rows, n);
            }
        }
        self.w.flush()?;
        Ok(self.w)
    }
}
