//! A whole matrix in memory.

use std::io::Write;

use anyhow::Result;

use super::{DataFormat, MatrixInfo, MatrixReader, MatrixWriter, WriteOptions};
use crate::header::Header;

/// Values fetched per allocation step when the row count is not trusted.
const GROW_STEP: usize = 1 << 22;

/// A matrix: `data[(row·ncols + col)·ncomp + comp]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    /// Rows.
    pub nrows: usize,
    /// Columns.
    pub ncols: usize,
    /// Components per element.
    pub ncomp: usize,
    /// Row-major values, components interleaved.
    pub data: Vec<f64>,
    /// Header lines kept from the input (see [`MatrixInfo::retained_header`]).
    pub header: Header,
    /// Storage format of the input.
    pub format: DataFormat,
    /// Warnings noticed while reading it (for the caller to report; the library prints
    /// nothing): data beyond the header's rows, values that are not finite numbers.
    pub notes: Vec<String>,
}

impl Matrix {
    /// A zero matrix.
    pub fn zeros(nrows: usize, ncols: usize, ncomp: usize) -> Self {
        Matrix {
            nrows,
            ncols,
            ncomp,
            data: vec![0.0; nrows * ncols * ncomp],
            header: Header::new(),
            format: DataFormat::Ascii,
            notes: Vec::new(),
        }
    }

    /// Reads a whole matrix from `name` (`-`, `!command` or a file); its warnings are kept
    /// in [`Matrix::notes`].
    pub fn read(name: &str) -> Result<Matrix> {
        Self::read_from(MatrixReader::open(name)?)
    }

    /// Reads a whole matrix, handing its warnings to `sink` as they are noticed.
    pub fn read_reporting(name: &str, sink: fn(String)) -> Result<Matrix> {
        Self::read_from(MatrixReader::open(name)?.report_to(sink))
    }

    /// Reads every remaining row of `r`. Memory grows with the data actually read,
    /// never with what the header claims.
    pub fn read_from(mut r: MatrixReader) -> Result<Matrix> {
        let info: MatrixInfo = r.info.clone();
        let row_len = info.row_len();
        let mut data: Vec<f64> = Vec::new();
        if let Some(n) = info.nrows {
            data.reserve(n.saturating_mul(row_len).min(GROW_STEP));
        }
        let mut row = vec![0.0; row_len];
        let mut nrows = 0;
        while r.read_row(&mut row)? {
            data.extend_from_slice(&row);
            nrows += 1;
        }
        if r.has_trailing_data() {
            let msg = format!(
                "{}: data beyond the {} rows of the header ignored",
                r.name(),
                nrows
            );
            r.note(msg);
        }
        let notes = r.take_notes();
        Ok(Matrix {
            nrows,
            ncols: info.ncols,
            ncomp: info.ncomp,
            data,
            header: info.retained_header(),
            format: info.format,
            notes,
        })
    }

    /// Element `(r, c)`'s components.
    pub fn get(&self, r: usize, c: usize) -> &[f64] {
        let i = (r * self.ncols + c) * self.ncomp;
        &self.data[i..i + self.ncomp]
    }

    /// Row `r`'s values.
    pub fn row(&self, r: usize) -> &[f64] {
        let n = self.ncols * self.ncomp;
        &self.data[r * n..(r + 1) * n]
    }

    /// Writes the matrix with `opts`.
    pub fn write<W: Write>(&self, w: W, opts: &WriteOptions) -> Result<W> {
        let mut mw = MatrixWriter::new(w, Some(self.nrows), self.ncols, self.ncomp, opts)?;
        for r in 0..self.nrows {
            mw.write_row(self.row(r))?;
        }
        mw.finish()
    }

    /// The transpose (components stay with their element).
    pub fn transpose(&self) -> Matrix {
        let nc = self.ncomp;
        let mut data = vec![0.0; self.data.len()];
        for r in 0..self.nrows {
            for c in 0..self.ncols {
                let s = (r * self.ncols + c) * nc;
                let d = (c * self.nrows + r) * nc;
                data[d..d + nc].copy_from_slice(&self.data[s..s + nc]);
            }
        }
        Matrix {
            nrows: self.ncols,
            ncols: self.nrows,
            ncomp: nc,
            data,
            header: self.header.clone(),
            format: self.format,
            notes: Vec::new(),
        }
    }
}
