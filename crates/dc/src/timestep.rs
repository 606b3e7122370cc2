//! V·T·D·s time stepping (the arithmetic behind `dctimestep`).
//!
//! Matrices are RGB (three independent channels) and held in planar form
//! ([`Planar`]). The sky (right-hand) matrix is packed into column panels of
//! [`PANEL`] time steps ([`PackedSky`]), so that a block of result rows
//! (`W = V·T·D` rows) times the sky runs as a register-tiled product
//! ([`multiply`]), parallel over panels, accumulating in `f64`. Columns of the
//! sky that are zero in every patch and channel give exact (positive) zeros.

use std::ops::Range;

use anyhow::{bail, Result};
use rayon::prelude::*;

/// Time steps per packed sky panel (columns computed together by the kernel).
pub const PANEL: usize = 8;
/// Result rows computed together by the kernel.
pub const MR: usize = 4;

/// An RGB matrix in planar form: channel `c`, row `r`, column `k` at
/// `data[c][r * cols + k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Planar {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// One row-major plane per channel.
    pub data: [Vec<f64>; 3],
}

impl Planar {
    /// A zero matrix.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        let n = rows * cols;
        Planar {
            rows,
            cols,
            data: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
        }
    }

    /// Builds a matrix from interleaved values (`(r·cols + k)·ncomp + c`); one
    /// component is used for all three channels.
    pub fn from_interleaved(rows: usize, cols: usize, ncomp: usize, v: &[f64]) -> Result<Self> {
        if ncomp != 1 && ncomp != 3 {
            bail!("matrix has {ncomp} components per element (1 or 3 expected)");
        }
        if v.len() != rows * cols * ncomp {
            bail!(
                "matrix data hold {} values, {rows}×{cols}×{ncomp} expected",
                v.len()
            );
        }
        let mut m = Planar::zeros(rows, cols);
        for i in 0..rows * cols {
            for c in 0..3 {
                m.data[c][i] = v[i * ncomp + if ncomp == 3 { c } else { 0 }];
            }
        }
        Ok(m)
    }

    /// Element (r, k) of channel c.
    pub fn get(&self, c: usize, r: usize, k: usize) -> f64 {
        self.data[c][r * self.cols + k]
    }

    /// The product `self · rhs` per channel, accumulated in f64 (rows in parallel).
    pub fn mul(&self, rhs: &Planar) -> Result<Planar> {
        if self.cols != rhs.rows {
            bail!(
                "cannot multiply a {}×{} matrix by a {}×{} matrix",
                self.rows,
                self.cols,
                rhs.rows,
                rhs.cols
            );
        }
        let mut out = Planar::zeros(self.rows, rhs.cols);
        let n = rhs.cols;
        for c in 0..3 {
            let a = &self.data[c];
            let b = &rhs.data[c];
            let k = self.cols;
            if n == 0 {
                continue;
            }
            out.data[c]
                .par_chunks_mut(n)
                .enumerate()
                .for_each(|(r, orow)| {
                    for (j, &av) in a[r * k..(r + 1) * k].iter().enumerate() {
                        if av != 0.0 {
                            for (o, &bv) in orow.iter_mut().zip(&b[j * n..(j + 1) * n]) {
                                *o += av * bv;
                            }
                        }
                    }
                });
        }
        Ok(out)
    }

    /// `v · self` for a block of `nrows` rows `v` (each `self.rows × ncomp` values,
    /// components interleaved; one component serves all channels): a block of
    /// `W = V · self`, padded with zero rows to a multiple of [`MR`].
    pub fn left_mul_rows(&self, v: &[f64], nrows: usize, ncomp: usize) -> Result<Planar> {
        let kin = self.rows;
        if v.len() != nrows * kin * ncomp {
            bail!(
                "left operand holds {} values, {nrows}×{kin}×{ncomp} expected",
                v.len()
            );
        }
        let padded = nrows.div_ceil(MR) * MR;
        let n = self.cols;
        let mut out = Planar::zeros(padded, n);
        if n == 0 {
            return Ok(out);
        }
        for c in 0..3 {
            let b = &self.data[c];
            let cc = if ncomp == 3 { c } else { 0 };
            out.data[c][..nrows * n]
                .par_chunks_mut(n)
                .enumerate()
                .for_each(|(r, orow)| {
                    let vrow = &v[r * kin * ncomp..(r + 1) * kin * ncomp];
                    for j in 0..kin {
                        let av = vrow[j * ncomp + cc];
                        if av != 0.0 {
                            for (o, &bv) in orow.iter_mut().zip(&b[j * n..(j + 1) * n]) {
                                *o += av * bv;
                            }
                        }
                    }
                });
        }
        Ok(out)
    }

    /// This matrix padded with zero rows to a multiple of [`MR`] rows.
    pub fn padded_rows(mut self) -> Planar {
        let padded = self.rows.div_ceil(MR) * MR;
        for c in 0..3 {
            self.data[c].resize(padded * self.cols, 0.0);
        }
        self.rows = padded;
        self
    }
}

