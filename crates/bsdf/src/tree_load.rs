//! A tensor tree as Radiance holds it after loading a BSDF file: which component it is,
//! its Lambertian part split off (grey: the reachable minimum; coloured: the CIE u′/v′ rules),
//! values looked up at the nearest leaf times Radiance's position factor, directions
//! oriented into the tree's coordinates, solid angles of leaves. checkBSDF's reciprocity
//! sampling (`check::sampled`) reads trees through this; rendering tensor trees will too.

use std::f64::consts::PI;

use crate::model::Direction;
use crate::radiance::{from_sharp, to_sharp, XYZ_FROM_SHARP_F};
use crate::radiance::{LAMBERTIAN_MIN, TREE_LAMBERTIAN_MAX};
use crate::tree::{disk_to_square, leaf_at, smallest_leaf_edge, Leaf, Node};

/// The small margin of Radiance's arithmetic (see `check::sampled`).
const TINY: f64 = 1e-6;

/// Which component a tree is, named as checkBSDF's rows name it. Directions with z > 0 are on
/// the interior side (the XML back).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Side {
    /// XML `Reflection Back`: light from the interior reflected.
    IntRefl,
    /// XML `Reflection Front`: light from the exterior reflected.
    ExtRefl,
    /// XML `Transmission Back`: light from the interior transmitted.
    IntExt,
    /// XML `Transmission Front`: light from the exterior transmitted.
    ExtInt,
}

/// The components in the order of the component table (and of the colour encoding on loading).
pub(crate) const SIDES: [(Side, Direction); 4] = [
    (Side::IntRefl, Direction::ReflectionBack),
    (Side::ExtRefl, Direction::ReflectionFront),
    (Side::IntExt, Direction::TransmissionBack),
    (Side::ExtInt, Direction::TransmissionFront),
];

/// One `Visible` tree as Radiance holds it after loading (Lambertian minimum subtracted).
#[derive(Debug)]
pub(crate) struct Tree {
    pub(crate) rank: usize,
    pub(crate) side: Side,
    pub(crate) root: Node,
    /// CIE u′ and v′ trees of a coloured component (Radiance loses them when a rank-3 coloured
    /// component has a Lambertian part split off, see `Tree::split_colour`).
    pub(crate) u: Option<Node>,
    pub(crate) v: Option<Node>,
    /// The last pair looked up (oriented directions, tree position, leaf): the sampling asks for
    /// the same pair twice in a row (cell size, then one of the two values).
    pub(crate) memo: Memo,
}

pub(crate) type Memo = std::cell::Cell<Option<([f64; 3], [f64; 3], [f64; 4], Leaf)>>;

impl Tree {
    pub(crate) fn lookup(&self, pos: &[f64; 4]) -> Leaf {
        leaf_at(&self.root, self.rank, pos)
    }

    /// Edge of the smallest leaf.
    pub(crate) fn smallest_leaf(&self) -> f64 {
        smallest_leaf_edge(&self.root)
    }

