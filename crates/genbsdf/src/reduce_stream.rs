//! The rank-4 reduction of [`crate::reduce`] without the whole grid in memory, for large
//! trees (`-t4 7`: 2^28 cells per component, a gigabyte in single precision). Two passes
//! over the incident cells, which the caller traces (again) on demand, a square block of
//! incident cells at a time:
//! 1. the variability of every lowest branch node (2 × 2 incident by 2 × 2 outgoing
//!    cells) into the histogram that fixes the merge threshold;
//! 2. the tree text bottom-up: a node's text depends only on its own variability and on
//!    its children's texts (merged into its mean when at or below the threshold, else its
//!    children), which is what the top-down merge and print of the in-memory reduction
//!    write. Blocks are combined in the in-memory builder's order and precision, so the
//!    text is the same, byte for byte (tested).
//!
//! Memory: one block of incident cells' values, and the texts of nodes not yet combined.

use anyhow::Result;
use rayon::prelude::*;

use crate::reduce::{bin, fmt_value, threshold, variability, HISTLEN};

/// One node: minimum, maximum and mean (single precision, summed as the in-memory builder
/// sums them) and its text when it is not merged (a merged node's text, its mean, is
/// written only if its parent is not merged too).
struct NodeSum {
    vmin: f32,
    vmax: f32,
    vavg: f32,
    text: Option<String>,
}

impl NodeSum {
    /// The node's text at `pad` (its own, or its mean when merged).
    fn into_text(self, pad: &str) -> String {
        match self.text {
            Some(t) => t,
            None => merged(pad, self.vavg),
        }
    }
}

/// The text of a merged node.
fn merged(pad: &str, vavg: f32) -> String {
    format!("{pad}{{ {} }}\n", fenestra_cfmt::fmt_e(f64::from(vavg), 6))
}

/// The values of a block of incident cells: `[cell][grid][outgoing cell]`, cells in
/// `(ix, iy)` order with `iy` fastest, outgoing cells with `oy` fastest.
pub type Rows = Vec<Vec<Vec<f32>>>;

/// Where the values come from: `rows(x0, y0, side)` gives the `side` × `side` incident
/// cells from (x0, y0).
pub type RowFn<'a> = dyn Fn(usize, usize, usize) -> Result<Rows> + Sync + 'a;

/// A reducer of `grids` rank-4 grids of resolution 2^`log2`, fed blocks of 2^`batch_log2`
/// incident cells on a side.
pub struct StreamReduce<'a> {
    log2: u32,
    batch: usize,
    grids: usize,
    rows: &'a RowFn<'a>,
}

fn clamp(v: f32) -> f32 {
    if v > 0.0 {
        v
    } else {
        0.0
    }
}

fn indent(log2: u32, l2s: u32) -> String {
    "    ".repeat((log2 - l2s) as usize)
}

impl<'a> StreamReduce<'a> {
    /// A reducer over `rows`; `batch_log2` ≥ 1 and ≤ `log2`.
    pub fn new(log2: u32, batch_log2: u32, grids: usize, rows: &'a RowFn<'a>) -> Self {
        let b = batch_log2.clamp(1, log2);
        StreamReduce {
            log2,
            batch: 1 << b,
            grids,
            rows,
        }
    }

    /// The trees' texts (as [`crate::reduce::reduce`] writes them), one per grid, culled
    /// at the percentiles `pct` (one per grid). Traces every incident cell twice.
    pub fn reduce(&self, pct: &[f64]) -> Result<Vec<String>> {
        let histos = self.histograms()?;
        let thresh: Vec<f64> = histos
            .iter()
            .zip(pct)
            .map(|(h, &p)| threshold(h, p))
            .collect();
        let n = 1usize << self.log2;
        let root = self.block(0, 0, n, &thresh)?;
        Ok(root
            .into_iter()
            .map(|g| {
                g.into_iter()
                    .next()
                    .map_or_else(String::new, |r| r.into_text(""))
            })
            .collect())
    }

    /// The 16 values of the lowest branch node at incident sub-block (a, b) of a block of
    /// `side` and outgoing block (c, d), in the builder's summing order (last child first,
    /// dimension j taking bit j of the child's index).
    fn leaf_values(rows: &Rows, g: usize, side: usize, n: usize, abcd: [usize; 4]) -> [f32; 16] {
        let [a, b, c, d] = abcd;
        let mut v = [0.0f32; 16];
        for (i, x) in v.iter_mut().enumerate() {
            let (ix, iy) = (2 * a + (i & 1), 2 * b + (i >> 1 & 1));
            let (ox, oy) = (2 * c + (i >> 2 & 1), 2 * d + (i >> 3 & 1));
            *x = clamp(rows[ix * side + iy][g][ox * n + oy]);
        }
        v
    }