/// The sky matrix (patches × time steps) packed in panels of [`PANEL`] steps:
/// channel `c`, panel `p`, patch `k`, step `p·PANEL + j` at
/// `data[c][(p·patches + k)·PANEL + j]` (steps past the end are zero).
#[derive(Debug, Clone)]
pub struct PackedSky {
    patches: usize,
    steps: usize,
    panels: usize,
    data: [Vec<f64>; 3],
    zero: Vec<bool>,
}

impl PackedSky {
    /// An all-zero sky of `patches` rows and `steps` columns.
    pub fn new(patches: usize, steps: usize) -> Self {
        let panels = steps.div_ceil(PANEL);
        let n = panels * patches * PANEL;
        PackedSky {
            patches,
            steps,
            panels,
            data: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            zero: vec![true; steps],
        }
    }

    /// Rows (sky patches).
    pub fn patches(&self) -> usize {
        self.patches
    }

    /// Columns (time steps).
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Number of panels.
    pub fn panels(&self) -> usize {
        self.panels
    }

    /// Sets patch row `k` from interleaved values (`steps × ncomp`, ncomp 1 or 3).
    pub fn set_row(&mut self, k: usize, row: &[f64], ncomp: usize) {
        for t in 0..self.steps {
            let (p, j) = (t / PANEL, t % PANEL);
            let at = (p * self.patches + k) * PANEL + j;
            for c in 0..3 {
                let v = row[t * ncomp + if ncomp == 3 { c } else { 0 }];
                self.data[c][at] = v;
                if v != 0.0 {
                    self.zero[t] = false;
                }
            }
        }
    }

    /// Value of patch `k`, step `t`, channel `c`.
    pub fn get(&self, c: usize, k: usize, t: usize) -> f64 {
        self.data[c][((t / PANEL) * self.patches + k) * PANEL + t % PANEL]
    }

    /// Whether step `t` is zero in every patch and channel.
    pub fn is_zero_step(&self, t: usize) -> bool {
        self.zero[t]
    }
}

/// A block of results: rows of `W` × a range of sky panels, stored panel by panel:
/// panel `p` (relative to the range start), channel `c`, row `r`, step-in-panel `j`
/// at `data[((p·3 + c)·rows + r)·PANEL + j]`.
#[derive(Debug, Clone)]
pub struct ResultBlock {
    rows: usize,
    panel0: usize,
    steps: Range<usize>,
    data: Vec<f64>,
    zero: Vec<bool>,
    any_zero: bool,
}

impl ResultBlock {
    /// Steps covered.
    pub fn steps(&self) -> Range<usize> {
        self.steps.clone()
    }

    /// Result of row `r`, absolute step `t` (inside [`steps`](Self::steps)), channel `c`.
    /// A step whose sky is all zero gives exactly +0.
    #[inline]
    pub fn get(&self, r: usize, t: usize, c: usize) -> f64 {
        if self.zero[t - self.steps.start] {
            return 0.0;
        }
        let p = t / PANEL - self.panel0;
        self.data[((p * 3 + c) * self.rows + r) * PANEL + t % PANEL]
    }
}