    /// Edge of the smallest leaf met by the slice through `pos` in the dimensions of `mask`.
    pub(crate) fn slice_smallest_leaf(&self, pos: &[f64; 4], mask: u32) -> f64 {
        fn walk(n: &Node, pos: &[f64; 4], mask: u32, rank: usize, lo: &[f64; 4], size: f64) -> f64 {
            match n {
                Node::Branch(ch) => {
                    let half = 0.5 * size;
                    let mut best = f64::INFINITY;
                    'child: for (k, c) in ch.iter().enumerate() {
                        let mut clo = *lo;
                        for i in 0..rank {
                            let upper = k >> i & 1 == 1;
                            if mask >> i & 1 == 1 && (pos[i] >= lo[i] + half) != upper {
                                continue 'child;
                            }
                            if upper {
                                clo[i] += half;
                            }
                        }
                        best = best.min(walk(c, pos, mask, rank, &clo, half));
                    }
                    best
                }
                Node::Grid { log2, .. } => size / (1u64 << log2) as f64,
            }
        }
        walk(&self.root, pos, mask, self.rank, &[0.0; 4], 1.0)
    }

    /// Smallest value Radiance considers for the Lambertian part (rank 3: only the half of the
    /// incident coordinate that directions reach).
    pub(crate) fn lambertian_min(&self) -> f32 {
        fn min_of(n: &Node) -> f32 {
            match n {
                Node::Branch(ch) => ch.iter().map(min_of).fold(f32::INFINITY, f32::min),
                Node::Grid { values, .. } => values.iter().copied().fold(f32::INFINITY, f32::min),
            }
        }
        if self.rank != 3 {
            return min_of(&self.root);
        }
        let cap = TREE_LAMBERTIAN_MAX as f32;
        match &self.root {
            Node::Branch(ch) => ch.iter().step_by(2).map(min_of).fold(cap, f32::min),
            Node::Grid { log2: 0, values } => values[0],
            Node::Grid { log2, values } => values[..1usize << (3 * log2 - 1)]
                .iter()
                .copied()
                .fold(cap, f32::min),
        }
    }

    pub(crate) fn subtract(&mut self, v: f32) {
        fn walk(n: &mut Node, v: f32) {
            match n {
                Node::Branch(ch) => ch.iter_mut().for_each(|c| walk(c, v)),
                Node::Grid { values, .. } => {
                    for x in values {
                        *x = (*x - v).max(0.0);
                    }
                }
            }
        }
        walk(&mut self.root, v)
    }

    /// Splits the Lambertian part off as Radiance does on loading; returns it as a
    /// hemispherical fraction (π × minimum; 0 when nothing is split off).
    pub(crate) fn split_lambertian(&mut self) -> f64 {
        let vmin = self.lambertian_min();
        if vmin >= TREE_LAMBERTIAN_MAX as f32 || f64::from(vmin) <= LAMBERTIAN_MIN {
            return 0.0;
        }
        self.subtract(vmin);
        PI * f64::from(vmin)
    }

    /// Directional-hemispherical total at normal incidence: π × the mean over the outgoing
    /// square of the slice at incident position 0.5 − 1e-6 (rank 3) or (0.5, 0.5) (rank 4).
    pub(crate) fn normal_total(&self) -> f64 {
        let r = self.rank;
        let at = if r == 3 {
            [0.5 - TINY, 0.0]
        } else {
            [0.5, 0.5]
        };
        let nin = r - 2;
        let mut sum = 0.0;
        visit_leaves(&self.root, r, &[0.0; 4], 1.0, &mut |val, cmin, csiz| {
            let inside = (0..nin).all(|i| cmin[i] <= at[i] && at[i] < cmin[i] + csiz);
            if inside {
                sum += f64::from(val) * csiz * csiz;
            }
        });
        PI * sum
    }

    /// Hemispherical total for uniform diffuse incidence: incident positions weighted by their
    /// projected solid angle (rank 4: uniform over the square; rank 3: position x covers radius
    /// 1 − 2x, so a leaf over [a, b) weighs r(a)² − r(b)²).
    pub(crate) fn diffuse_total(&self) -> f64 {
        let r = self.rank;
        let mut sum = 0.0;
        visit_leaves(&self.root, r, &[0.0; 4], 1.0, &mut |val, cmin, csiz| {
            let w = if r == 4 {
                csiz * csiz
            } else {
                let rad = |x: f64| (1.0 - 2.0 * x).clamp(0.0, 1.0);
                let (ra, rb) = (rad(cmin[0]), rad(cmin[0] + csiz));
                ra * ra - rb * rb
            };
            sum += f64::from(val) * csiz * csiz * w;
        });
        PI * sum
    }

    /// The largest directional-hemispherical total as Radiance computes it: π × the largest mean
    /// of the tree over incident strips (rank 3: of the reachable half; rank 4: squares) as wide
    /// as the smallest leaf, at least 1/32.
    pub(crate) fn max_hemi(&self) -> f64 {
        let step = self.smallest_leaf().max(0.03125);
        let mut best = 0.0f64;
        let (mut lo, mut hi) = ([0.0, 0.0, 0.0, 0.0], [1.0; 4]);
        if self.rank == 3 {
            lo[0] = 0.0;
            while lo[0] < 0.5 - TINY {
                hi[0] = lo[0] + step;
                best = best.max(box_mean(&self.root, 3, &lo, &hi));
                lo[0] += step;
            }
        } else {
            lo[0] = 0.0;
            while lo[0] < 1.0 - TINY {
                hi[0] = lo[0] + step;
                lo[1] = 0.0;
                while lo[1] < 1.0 - TINY {
                    hi[1] = lo[1] + step;
                    best = best.max(box_mean(&self.root, 4, &lo, &hi));
                    lo[1] += step;
                }
                lo[0] += step;
            }
        }
        best * PI
    }

    /// Orders a direction pair for this tree (`a` where light comes from as Radiance's tree
    /// query names it); `None` when the pair is not on this component's sides.
    pub(crate) fn orient(&self, a: [f64; 3], b: [f64; 3]) -> Option<([f64; 3], [f64; 3])> {
        orient(self.side, a, b)
    }

    /// The leaf for the pair `(a, b)` in Radiance's tree-query order.
    pub(crate) fn query(&self, a: [f64; 3], b: [f64; 3]) -> Option<Leaf> {
        Some(self.locate(a, b)?.1)
    }

    /// Tree position and leaf of the pair `(a, b)` in Radiance's tree-query order.
    pub(crate) fn locate(&self, a: [f64; 3], b: [f64; 3]) -> Option<([f64; 4], Leaf)> {
        let (i, o) = self.orient(a, b)?;
        if let Some((mi, mo, pos, leaf)) = self.memo.get() {
            if mi == i && mo == o {
                return Some((pos, leaf));
            }
        }
        let pos = self.position(i, o);
        let leaf = self.lookup(&pos);
        self.memo.set(Some((i, o, pos, leaf)));
        Some((pos, leaf))
    }

    /// Tree coordinates of the oriented pair (`i` where the tree's light comes from).
    pub(crate) fn position(&self, i: [f64; 3], o: [f64; 3]) -> [f64; 4] {
        position(self.rank, i, o)
    }

    /// The tree's BSDF coefficients for the pair as Radiance returns them: one (grey) or three
    /// (Sharp RGB weighted by the primaries' luminances, from the value and the u′, v′ trees).
    pub(crate) fn coefs(&self, a: [f64; 3], b: [f64; 3]) -> Option<([f32; 3], usize)> {
        let (pos, leaf) = self.locate(a, b)?;
        // The reference scales a leaf's value by 1 + 1e-4·d, d the sum over the dimensions
        // (last first) of frac(2^(i+1) / (corner_i + 0.01687)) − 1/2: a fixed jitter from the
        // leaf's position, rounded to float with the value.
        let y = leaf_value(self.rank, &leaf);
        let (Some(u), Some(v)) = (&self.u, &self.v) else {
            return Some(([y, 0.0, 0.0], 1));
        };
        let up = leaf_at(u, self.rank, &pos).value;
        let vp = leaf_at(v, self.rank, &pos).value;
        let rgb = yuv_to_sharp(f64::from(y), f64::from(up), f64::from(vp));
        let w = XYZ_FROM_SHARP_F[1];
        Some(([rgb[0] * w[0], rgb[1] * w[1], rgb[2] * w[2]], 3))
    }

    /// Splits a coloured Lambertian part off as Radiance does on loading: the per-channel
    /// minima (Sharp RGB) over the Y tree's leaves (rank 3: the reachable half), each leaf's
    /// colour averaged from the u′, v′ trees over the leaf; when their luminance lies above
    /// 0.01/π it is subtracted from the Y tree and every u′ (v′) leaf is recoloured with the
    /// minimum taken off (channels kept at least 1e-5 × the leaf's mean Y). Radiance skips the
    /// unreachable leaves of a rank-3 u′/v′ tree while rebuilding it, which leaves the new tree
    /// incomplete and drops it: the component is grey from then on.
    ///
    /// Leaf values of u′, v′ trees are checked on reading (v′ in (0, 0.75)); a mean can still come
    /// out 0 where the box is tiny against a branch of the averaged tree (the averaging skips
    /// overlaps below 1e-10 of a child). That leaf has no chromaticity: it takes no part in the
    /// minimum, and a recoloured leaf becomes NaN, as in Radiance; a sampled pair that meets such
    /// a leaf makes its row an error ([`SampledRow`] rows are never NaN).
    pub(crate) fn split_colour(&mut self) -> Lambertian {
        let none = Lambertian {
            y: 0.0,
            xyz: [0.0; 3],
        };
        let (Some(u), Some(v)) = (&self.u, &self.v) else {
            return none;
        };
        let r = self.rank;
        let dead = |cmin: &[f64; 4], csiz: f64| r == 3 && cmin[0] + 0.5 * csiz >= 0.5;
        let upper = |cmin: &[f64; 4], csiz: f64| {
            let mut cmax = *cmin;
            for c in cmax.iter_mut().take(r) {
                *c += csiz;
            }
            cmax
        };
        let mut min = [1e10f32; 3];
        visit_leaves(&self.root, r, &[0.0; 4], 1.0, &mut |val, cmin, csiz| {
            if dead(cmin, csiz) {
                return;
            }
            let cmax = upper(cmin, csiz);
            // A mean without a chromaticity gives NaN channels, which no comparison keeps: such
            // a leaf takes no part in the minimum (as in Radiance 6.0a, whose output on a rank-4
            // tree with 1/1024 Visible leaves under one-level u′/v′ trees this matches).
            let rgb = yuv_to_sharp(
                f64::from(val),
                box_mean(u, r, cmin, &cmax),
                box_mean(v, r, cmin, &cmax),
            );
            for c in 0..3 {
                if rgb[c] < min[c] {
                    min[c] = rgb[c];
                }
            }
        });
        let (ymin, cs) = from_sharp(min);
        if ymin >= 0.5e10 || ymin <= LAMBERTIAN_MIN {
            return none;
        }
        // Recolour one chromaticity tree: `pick` gives the new coordinate of a remainder colour.
        let recolour = |t: &Node, is_u: bool| -> Option<Node> {
            let mut complete = true;
            let node = map_leaves(t, r, &[0.0; 4], 1.0, &mut |val, cmin, csiz| {
                if dead(cmin, csiz) {
                    complete = false;
                    return val;
                }
                let cmax = upper(cmin, csiz);
                let yval = box_mean(&self.root, r, cmin, &cmax);
                let (um, vm) = if is_u {
                    (f64::from(val), box_mean(v, r, cmin, &cmax))
                } else {
                    (box_mean(u, r, cmin, &cmax), f64::from(val))
                };
                let mut rgb = yuv_to_sharp(yval, um, vm);
                for c in 0..3 {
                    rgb[c] -= min[c];
                    if f64::from(rgb[c]) < 1e-5 * yval {
                        rgb[c] = (1e-5 * yval) as f32;
                    }
                }
                let third = (1.0f64 / 3.0) as f32;
                let (cx, cy) = from_sharp(rgb).1.unwrap_or((third, third));
                let (cx, cy) = (f64::from(cx), f64::from(cy));
                let d = -2.0 * cx + 12.0 * cy + 3.0;
                (if is_u { 4.0 * cx / d } else { 9.0 * cy / d }) as f32
            });
            complete.then_some(node)
        };
        let new_u = recolour(u, true);
        let new_v = recolour(v, false);
        self.u = new_u;
        self.v = new_v;
        self.subtract(ymin as f32);
        let third = (1.0f64 / 3.0) as f32;
        let (cx, cy) = cs.unwrap_or((third, third));
        let y = PI * ymin;
        Lambertian {
            y,
            xyz: [
                y * f64::from(cx) / f64::from(cy),
                y,
                y * f64::from(1.0f32 - cx - cy) / f64::from(cy),
            ],
        }
    }

    /// Projected solid angle of the leaf for a pair (`π·edge²`), or, without `b`, of the
    /// smallest leaf in the slice of incident direction `a`.
    pub(crate) fn solid_angle(&self, a: [f64; 3], b: Option<[f64; 3]>) -> Option<f64> {
        match b {
            Some(b) => {
                let e = self.query(a, b)?.edge;
                Some(e * (e * PI))
            }
            None => {
                if self.rank != 4 {
                    return None;
                }
                // The slice the reference's sampling table for incident direction `a` covers: a
                // tree used in reverse (light arriving on the other side) is sliced in its
                // outgoing dimensions. The leaf width is rounded to 1/65536 as that table keeps it.
                let interior = a[2] > 0.0;
                let reverse = match self.side {
                    Side::IntRefl => {
                        if !interior {
                            return Some(0.0);
                        }
                        false
                    }
                    Side::ExtRefl => {
                        if a[2] > 0.0 {
                            return Some(0.0);
                        }
                        false
                    }
                    Side::IntExt => a[2] < 0.0,
                    Side::ExtInt => a[2] > 0.0,
                };
                let (u, v) = if reverse {
                    disk_to_square(a[0], a[1])
                } else {
                    disk_to_square(-a[0], -a[1])
                };
                if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
                    return Some(0.0);
                }
                let (pos, mask) = if reverse {
                    ([0.0, 0.0, u, v], 0b1100)
                } else {
                    ([u, v, 0.0, 0.0], 0b0011)
                };
                let w = self.slice_smallest_leaf(&pos, mask);
                let wid = (w * 65536.0 + 0.5) as u32;
                let s = f64::from(wid) / 65536.0;
                Some(PI * s * s)
            }
        }
    }
}

