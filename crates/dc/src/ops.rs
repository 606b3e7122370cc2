//! Matrix operations behind rmtxop, with the numerics of Radiance 6.0a's `rmtxop`:
//! elements are stored as `f32` (the oracle's build keeps matrix data in single precision),
//! products and component transforms accumulate in `f64` and round once per element.
//!
//! A matrix carries its information-header lines (`info`): the input's lines (minus the
//! identifier and the layout keys), plus a note per operation (`Applied scalar`,
//! `Applied NxM component transform`, `Transposed rows and columns`) when it has any;
//! a sum keeps the first operand's lines, a product keeps none — as Radiance's rmtxop.

use std::path::Path;

use anyhow::{bail, Context, Result};
use fenestra_formats::matrix::{DataFormat, MatrixReader};

/// The process's generator for the colour dither of BSDF XML loads (see
/// `fenestra_bsdf::radiance`).
static XML_DITHER: std::sync::Mutex<fenestra_bsdf::radiance::Drand48> =
    std::sync::Mutex::new(fenestra_bsdf::radiance::Drand48::new());

/// Which matrix an XML BSDF input gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum XmlPart {
    /// The transmission matrix (`dctimestep`'s T).
    #[default]
    Transmission,
    /// Front (room-side) reflection (`-rf`).
    ReflectionFront,
    /// Back reflection (`-rb`).
    ReflectionBack,
}

/// A matrix as rmtxop holds it: `data[(row·ncols + col)·ncomp + comp]` in single precision.
#[derive(Debug, Clone, PartialEq)]
pub struct Mtx {
    /// Rows.
    pub nrows: usize,
    /// Columns.
    pub ncols: usize,
    /// Components per element.
    pub ncomp: usize,
    /// Row-major values, components interleaved.
    pub data: Vec<f32>,
    /// Header lines carried along.
    pub info: Vec<String>,
    /// Storage format of the input (the default output format).
    pub format: DataFormat,
}

/// Per-component factors undoing `EXPOSURE=` and `COLORCORR=` lines: `1 / (Π exposure ·
/// Π colorcorr[k])`, the products formed in single precision as Radiance does.
fn unscale_factors(h: &fenestra_formats::header::Header, ncomp: usize) -> Result<Vec<f32>> {
    let mut e = 1.0f32;
    for v in h.get_all("EXPOSURE") {
        match v.trim().parse::<f64>() {
            Ok(x) if x > 0.0 && x.is_finite() => e *= x as f32,
            _ => bail!(
                "bad header line EXPOSURE={} (expected a positive number)",
                fenestra_formats::header::printable(v)
            ),
        }
    }
    let mut cc = [1.0f32; 3];
    for v in h.get_all("COLORCORR") {
        let w: Vec<f64> = v
            .split_whitespace()
            .filter_map(|w| w.parse::<f64>().ok())
            .filter(|x| *x > 0.0 && x.is_finite())
            .collect();
        if w.len() != 3 {
            bail!(
                "bad header line COLORCORR={} (expected three positive numbers)",
                fenestra_formats::header::printable(v)
            );
        }
        for (c, x) in cc.iter_mut().zip(&w) {
            *c *= *x as f32;
        }
    }
    Ok((0..ncomp)
        .map(|k| (1.0 / (e * cc[if k < 3 { k } else { 1 }]) as f64) as f32)
        .collect())
}

/// A matrix input read row by row, with Radiance's rmtxop treatment of `EXPOSURE=` and
/// `COLORCORR=` (the raw values are scaled in single precision and noted as `Applied scalar`).
pub struct Source {
    /// The reader (its header has no EXPOSURE/COLORCORR lines left).
    pub reader: MatrixReader,
    factors: Option<Vec<f32>>,
    buf: Vec<f64>,
}