impl ResultBlock {
    /// All steps of row `r` written to `dst` (length = number of [`steps`](Self::steps)) as
    /// RGB triples; all-zero sky steps give exactly +0.
    pub fn row_into(&self, r: usize, dst: &mut [[f64; 3]]) {
        assert_eq!(dst.len(), self.steps.len(), "row length");
        let plane = self.rows * PANEL;
        for (pi, chunk) in dst.chunks_mut(PANEL).enumerate() {
            let at = (pi * 3 * self.rows + r) * PANEL;
            let red = &self.data[at..at + PANEL];
            let green = &self.data[at + plane..at + plane + PANEL];
            let blue = &self.data[at + 2 * plane..at + 2 * plane + PANEL];
            for (j, d) in chunk.iter_mut().enumerate() {
                *d = [red[j], green[j], blue[j]];
            }
        }
        if self.any_zero {
            // Steps start on a panel boundary (panel0 · PANEL), so chunk offsets line up.
            for (d, &z) in dst.iter_mut().zip(&self.zero) {
                if z {
                    *d = [0.0; 3];
                }
            }
        }
    }
}

/// `w · sky` for the panels `panels` (all rows of `w`, which must be padded to a
/// multiple of [`MR`] rows), in parallel over panels.
pub fn multiply(w: &Planar, sky: &PackedSky, panels: Range<usize>) -> Result<ResultBlock> {
    if w.cols != sky.patches {
        bail!(
            "cannot multiply a {}-column matrix by a sky of {} patches",
            w.cols,
            sky.patches
        );
    }
    if w.rows % MR != 0 {
        bail!("internal: result rows not padded to a multiple of {MR}");
    }
    let rows = w.rows;
    let kk = w.cols;
    let per_panel = 3 * rows * PANEL;
    let np = panels.len();
    let mut data = vec![0.0; np * per_panel];
    let fast = fast_kernel_available();
    if per_panel > 0 {
        data.par_chunks_mut(per_panel)
            .enumerate()
            .for_each(|(pi, out)| {
                let p = panels.start + pi;
                for c in 0..3 {
                    let s = &sky.data[c][p * kk * PANEL..(p + 1) * kk * PANEL];
                    let wc = &w.data[c];
                    let oc = &mut out[c * rows * PANEL..(c + 1) * rows * PANEL];
                    for q in 0..rows / MR {
                        let wq = &wc[q * MR * kk..(q + 1) * MR * kk];
                        let acc = if fast {
                            kernel_fast(wq, kk, s)
                        } else {
                            kernel_body::<false>(wq, kk, s)
                        };
                        for (i, a) in acc.iter().enumerate() {
                            let r = q * MR + i;
                            oc[r * PANEL..(r + 1) * PANEL].copy_from_slice(a);
                        }
                    }
                }
            });
    }
    let t0 = panels.start * PANEL;
    let t1 = (panels.end * PANEL).min(sky.steps);
    Ok(ResultBlock {
        rows,
        panel0: panels.start,
        steps: t0..t1,
        data,
        zero: sky.zero[t0..t1].to_vec(),
        any_zero: sky.zero[t0..t1].iter().any(|&z| z),
    })
}

fn fast_kernel_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(target_arch = "x86_64")]
fn kernel_fast(w: &[f64], kk: usize, s: &[f64]) -> [[f64; PANEL]; MR] {
    #[target_feature(enable = "avx2,fma")]
    unsafe fn inner(w: &[f64], kk: usize, s: &[f64]) -> [[f64; PANEL]; MR] {
        kernel_body::<true>(w, kk, s)
    }
    // SAFETY: only called after fast_kernel_available() found AVX2 and FMA.
    unsafe { inner(w, kk, s) }
}

#[cfg(not(target_arch = "x86_64"))]
fn kernel_fast(w: &[f64], kk: usize, s: &[f64]) -> [[f64; PANEL]; MR] {
    kernel_body::<false>(w, kk, s)
}