/// Sharp RGB (single precision) of luminance `y` and CIE (u′, v′), as Radiance converts it.
pub(crate) fn yuv_to_sharp(y: f64, u: f64, v: f64) -> [f32; 3] {
    let df = 1.0 / (6.0 * u - 16.0 * v + 12.0);
    to_sharp(((9.0 * u * df) as f32, (4.0 * v * df) as f32), y)
}

/// Calls `f(value, lower corner, edge)` for every leaf of `node` (lower corner `cmin`, edge
/// `csiz`).
pub(crate) fn visit_leaves(
    node: &Node,
    r: usize,
    cmin: &[f64; 4],
    csiz: f64,
    f: &mut dyn FnMut(f32, &[f64; 4], f64),
) {
    match node {
        Node::Branch(ch) => {
            let half = 0.5 * csiz;
            for (n, c) in ch.iter().enumerate() {
                visit_leaves(c, r, &child_corner(cmin, r, n, half), half, f);
            }
        }
        Node::Grid { log2, values } => {
            let cells = 1usize << log2;
            let cell = csiz / cells as f64;
            for (k, &val) in values.iter().enumerate() {
                f(val, &cell_corner(cmin, r, cells, cell, k), cell);
            }
        }
    }
}

/// Lower corner of child `n` (of a branch of rank `r`, corner `cmin`, half edge `half`):
/// bit `i` of `n` set puts the child in the upper half of dimension `i`.
#[inline]
pub(crate) fn child_corner(cmin: &[f64; 4], r: usize, n: usize, half: f64) -> [f64; 4] {
    let mut lo = *cmin;
    for (i, l) in lo.iter_mut().enumerate().take(r) {
        if n >> i & 1 == 1 {
            *l += half;
        }
    }
    lo
}

