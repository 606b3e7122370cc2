//! Tensor-tree reduction (what Radiance's `rttree_reduce` does for genBSDF; facts from its
//! source, our own code): the full-resolution grid of BSDF values (rank 4: incident x, y,
//! outgoing x, y; rank 3: the isotropic half) is built into a tree whose nodes keep their
//! minimum, maximum and mean; each node of four (or three) halvings gets a variability
//! measure `√((max − min)/(√mean + 0.03))`; the threshold is the given percentile of the
//! measure over the lowest branch nodes (a 300-bin histogram up to 4); nodes at or below it are
//! merged into their mean from the top down. Optional reciprocity averaging first.

use std::fmt::Write as _;

/// Histogram bins of the variability measure.
pub(crate) const HISTLEN: usize = 300;
/// Largest measure recorded.
pub(crate) const HISTMAX: f64 = 4.0;

struct TNode {
    vmin: f32,
    vmax: f32,
    vavg: f32,
    kids: Option<Vec<TNode>>,
}

fn measure(n: &TNode) -> f64 {
    variability(n.vmin, n.vmax, n.vavg)
}

/// rttree_reduce's variability of a node from its minimum, maximum and mean.
pub(crate) fn variability(vmin: f32, vmax: f32, vavg: f32) -> f64 {
    (f64::from(vmax - vmin) / (f64::from(vavg).sqrt() + 0.03)).sqrt()
}

/// The histogram bin of a variability.
pub(crate) fn bin(m: f64) -> usize {
    (((HISTLEN as f64 / HISTMAX) * m) as usize).min(HISTLEN - 1)
}

/// The merge threshold: the `pctcull` percentile of the lowest branch nodes' variability.
pub(crate) fn threshold(histo: &[usize], pctcull: f64) -> f64 {
    let total: usize = histo.iter().sum();
    let mut hsum = (pctcull * 0.01 * total as f64) as i64;
    let mut i = 0;
    while hsum > 0 && i < histo.len() {
        hsum -= histo[i] as i64;
        i += 1;
    }
    (HISTMAX / HISTLEN as f64) * i as f64
}

/// The data of one component on a `2^log2` grid per dimension, dimension 0 slowest
/// (rank 4: `[ix][iy][ox][oy]`; rank 3: `[ix][ox][oy]` with ix over the first half only).
pub struct Grid<'a> {
    /// Rank (3 or 4).
    pub rank: usize,
    /// log2 of the resolution per dimension.
    pub log2: u32,
    /// The values (negatives and NaN are taken as zero).
    pub data: &'a [f32],
}

impl Grid<'_> {
    fn value(&self, c: &[usize; 4]) -> f32 {
        let mut idx = 0usize;
        for &x in &c[..self.rank] {
            idx = (idx << self.log2) + x;
        }
        let v = self.data[idx];
        if v > 0.0 {
            v
        } else {
            0.0
        }
    }
}

struct Builder<'a> {
    g: &'a Grid<'a>,
    histo: Vec<usize>,
}

impl Builder<'_> {
    fn build(&mut self, bmin: [usize; 4], l2s: u32) -> TNode {
        let rank = self.g.rank;
        let mut n = TNode {
            vmin: 1e20,
            vmax: 0.0,
            vavg: 0.0,
            kids: None,
        };
        if l2s <= 1 {
            for i in (0..1usize << rank).rev() {
                let mut c = bmin;
                for (j, cj) in c.iter_mut().enumerate().take(rank) {
                    *cj += i >> j & 1;
                }
                let v = self.g.value(&c);
                n.vmin = n.vmin.min(v);
                n.vmax = n.vmax.max(v);
                n.vavg += v;
            }
            n.vavg /= (1usize << rank) as f32;
            self.histo[bin(measure(&n))] += 1;
            return n;
        }
        let l2s = l2s - 1;
        let mut kids: Vec<TNode> = Vec::with_capacity(1 << rank);
        // children are built from the last to the first, as rttree_reduce sums them
        let mut built: Vec<Option<TNode>> = (0..1usize << rank).map(|_| None).collect();
        for i in (0..1usize << rank).rev() {
            let mut c = bmin;
            for (j, cj) in c.iter_mut().enumerate().take(rank) {
                *cj += (i >> j & 1) << l2s;
            }
            let k = self.build(c, l2s);
            n.vmin = n.vmin.min(k.vmin);
            n.vmax = n.vmax.max(k.vmax);
            n.vavg += k.vavg;
            built[i] = Some(k);
        }
        n.vavg /= (1usize << rank) as f32;
        kids.extend(built.into_iter().map(|k| k.expect("built")));
        n.kids = Some(kids);
        n
    }
}

fn trim(n: &mut TNode, thresh: f64) {
    if n.kids.is_none() {
        return;
    }
    if measure(n) > thresh {
        for k in n.kids.as_mut().expect("kids") {
            trim(k, thresh);
        }
        return;
    }
    n.kids = None;
}