impl Source {
    /// Opens a matrix or picture: a file (sizes checked up front, NROWS of binary data
    /// inferred from the size), `-` (stdin) or `!command`.
    pub fn open(name: &str) -> Result<Source> {
        let is_file = !(name.is_empty() || name == "-" || name.starts_with('!'));
        if is_file {
            let r = MatrixReader::open(name)?;
            let h = &r.info.header;
            if h.get("EXPOSURE").is_none() && h.get("COLORCORR").is_none() {
                return Ok(Self::new(r, None));
            }
        }
        // Read the header here; hand the reader a copy without EXPOSURE/COLORCORR so
        // that it returns raw values.
        let mut input = fenestra_cli::input::open(name)?;
        let mut header = fenestra_formats::header::Header::read(&mut input, name)?;
        let factors = if header.get("EXPOSURE").is_some() || header.get("COLORCORR").is_some() {
            let ncomp = header.ncomp().ok().flatten().unwrap_or(3);
            let f = unscale_factors(&header, ncomp)
                .with_context(|| format!("{name}: bad matrix header"))?;
            header.remove("EXPOSURE");
            header.remove("COLORCORR");
            Some(f)
        } else {
            None
        };
        let mut bytes = Vec::new();
        header.write(&mut bytes, None)?;
        let stream =
            std::io::BufReader::new(std::io::Read::chain(std::io::Cursor::new(bytes), input));
        Ok(Self::new(MatrixReader::from_reader(stream, name)?, factors))
    }

    fn new(reader: MatrixReader, factors: Option<Vec<f32>>) -> Source {
        let reader = reader.report_to(fenestra_cli::warn_note);
        let n = reader.info.row_len();
        Source {
            reader,
            factors,
            buf: vec![0.0; n],
        }
    }

    /// An empty matrix (no rows) with this input's columns, components, header lines
    /// and format.
    pub fn shape(&self) -> Mtx {
        let info = &self.reader.info;
        let mut m = Mtx {
            nrows: 0,
            ncols: info.ncols,
            ncomp: info.ncomp,
            data: Vec::new(),
            info: info.retained_header().lines,
            format: info.format,
        };
        if self.factors.is_some() {
            m.note("Applied scalar");
        }
        m
    }

    /// Reads the next row into `out` (`ncols × ncomp` values); `Ok(false)` at the end.
    pub fn read_row(&mut self, out: &mut [f32]) -> Result<bool> {
        if !self.reader.read_row(&mut self.buf)? {
            return Ok(false);
        }
        for (o, &v) in out.iter_mut().zip(&self.buf) {
            *o = v as f32;
        }
        if let Some(f) = &self.factors {
            for el in out.chunks_exact_mut(f.len()) {
                for (v, &s) in el.iter_mut().zip(f) {
                    *v *= s;
                }
            }
        }
        Ok(true)
    }

    /// Checks the end of the data after `nrows` rows: no rows at all, or data beyond
    /// what the header describes, are errors.
    pub fn finish(&mut self, nrows: usize) -> Result<()> {
        let info = &self.reader.info;
        let (ncols, ncomp, announced) = (info.ncols, info.ncomp, info.nrows);
        if announced.is_none() && nrows == 0 {
            bail!("{}: no data rows in matrix", self.reader.name());
        }
        if self.reader.has_trailing_data() {
            bail!(
                "{}: more data than the header's NROWS={nrows} NCOLS={ncols} NCOMP={ncomp} describe (wrong header?)",
                self.reader.name()
            );
        }
        Ok(())
    }
}