/// Lower corner of cell `k` (dimension 0 slowest) of a grid of `cells` per dimension and cell
/// edge `cell` whose corner is `cmin`.
#[inline]
pub(crate) fn cell_corner(
    cmin: &[f64; 4],
    r: usize,
    cells: usize,
    cell: f64,
    k: usize,
) -> [f64; 4] {
    let mut lo = *cmin;
    for (i, l) in lo.iter_mut().enumerate().take(r) {
        let ci = k / cells.pow((r - 1 - i) as u32) % cells;
        *l += cell * ci as f64;
    }
    lo
}

/// `node` with every leaf value replaced by `f(value, lower corner, edge)`.
pub(crate) fn map_leaves(
    node: &Node,
    r: usize,
    cmin: &[f64; 4],
    csiz: f64,
    f: &mut dyn FnMut(f32, &[f64; 4], f64) -> f32,
) -> Node {
    match node {
        Node::Branch(ch) => {
            let half = 0.5 * csiz;
            let mut out = Vec::with_capacity(ch.len());
            for (n, c) in ch.iter().enumerate() {
                out.push(map_leaves(c, r, &child_corner(cmin, r, n, half), half, f));
            }
            Node::Branch(out)
        }
        Node::Grid { log2, values } => {
            let cells = 1usize << log2;
            let cell = csiz / cells as f64;
            let values = values
                .iter()
                .enumerate()
                .map(|(k, &val)| f(val, &cell_corner(cmin, r, cells, cell, k), cell))
                .collect();
            Node::Grid {
                log2: *log2,
                values,
            }
        }
    }
}