    fn histograms(&self) -> Result<Vec<Vec<usize>>> {
        let n = 1usize << self.log2;
        let b = self.batch;
        let mut histos = vec![vec![0usize; HISTLEN]; self.grids];
        for x0 in (0..n).step_by(b) {
            for y0 in (0..n).step_by(b) {
                let rows = (self.rows)(x0, y0, b)?;
                for (g, histo) in histos.iter_mut().enumerate() {
                    // counts are sums, so the split over threads does not matter
                    let (m, k) = (b / 2, n / 2);
                    let part = (0..m * m * k)
                        .into_par_iter()
                        .fold(
                            || vec![0usize; HISTLEN],
                            |mut h, j| {
                                let (a, bb, c) = (j / (m * k), j / k % m, j % k);
                                for d in 0..k {
                                    let v = Self::leaf_values(&rows, g, b, n, [a, bb, c, d]);
                                    let (lo, hi, avg) = stats(&v);
                                    h[bin(variability(lo, hi, avg))] += 1;
                                }
                                h
                            },
                        )
                        .reduce(
                            || vec![0usize; HISTLEN],
                            |mut x, y| {
                                x.iter_mut().zip(y).for_each(|(a, b)| *a += b);
                                x
                            },
                        );
                    histo.iter_mut().zip(part).for_each(|(a, b)| *a += b);
                }
            }
        }
        Ok(histos)
    }

    /// The nodes of the incident block of `side` at (x0, y0), per grid, one per outgoing
    /// block of the same side (`oy` fastest).
    fn block(
        &self,
        x0: usize,
        y0: usize,
        side: usize,
        thresh: &[f64],
    ) -> Result<Vec<Vec<NodeSum>>> {
        let n = 1usize << self.log2;
        if side <= self.batch {
            let rows = (self.rows)(x0, y0, side)?;
            let mut out = Vec::with_capacity(self.grids);
            for (g, &th) in thresh.iter().enumerate().take(self.grids) {
                // the lowest branch level: (side/2)² incident sub-blocks × (n/2)² outgoing
                let (m, k) = (side / 2, n / 2);
                let parts: Vec<Vec<NodeSum>> = (0..m * m * k)
                    .into_par_iter()
                    .map(|j| {
                        let (a, b, c) = (j / (m * k), j / k % m, j % k);
                        (0..k)
                            .map(|d| {
                                let v = Self::leaf_values(&rows, g, side, n, [a, b, c, d]);
                                self.leaf_node(&v, th)
                            })
                            .collect()
                    })
                    .collect();
                let mut level: Vec<NodeSum> = parts.into_iter().flatten().collect();
                // combined up to the block's own side
                let mut s = 2;
                while s < side {
                    level = self.combine(level, side / s, n / s, s, th);
                    s *= 2;
                }
                out.push(level);
            }
            return Ok(out);
        }
        let h = side / 2;
        // the four quarters, each with (n/h)² nodes per grid
        let quarters = [
            self.block(x0, y0, h, thresh)?,
            self.block(x0, y0 + h, h, thresh)?,
            self.block(x0 + h, y0, h, thresh)?,
            self.block(x0 + h, y0 + h, h, thresh)?,
        ];
        let k = n / h;
        let mut out = Vec::with_capacity(self.grids);
        let mut quarters = quarters.map(|q| q.into_iter());
        for &th in thresh.iter().take(self.grids) {
            // as one level of 2 × 2 incident sub-blocks (a-major) of side h
            let mut level: Vec<NodeSum> = Vec::with_capacity(4 * k * k);
            for q in quarters.iter_mut() {
                level.extend(q.next().expect("one level per grid"));
            }
            out.push(self.combine(level, 2, k, h, th));
        }
        Ok(out)
    }

    /// A lowest branch node from its 16 values.
    fn leaf_node(&self, v: &[f32; 16], th: f64) -> NodeSum {
        let (vmin, vmax, vavg) = stats(v);
        let text = (variability(vmin, vmax, vavg) > th).then(|| {
            let mut text = indent(self.log2, 1);
            text.push('{');
            // printed with dimension j taking bit (3 − j) of the position
            for p in 0..16 {
                let i = (p >> 3 & 1) | (p >> 2 & 1) << 1 | (p >> 1 & 1) << 2 | (p & 1) << 3;
                text.push_str(&fmt_value(v[i]));
            }
            text.push_str(" }\n");
            text
        });
        NodeSum {
            vmin,
            vmax,
            vavg,
            text,
        }
    }