pub(crate) fn fmt_value(v: f32) -> String {
    if (0.001..10.0).contains(&v) {
        format!(" {v:.7}")
    } else {
        format!(" {}", fenestra_cfmt::fmt_e(f64::from(v), 3))
    }
}

fn print(out: &mut String, g: &Grid, n: &TNode, bmin: [usize; 4], l2s: u32, thresh: f64) {
    let rank = g.rank;
    for _ in 0..(g.log2 - l2s) {
        out.push_str("    ");
    }
    out.push('{');
    if l2s <= 1 && measure(n) > thresh {
        for i in 0..1usize << rank {
            let mut c = bmin;
            for (j, cj) in c.iter_mut().enumerate().take(rank) {
                *cj += i >> (rank - 1 - j) & 1;
            }
            out.push_str(&fmt_value(g.value(&c)));
        }
        out.push_str(" }\n");
        return;
    }
    let Some(kids) = &n.kids else {
        let _ = writeln!(out, " {} }}", fenestra_cfmt::fmt_e(f64::from(n.vavg), 6));
        return;
    };
    out.push('\n');
    for (i, k) in kids.iter().enumerate() {
        let mut c = bmin;
        for (j, cj) in c.iter_mut().enumerate().take(rank) {
            *cj += (i >> j & 1) << (l2s - 1);
        }
        print(out, g, k, c, l2s - 1, thresh);
    }
    for _ in 0..(g.log2 - l2s) {
        out.push_str("    ");
    }
    out.push_str("}\n");
}

/// Averages reciprocal pairs (rank 4: value(i → o) with value(o' → i') where ' reverses both
/// grid indices; rank 3: the two azimuth halves), as `rttree_reduce -a`.
pub fn reciprocity(rank: usize, log2: u32, data: &mut [f32]) {
    let siz = 1usize << log2;
    let idx4 = |a: usize, b: usize, c: usize, d: usize| (((a << log2) + b) << log2 | c) << log2 | d;
    if rank == 3 {
        let idx3 = |a: usize, c: usize, d: usize| ((a << log2) + c) << log2 | d;
        for ix in 0..siz / 2 {
            for ox in 0..siz {
                for oy in 0..siz / 2 {
                    let (p, q) = (idx3(ix, ox, oy), idx3(ix, ox, siz - 1 - oy));
                    let m = 0.5 * (data[p] + data[q]);
                    data[p] = m;
                    data[q] = m;
                }
            }
        }
        return;
    }
    for ix in 0..siz {
        for iy in 0..siz {
            let mut cnt = ix * siz + iy;
            let mut ox = 0;
            'outer: while cnt > 0 {
                for oy in 0..siz {
                    let p = idx4(siz - 1 - ix, siz - 1 - iy, ox, oy);
                    let q = idx4(siz - 1 - ox, siz - 1 - oy, ix, iy);
                    let m = 0.5 * (data[p] + data[q]);
                    data[p] = m;
                    data[q] = m;
                    cnt -= 1;
                    if cnt == 0 {
                        break 'outer;
                    }
                }
                ox += 1;
            }
        }
    }
}

/// The tensor tree (text, as the XML's `ScatteringData` holds it) of `grid`, culled at the
/// `pctcull` percentile (0 ≤ pctcull < 100).
pub fn reduce(grid: &Grid, pctcull: f64) -> String {
    let mut b = Builder {
        g: grid,
        histo: vec![0; HISTLEN],
    };
    let mut root = b.build([0; 4], grid.log2);
    let thresh = threshold(&b.histo, pctcull);
    trim(&mut root, thresh);
    let mut out = String::new();
    print(&mut out, grid, &root, [0; 4], grid.log2, thresh);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_grid_becomes_one_value_and_a_peak_stays() {
        let log2 = 2;
        let n = 1usize << (4 * log2);
        let data = vec![0.5f32; n];
        let t = reduce(
            &Grid {
                rank: 4,
                log2,
                data: &data,
            },
            90.0,
        );
        assert_eq!(t.trim(), "{ 5.000000e-01 }");
        let mut data = vec![0.1f32; n];
        data[5] = 100.0;
        let t = reduce(
            &Grid {
                rank: 4,
                log2,
                data: &data,
            },
            90.0,
        );
        let tree = fenestra_bsdf::tree::TensorTree::parse(4, &t).unwrap();
        let _ = tree;
        assert!(t.contains("1.000e+02"), "{t}");
    }

    #[test]
    fn reciprocity_averages_pairs_once() {
        let log2 = 1;
        let siz = 2usize;
        let mut data: Vec<f32> = (0..16).map(|k| k as f32).collect();
        reciprocity(4, log2, &mut data);
        let at = |a: usize, b: usize, c: usize, d: usize| data[((a * siz + b) * siz + c) * siz + d];
        for ix in 0..2 {
            for iy in 0..2 {
                for ox in 0..2 {
                    for oy in 0..2 {
                        assert_eq!(at(1 - ix, 1 - iy, ox, oy), at(1 - ox, 1 - oy, ix, iy));
                    }
                }
            }
        }
    }
}