/// The mean of a tree over the box `[bmin, bmax)` as Radiance computes it: a branch weighs each
/// child (last child first) by the overlap of the box with it, measured in the child's own unit
/// cube, skips overlaps of at most 1e-10 and divides by the weights' sum plus 1e-20; a grid
/// gives the plain mean of the cells the box touches (upper index rounded up after adding
/// 0.999999).
pub(crate) fn box_mean(node: &Node, r: usize, bmin: &[f64; 4], bmax: &[f64; 4]) -> f64 {
    for i in 0..r {
        if bmin[i] >= 1.0 || bmax[i] <= 0.0 || bmin[i] >= bmax[i] {
            return 0.0;
        }
    }
    match node {
        Node::Branch(ch) => {
            let (mut sum, mut wsum) = (0.0, 1e-20);
            for n in (0..ch.len()).rev() {
                let (mut lo, mut hi) = ([0.0; 4], [0.0; 4]);
                let mut w = 1.0;
                for i in (0..r).rev() {
                    lo[i] = 2.0 * bmin[i];
                    hi[i] = 2.0 * bmax[i];
                    if n >> i & 1 == 1 {
                        lo[i] -= 1.0;
                        hi[i] -= 1.0;
                    }
                    lo[i] = lo[i].max(0.0);
                    hi[i] = hi[i].min(1.0);
                    if lo[i] >= hi[i] {
                        w = 0.0;
                        break;
                    }
                    w *= hi[i] - lo[i];
                }
                if w > 1e-10 {
                    sum += w * box_mean(&ch[n], r, &lo, &hi);
                    wsum += w;
                }
            }
            sum / wsum
        }
        Node::Grid { log2, values } => {
            let cells = 1usize << log2;
            let (mut imin, mut imax) = ([0usize; 4], [0usize; 4]);
            let mut n = 1;
            for i in (0..r).rev() {
                imin[i] = if bmin[i] <= 0.0 {
                    0
                } else {
                    (cells as f64 * bmin[i]) as usize
                };
                imax[i] = if bmax[i] >= 1.0 {
                    cells
                } else {
                    (cells as f64 * bmax[i] + 0.999999) as usize
                };
                n *= imax[i] - imin[i];
            }
            if n == 0 {
                return 0.0;
            }
            grid_box_sum(values, r, *log2, &imin[..r], &imax[..r]) / n as f64
        }
    }
}