/// Whether `name` names a BSDF XML file (by its extension, as Radiance decides).
pub fn is_xml(name: &str) -> bool {
    !name.starts_with('!')
        && Path::new(name)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

impl Mtx {
    /// A zero matrix.
    pub fn zeros(nrows: usize, ncols: usize, ncomp: usize) -> Mtx {
        Mtx {
            nrows,
            ncols,
            ncomp,
            data: vec![0.0; nrows * ncols * ncomp],
            info: Vec::new(),
            format: DataFormat::Ascii,
        }
    }

    /// Loads `name`: a BSDF XML file (`part` selects the matrix), `-` (stdin),
    /// `!command`, or a matrix/picture file in any format Radiance writes.
    pub fn load(name: &str, part: XmlPart) -> Result<Mtx> {
        if is_xml(name) {
            return Self::load_xml(name, part);
        }
        Self::read_source(Source::open(name)?)
    }

    /// Reads every row of an opened input (memory grows with the data read, not with NROWS).
    pub fn read_source(mut src: Source) -> Result<Mtx> {
        let row_len = src.reader.info.row_len();
        let mut data: Vec<f32> = Vec::new();
        if let Some(n) = src.reader.info.nrows {
            data.reserve(n.saturating_mul(row_len).min(1 << 20));
        }
        let mut row = vec![0.0f32; row_len];
        let mut nrows = 0;
        while src.read_row(&mut row)? {
            data.extend_from_slice(&row);
            nrows += 1;
        }
        src.finish(nrows)?;
        let mut m = src.shape();
        m.nrows = nrows;
        m.data = data;
        Ok(m)
    }

    fn load_xml(name: &str, part: XmlPart) -> Result<Mtx> {
        let b = fenestra_bsdf::read_file(Path::new(name))
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("cannot load BSDF '{name}'"))?;
        // One colour-dither generator per process, as Radiance's: a second XML operand of the
        // same command continues the sequence of the first.
        let mut rng = XML_DITHER
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let m = match part {
            XmlPart::Transmission => {
                fenestra_bsdf::radiance::transmission_matrix_with(&b, &mut rng)
                    .map_err(|e| anyhow::anyhow!("{name}: {e}"))?
            }
            XmlPart::ReflectionFront | XmlPart::ReflectionBack => {
                let front = part == XmlPart::ReflectionFront;
                match fenestra_bsdf::radiance::reflection_matrix_with(&b, front, &mut rng)
                    .map_err(|e| anyhow::anyhow!("{name}: {e}"))?
                {
                    Some(m) => m,
                    // No such block: a zero matrix in the full Klems basis, as Radiance.
                    None => {
                        let n = fenestra_bsdf::KlemsBasis::full().len();
                        fenestra_bsdf::radiance::RgbMatrix::zeros(n, n)
                    }
                }
            }
        };
        let mut data = Vec::with_capacity(m.data.len() * 3);
        for v in &m.data {
            data.extend(v.iter().map(|&x| x as f32));
        }
        Ok(Mtx {
            nrows: m.rows,
            ncols: m.cols,
            ncomp: 3,
            data,
            info: Vec::new(),
            format: DataFormat::Ascii,
        })
    }

    /// Values per row.
    pub fn row_len(&self) -> usize {
        self.ncols * self.ncomp
    }

    /// Row `r`'s values.
    pub fn row(&self, r: usize) -> &[f32] {
        let n = self.row_len();
        &self.data[r * n..(r + 1) * n]
    }

    /// Appends an operation note to the header lines, when there are any (as Radiance).
    pub fn note(&mut self, line: &str) {
        if !self.info.is_empty() {
            self.info.push(line.to_string());
        }
    }

    /// Swaps rows and columns (components stay with their element).
    pub fn transpose(&mut self) {
        let nc = self.ncomp;
        let mut data = vec![0.0f32; self.data.len()];
        for r in 0..self.nrows {
            for c in 0..self.ncols {
                let s = (r * self.ncols + c) * nc;
                let d = (c * self.nrows + r) * nc;
                data[d..d + nc].copy_from_slice(&self.data[s..s + nc]);
            }
        }
        self.data = data;
        std::mem::swap(&mut self.nrows, &mut self.ncols);
        self.note("Transposed rows and columns");
    }

    /// Applies a component transform and/or scale factors, as rmtxop's `-c` and `-s`:
    /// `cmat` holds `nout × ncomp` coefficients (row per output component); `scale` holds
    /// one factor or one per output component, applied after the transform.
    pub fn transform(&mut self, cmat: Option<&[f64]>, scale: Option<&[f64]>) -> Result<()> {
        let nin = self.ncomp;
        let nout = match cmat {
            Some(c) => {
                if c.is_empty() || c.len() % nin != 0 {
                    bail!(
                        "-c needs N × {nin} coefficients for a matrix with {nin} components, got {}",
                        c.len()
                    );
                }
                c.len() / nin
            }
            None => nin,
        };
        let sf: Option<Vec<f64>> = match scale {
            None => None,
            Some(s) if s.len() == 1 => Some(vec![s[0]; nout]),
            Some(s) if s.len() == nout => Some(s.to_vec()),
            Some(s) => bail!(
                "-s needs one factor or {nout} (one per component), got {}",
                s.len()
            ),
        };
        match cmat {
            Some(c) => {
                // Fold the scale factors into the coefficients.
                let mut m = c.to_vec();
                if let Some(sf) = &sf {
                    for (k, row) in m.chunks_exact_mut(nin).enumerate() {
                        for v in row {
                            *v *= sf[k];
                        }
                    }
                }
                let nel = self.nrows * self.ncols;
                let mut out = Vec::with_capacity(nel * nout);
                for el in self.data.chunks_exact(nin) {
                    for row in m.chunks_exact(nin) {
                        // Radiance sums the last component first.
                        let mut d = 0.0f64;
                        for (a, &b) in row.iter().zip(el).rev() {
                            d += a * b as f64;
                        }
                        out.push(d as f32);
                    }
                }
                self.data = out;
                self.ncomp = nout;
                self.note(&format!("Applied {nout}x{nin} component transform"));
            }
            None => {
                if let Some(sf) = &sf {
                    // A plain scale is a single-precision product, as in Radiance.
                    let sf: Vec<f32> = sf.iter().map(|&s| s as f32).collect();
                    for el in self.data.chunks_exact_mut(nin) {
                        for (v, &s) in el.iter_mut().zip(&sf) {
                            *v *= s;
                        }
                    }
                    self.note("Applied scalar");
                }
            }
        }
        Ok(())
    }

    /// Adds `other` element by element (same shape and components required).
    pub fn add(&mut self, other: &Mtx) -> Result<()> {
        self.same_shape(other, "sum")?;
        for (a, &b) in self.data.iter_mut().zip(&other.data) {
            *a += b;
        }
        Ok(())
    }

    /// Multiplies element by element (`*`); a one-component `other` multiplies every
    /// component of its element, as Radiance's.
    pub fn elem_mul(&mut self, other: &Mtx) -> Result<()> {
        if other.ncomp == 1 && self.ncomp > 1 {
            self.same_size(other, "element-wise product")?;
            let nc = self.ncomp;
            for (a, &b) in self.data.chunks_exact_mut(nc).zip(&other.data) {
                for x in a {
                    *x = (*x as f64 * b as f64) as f32;
                }
            }
            return Ok(());
        }
        self.same_shape(other, "element-wise product")?;
        for (a, &b) in self.data.iter_mut().zip(&other.data) {
            *a = (*a as f64 * b as f64) as f32;
        }
        Ok(())
    }

    /// Divides element by element (`/`), a one-component `other` dividing every component
    /// of its element; a zero divisor gives 0 (Radiance's rule). Returns how many did.
    pub fn elem_div(&mut self, other: &Mtx) -> Result<usize> {
        let nc = self.ncomp;
        let per = if other.ncomp == 1 && nc > 1 {
            self.same_size(other, "element-wise division")?;
            nc
        } else {
            self.same_shape(other, "element-wise division")?;
            1
        };
        let mut zeros = 0;
        for (a, &b) in self.data.chunks_exact_mut(per).zip(&other.data) {
            for x in a {
                if b == 0.0 {
                    zeros += 1;
                    *x = 0.0;
                } else {
                    *x = (*x as f64 / b as f64) as f32;
                }
            }
        }
        Ok(zeros)
    }

    fn same_size(&self, other: &Mtx, what: &str) -> Result<()> {
        if (self.nrows, self.ncols) != (other.nrows, other.ncols) {
            bail!(
                "{what} of mismatched matrices: {}×{} and {}×{} (rows × columns)",
                self.nrows,
                self.ncols,
                other.nrows,
                other.ncols
            );
        }
        Ok(())
    }

    fn same_shape(&self, other: &Mtx, what: &str) -> Result<()> {
        if (self.nrows, self.ncols, self.ncomp) != (other.nrows, other.ncols, other.ncomp) {
            bail!(
                "{what} of mismatched matrices: {}×{}×{} and {}×{}×{} (rows × columns × components)",
                self.nrows,
                self.ncols,
                self.ncomp,
                other.nrows,
                other.ncols,
                other.ncomp
            );
        }
        Ok(())
    }

    /// The matrix product `self · other`, component by component (both need the same
    /// number of components); sums accumulate in double precision.
    pub fn multiply(&self, other: &Mtx) -> Result<Mtx> {
        self.multiply_check(other)?;
        let (n, m, p, nc) = (self.nrows, self.ncols, other.ncols, self.ncomp);
        let mut out = Mtx::zeros(n, p, nc);
        out.format = self.format;
        let mut acc = vec![0.0f64; p * nc];
        for i in 0..n {
            acc.iter_mut().for_each(|v| *v = 0.0);
            let arow = self.row(i);
            for h in 0..m {
                let a = &arow[h * nc..(h + 1) * nc];
                let brow = other.row(h);
                for (d, b) in acc.chunks_exact_mut(nc).zip(brow.chunks_exact(nc)) {
                    for k in 0..nc {
                        d[k] += a[k] as f64 * b[k] as f64;
                    }
                }
            }
            let orow = &mut out.data[i * p * nc..(i + 1) * p * nc];
            for (o, &v) in orow.iter_mut().zip(&acc) {
                *o = v as f32;
            }
        }
        Ok(out)
    }

    fn multiply_check(&self, other: &Mtx) -> Result<()> {
        if self.ncols != other.nrows {
            bail!(
                "matrix product of mismatched sizes: {}×{} times {}×{} (columns of the first must equal rows of the second)",
                self.nrows,
                self.ncols,
                other.nrows,
                other.ncols
            );
        }
        if self.ncomp != other.ncomp {
            bail!(
                "matrix product of matrices with {} and {} components",
                self.ncomp,
                other.ncomp
            );
        }
        Ok(())
    }
}