/// `MR` rows of `w` (each `kk` long) times one sky panel (`kk × PANEL`).
#[inline(always)]
fn kernel_body<const FMA: bool>(w: &[f64], kk: usize, s: &[f64]) -> [[f64; PANEL]; MR] {
    let mut acc = [[0.0f64; PANEL]; MR];
    let (w0, rest) = w.split_at(kk);
    let (w1, rest) = rest.split_at(kk);
    let (w2, w3) = rest.split_at(kk);
    for ((((sv, &a0), &a1), &a2), &a3) in
        s.chunks_exact(PANEL).zip(w0).zip(w1).zip(w2).zip(&w3[..kk])
    {
        let sv: &[f64; PANEL] = sv.try_into().expect("panel width");
        let a = [a0, a1, a2, a3];
        for i in 0..MR {
            for j in 0..PANEL {
                acc[i][j] = if FMA {
                    a[i].mul_add(sv[j], acc[i][j])
                } else {
                    acc[i][j] + a[i] * sv[j]
                };
            }
        }
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive(w: &Planar, sky: &[Vec<[f64; 3]>], t: usize, r: usize, c: usize) -> f64 {
        (0..w.cols).map(|k| w.get(c, r, k) * sky[k][t][c]).sum()
    }

    #[test]
    fn blocked_product_equals_naive() {
        let (rows, k, steps) = (7usize, 5usize, 19usize);
        let mut w = Planar::zeros(rows, k);
        for c in 0..3 {
            for i in 0..rows * k {
                w.data[c][i] = ((i * 7 + c * 3) % 11) as f64 - 3.0;
            }
        }
        let w = w.padded_rows();
        let mut sky = PackedSky::new(k, steps);
        let mut raw = vec![vec![[0.0; 3]; steps]; k];
        for (kr, rrow) in raw.iter_mut().enumerate() {
            let mut row = vec![0.0; steps * 3];
            for t in 0..steps {
                for c in 0..3 {
                    let v = if t == 4 {
                        0.0
                    } else {
                        ((kr * 13 + t * 5 + c) % 17) as f64 * 0.25
                    };
                    row[t * 3 + c] = v;
                    rrow[t][c] = v;
                }
            }
            sky.set_row(kr, &row, 3);
        }
        assert!(sky.is_zero_step(4));
        let res = multiply(&w, &sky, 0..sky.panels()).unwrap();
        for r in 0..rows {
            for t in 0..steps {
                for c in 0..3 {
                    let want = naive(&w, &raw, t, r, c);
                    let got = res.get(r, t, c);
                    assert!((want - got).abs() < 1e-12, "{r} {t} {c}: {want} {got}");
                }
            }
        }
        assert_eq!(res.get(0, 4, 0).to_bits(), 0.0f64.to_bits());
        let mut row = vec![[0.0; 3]; steps];
        res.row_into(5, &mut row);
        for (t, v) in row.iter().enumerate() {
            for (c, x) in v.iter().enumerate() {
                assert_eq!(x.to_bits(), res.get(5, t, c).to_bits());
            }
        }
        // A panel sub-range gives the same numbers.
        let part = multiply(&w, &sky, 1..2).unwrap();
        assert_eq!(part.steps(), 8..16);
        assert_eq!(part.get(3, 9, 2), res.get(3, 9, 2));
    }

    #[test]
    fn left_mul_matches_mul() {
        let mut b = Planar::zeros(3, 4);
        for c in 0..3 {
            for i in 0..12 {
                b.data[c][i] = (i + c) as f64;
            }
        }
        let v: Vec<f64> = (0..2 * 3 * 3).map(|i| (i % 5) as f64).collect();
        let a = Planar::from_interleaved(2, 3, 3, &v).unwrap();
        let p = a.mul(&b).unwrap();
        let q = b.left_mul_rows(&v, 2, 3).unwrap();
        assert_eq!(q.rows, 4);
        for c in 0..3 {
            assert_eq!(&q.data[c][..8], &p.data[c][..]);
            assert!(q.data[c][8..].iter().all(|&x| x == 0.0));
        }
        assert!(a.mul(&a).is_err());
    }
}