/// Sum of a grid's values over an index box, dimension 0 outermost, each innermost run added
/// in index order (the order the reference's sum has, which the rounding of the f64 sum
/// depends on).
pub(crate) fn grid_box_sum(
    va: &[f32],
    nd: usize,
    log2: u32,
    imin: &[usize],
    imax: &[usize],
) -> f64 {
    let skip = 1usize << ((nd - 1) as u32 * log2);
    let mut sum = 0.0;
    if skip == 1 {
        for &v in &va[imin[0]..imax[0]] {
            sum += f64::from(v);
        }
    } else {
        for i in imin[0]..imax[0] {
            sum += grid_box_sum(&va[i * skip..], nd - 1, log2, &imin[1..], &imax[1..]);
        }
    }
    sum
}

/// `v` turned about the z axis by `theta` (unchanged for 0).
pub(crate) fn spin_z(v: [f64; 3], theta: f64) -> [f64; 3] {
    if theta == 0.0 {
        return v;
    }
    let (s, c) = theta.sin_cos();
    [v[0] * c - v[1] * s, v[1] * c + v[0] * s, v[2]]
}

/// A Lambertian part split off on loading: CIE Y and XYZ as hemispherical fractions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lambertian {
    /// π × the Y value split off.
    pub y: f64,
    /// CIE X, Y, Z (grey: all equal to `y`).
    pub xyz: [f64; 3],
}