/// Whether Radiance's rmtxop multiplies a chain of three or more matrices from the right:
/// when the rightmost has one column, or fewer columns than rows and than the leftmost
/// has rows (the order changes the single-precision rounding of the result).
pub fn prefer_right_to_left(chain: &[Mtx]) -> bool {
    let (Some(first), Some(last)) = (chain.first(), chain.last()) else {
        return false;
    };
    if chain.len() < 3 {
        return false;
    }
    if last.ncols == 1 {
        return true;
    }
    last.ncols < last.nrows && last.ncols < first.nrows
}

/// Multiplies a chain of matrices from the left, or from the right when `right_to_left`.
pub fn multiply_chain(mut chain: Vec<Mtx>, right_to_left: bool) -> Result<Mtx> {
    for w in chain.windows(2) {
        if w[0].ncols != w[1].nrows || w[0].ncomp != w[1].ncomp {
            // Report the first mismatch in command-line order.
            w[0].multiply_check(&w[1])?;
        }
    }
    if right_to_left {
        let mut acc = chain.pop().context("empty matrix chain")?;
        while let Some(m) = chain.pop() {
            acc = m.multiply(&acc)?;
        }
        return Ok(acc);
    }
    let mut it = chain.into_iter();
    let mut acc = it.next().context("empty matrix chain")?;
    for m in it {
        acc = acc.multiply(&m)?;
    }
    Ok(acc)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(nrows: usize, ncols: usize, ncomp: usize, v: &[f32]) -> Mtx {
        Mtx {
            nrows,
            ncols,
            ncomp,
            data: v.to_vec(),
            info: vec!["x".into()],
            format: DataFormat::Ascii,
        }
    }

    #[test]
    fn transpose_moves_elements_with_components() {
        let mut a = m(1, 2, 2, &[1., 2., 3., 4.]);
        a.transpose();
        assert_eq!((a.nrows, a.ncols), (2, 1));
        assert_eq!(a.data, vec![1., 2., 3., 4.]);
        assert_eq!(a.info.last().unwrap(), "Transposed rows and columns");
    }

    #[test]
    fn component_transform_then_scale() {
        let mut a = m(1, 1, 3, &[1., 2., 3.]);
        a.transform(Some(&[1., 1., 1., 1., 0., 0.]), Some(&[2., 3.]))
            .unwrap();
        assert_eq!(a.ncomp, 2);
        assert_eq!(a.data, vec![12., 3.]);
        let mut b = m(1, 1, 3, &[1., 2., 3.]);
        assert!(b.transform(Some(&[1., 1.]), None).is_err());
        assert!(b.transform(None, Some(&[1., 2.])).is_err());
    }

    #[test]
    fn product_and_sum() {
        let a = m(1, 2, 1, &[1., 2.]);
        let b = m(2, 1, 1, &[3., 4.]);
        let p = a.multiply(&b).unwrap();
        assert_eq!(p.data, vec![11.]);
        assert!(p.info.is_empty());
        assert!(a.multiply(&a).is_err());
        let mut s = a.clone();
        s.add(&a).unwrap();
        assert_eq!(s.data, vec![2., 4.]);
        assert!(s.add(&b).is_err());
    }
}