    /// Nodes of side `s` (m × m incident sub-blocks, a-major, each with k × k outgoing
    /// blocks) combined into nodes of side 2s.
    fn combine(&self, level: Vec<NodeSum>, m: usize, k: usize, s: usize, th: f64) -> Vec<NodeSum> {
        let mut level: Vec<Option<NodeSum>> = level.into_iter().map(Some).collect();
        let (m2, k2) = (m / 2, k / 2);
        let l2s = (2 * s).trailing_zeros();
        let pad = indent(self.log2, l2s);
        let kid_pad = indent(self.log2, l2s - 1);
        let mut out = Vec::with_capacity(m2 * m2 * k2 * k2);
        for a in 0..m2 {
            for b in 0..m2 {
                for c in 0..k2 {
                    for d in 0..k2 {
                        let at = |i: usize| {
                            let (ia, ib) = (2 * a + (i & 1), 2 * b + (i >> 1 & 1));
                            let (oc, od) = (2 * c + (i >> 2 & 1), 2 * d + (i >> 3 & 1));
                            (ia * m + ib) * k * k + oc * k + od
                        };
                        let (mut vmin, mut vmax, mut vavg) = (1e20f32, 0.0f32, 0.0f32);
                        for i in (0..16).rev() {
                            let kid = level[at(i)].as_ref().expect("each child once");
                            vmin = vmin.min(kid.vmin);
                            vmax = vmax.max(kid.vmax);
                            vavg += kid.vavg;
                        }
                        vavg /= 16.0;
                        let text = if variability(vmin, vmax, vavg) > th {
                            let mut text = pad.clone();
                            text.push_str("{\n");
                            for i in 0..16 {
                                let kid = level[at(i)].take().expect("each child once");
                                text.push_str(&kid.into_text(&kid_pad));
                            }
                            text.push_str(&pad);
                            text.push_str("}\n");
                            Some(text)
                        } else {
                            for i in 0..16 {
                                level[at(i)] = None;
                            }
                            None
                        };
                        out.push(NodeSum {
                            vmin,
                            vmax,
                            vavg,
                            text,
                        });
                    }
                }
            }
        }
        out
    }
}

/// Minimum, maximum and mean of a lowest branch node's values, summed last first.
fn stats(v: &[f32; 16]) -> (f32, f32, f32) {
    let (mut lo, mut hi, mut avg) = (1e20f32, 0.0f32, 0.0f32);
    for &x in v.iter().rev() {
        lo = lo.min(x);
        hi = hi.max(x);
        avg += x;
    }
    (lo, hi, avg / 16.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduce::{reduce, Grid};

    /// A grid with smooth parts, peaks and zeros, so some nodes merge and some do not.
    fn grid(log2: u32) -> Vec<f32> {
        let n = 1usize << log2;
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        (0..n.pow(4))
            .map(|k| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let (ix, ox) = (k >> (3 * log2), (k >> log2) & (n - 1));
                let base = if ix == ox { 5.0 } else { 0.2 };
                let noise = (x >> 40) as f32 / (1u64 << 24) as f32;
                if k % 97 == 0 {
                    0.0
                } else {
                    base * (1.0 + 0.3 * noise * (k % 3) as f32)
                }
            })
            .collect()
    }

    #[test]
    fn streamed_reduction_writes_the_in_memory_text() {
        for log2 in [2u32, 3, 4] {
            let n = 1usize << log2;
            let data = grid(log2);
            let rows = |x0: usize, y0: usize, side: usize| -> Result<Rows> {
                let mut out = Vec::new();
                for ix in x0..x0 + side {
                    for iy in y0..y0 + side {
                        let at = (ix * n + iy) * n * n;
                        out.push(vec![data[at..at + n * n].to_vec()]);
                    }
                }
                Ok(out)
            };
            for pct in [0.0, 50.0, 90.0, 99.0] {
                let want = reduce(
                    &Grid {
                        rank: 4,
                        log2,
                        data: &data,
                    },
                    pct,
                );
                for batch in 1..=log2 {
                    let got = StreamReduce::new(log2, batch, 1, &rows)
                        .reduce(&[pct])
                        .unwrap();
                    assert_eq!(got[0], want, "L {log2} pct {pct} batch {batch}");
                }
            }
        }
    }
}