/// Orders a direction pair for a component on `side` (`a` where light comes from as
/// Radiance's tree query names it); `None` when the pair is not on that component's sides.
pub(crate) fn orient(side: Side, a: [f64; 3], b: [f64; 3]) -> Option<([f64; 3], [f64; 3])> {
    match side {
        Side::IntRefl => (b[2] >= 0.0 && a[2] >= 0.0).then_some((a, b)),
        Side::ExtRefl => (b[2] <= 0.0 && a[2] <= 0.0).then_some((a, b)),
        Side::IntExt => {
            if b[2] > 0.0 {
                (a[2] <= 0.0).then_some((b, a))
            } else {
                (a[2] >= 0.0).then_some((a, b))
            }
        }
        Side::ExtInt => {
            if a[2] > 0.0 {
                (b[2] <= 0.0).then_some((b, a))
            } else {
                (b[2] >= 0.0).then_some((a, b))
            }
        }
    }
}

/// Tree coordinates of an oriented pair (`i` where the tree's light comes from) in a tree
/// of `rank` 3 (isotropic: the radius of `i` and `o` turned by `i`'s azimuth) or 4.
pub(crate) fn position(rank: usize, i: [f64; 3], o: [f64; 3]) -> [f64; 4] {
    let mut pos = [0.0; 4];
    if rank == 3 {
        let theta = -(-i[1]).atan2(-i[0]);
        let r = spin_z(o, theta);
        pos[0] = (0.5 - TINY) - 0.5 * (i[0] * i[0] + i[1] * i[1]).sqrt();
        let (u, v) = disk_to_square(r[0], r[1]);
        pos[1] = u;
        pos[2] = v;
    } else {
        let (u, v) = disk_to_square(-i[0], -i[1]);
        let (s, t) = disk_to_square(o[0], o[1]);
        pos = [u, v, s, t];
    }
    pos
}

/// A leaf's value as Radiance returns it: scaled by `1 + 1e-4·d`, d the sum over the
/// dimensions (last first) of frac(2^(i+1) / (corner_i + 0.01687)) − 1/2, a fixed jitter
/// from the leaf's position that keeps equal leaves apart, rounded to single precision.
pub(crate) fn leaf_value(rank: usize, leaf: &Leaf) -> f32 {
    let mut d = 0.0;
    for i in (0..rank).rev() {
        let x = f64::from(2u32 << i) / (leaf.corner[i] + 0.01687);
        d += x - x.trunc() - 0.5;
    }
    (f64::from(leaf.value) * (1.0 + 1e-4 * d)) as f32
}
