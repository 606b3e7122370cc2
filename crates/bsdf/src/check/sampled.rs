//! Reciprocity rows of tensor-tree files computed the way Radiance 6.0a's `checkBSDF` samples
//! them, so that the printed rows agree digit for digit (docs/tools/checkBSDF.md).
//!
//! Radiance compares, for pairs of directions `(a, b)`, the total BSDF (Lambertian part
//! included) for light from `b` towards `a` with the one for light from `a` towards `b`, as the
//! relative difference `|x − y| / (max(x, y) + 1e-6)`; no pair is left out, a zero against a
//! value gives 100%. The pairs come from a random quadtree over the unit square that the
//! Shirley–Chiu map sends to the hemisphere:
//!
//! * The square is split into 16 × 16 cells, then each cell (visited in quadrant order: left
//!   top, right top, left bottom, right bottom) draws a point with two `drand48()` numbers. When
//!   the tree leaf that holds the pair at that point is smaller than the cell (projected solid
//!   angle `π·leaf²` below `π·cell² − 1e-6`) the point is dropped and the cell is split in
//!   four, each drawing its own point; otherwise the point is one sample.
//! * Rank 3 (isotropic): the first direction walks the radius `(k + ½)·s` along +x (`s` = the
//!   forward component's smallest leaf), the second comes from the quadtree over the other
//!   hemisphere side (`Transmission Back` is the forward transmission).
//! * Rank 4: the first direction comes from a quadtree of its own, where a cell's size is
//!   compared with the smallest leaf that the tree slice of that incident direction holds; each
//!   accepted point runs a second quadtree for the other direction.
//!
//! Tree values are looked up as Radiance does: nearest leaf, after the Lambertian minimum is
//! subtracted (float arithmetic), times Radiance's position-dependent factor `1 + 1e-4·d` that
//! keeps equal leaves apart; a coloured component's value is the sum of its luminance-weighted
//! Sharp RGB channels from the u′, v′ trees. The Lambertian parts are split off as Radiance's
//! loader does (grey: the reachable minimum; coloured: [`Tree::split_colour`]). The generator is
//! the process's one (the colour dither's): state runs on from file to file.

use std::f64::consts::{FRAC_PI_4, PI};

use crate::check::Reciprocity;
use crate::model::Direction;
use crate::radiance::{from_sharp, to_sharp, Drand48, XYZ_FROM_SHARP_F};

/// Radiance's `FTINY`.
const FTINY: f64 = 1e-6;

/// Which side of the surface a tree describes (Radiance's front = XML back).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Side {
    /// XML `Reflection Back`.
    FrontRefl,
    /// XML `Reflection Front`.
    BackRefl,
    /// XML `Transmission Back`.
    FrontTrans,
    /// XML `Transmission Front`.
    BackTrans,
}

#[derive(Debug)]
enum Node {
    Branch(Vec<Node>),
    Grid { log2: u32, values: Vec<f32> },
}

/// One `Visible` tree as Radiance holds it after loading (Lambertian minimum subtracted).
#[derive(Debug)]
struct Tree {
    rank: usize,
    side: Side,
    root: Node,
    /// CIE u′ and v′ trees of a coloured component (Radiance loses them when a rank-3 coloured
    /// component has a Lambertian part split off, see [`Tree::split_colour`]).
    u: Option<Node>,
    v: Option<Node>,
    /// The last pair looked up (oriented directions, tree position, leaf): the sampling asks for
    /// the same pair twice in a row (cell size, then one of the two values).
    memo: Memo,
}

type Memo = std::cell::Cell<Option<([f64; 3], [f64; 3], [f64; 4], Leaf)>>;

/// A leaf found by a lookup: its value and its hypercube (lower corner, edge).
#[derive(Clone, Copy, Debug)]
struct Leaf {
    value: f32,
    corner: [f64; 4],
    edge: f64,
}

impl Tree {
    fn lookup(&self, pos: &[f64; 4]) -> Leaf {
        lookup_node(&self.root, self.rank, pos)
    }

    /// Edge of the smallest leaf.
    fn smallest_leaf(&self) -> f64 {
        fn walk(n: &Node) -> f64 {
            match n {
                Node::Branch(ch) => 0.5 * ch.iter().map(walk).fold(1.0, f64::min),
                Node::Grid { log2, .. } => 1.0 / (1u64 << log2) as f64,
            }
        }
        walk(&self.root)
    }

    /// Edge of the smallest leaf met by the slice through `pos` in the dimensions of `mask`.
    fn slice_smallest_leaf(&self, pos: &[f64; 4], mask: u32) -> f64 {
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
    fn lambertian_min(&self) -> f32 {
        fn min_of(n: &Node) -> f32 {
            match n {
                Node::Branch(ch) => ch.iter().map(min_of).fold(f32::INFINITY, f32::min),
                Node::Grid { values, .. } => values.iter().copied().fold(f32::INFINITY, f32::min),
            }
        }
        if self.rank != 3 {
            return min_of(&self.root);
        }
        let cap = (1.5 / PI) as f32;
        match &self.root {
            Node::Branch(ch) => ch.iter().step_by(2).map(min_of).fold(cap, f32::min),
            Node::Grid { log2: 0, values } => values[0],
            Node::Grid { log2, values } => values[..1usize << (3 * log2 - 1)]
                .iter()
                .copied()
                .fold(cap, f32::min),
        }
    }

    fn subtract(&mut self, v: f32) {
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
    fn split_lambertian(&mut self) -> f64 {
        let vmin = self.lambertian_min();
        if vmin >= (1.5 / PI) as f32 || f64::from(vmin) <= 0.01 / PI {
            return 0.0;
        }
        self.subtract(vmin);
        PI * f64::from(vmin)
    }

    /// Directional-hemispherical total at normal incidence: π × the mean over the outgoing
    /// square of the slice at incident position 0.5 − 1e-6 (rank 3) or (0.5, 0.5) (rank 4).
    fn normal_total(&self) -> f64 {
        let r = self.rank;
        let at = if r == 3 {
            [0.5 - FTINY, 0.0]
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
    fn diffuse_total(&self) -> f64 {
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

    /// Radiance's largest directional-hemispherical total (see [`TreeFile::max_totals`]).
    fn max_hemi(&self) -> f64 {
        let step = self.smallest_leaf().max(0.03125);
        let mut best = 0.0f64;
        let (mut lo, mut hi) = ([0.0, 0.0, 0.0, 0.0], [1.0; 4]);
        if self.rank == 3 {
            lo[0] = 0.0;
            while lo[0] < 0.5 - FTINY {
                hi[0] = lo[0] + step;
                best = best.max(avg_box(&self.root, 3, &lo, &hi));
                lo[0] += step;
            }
        } else {
            lo[0] = 0.0;
            while lo[0] < 1.0 - FTINY {
                hi[0] = lo[0] + step;
                lo[1] = 0.0;
                while lo[1] < 1.0 - FTINY {
                    hi[1] = lo[1] + step;
                    best = best.max(avg_box(&self.root, 4, &lo, &hi));
                    lo[1] += step;
                }
                lo[0] += step;
            }
        }
        best * PI
    }

    /// Orders a direction pair for this tree (`a` where light comes from as Radiance's tree
    /// query names it); `None` when the pair is not on this component's sides.
    fn orient(&self, a: [f64; 3], b: [f64; 3]) -> Option<([f64; 3], [f64; 3])> {
        match self.side {
            Side::FrontRefl => (b[2] >= 0.0 && a[2] >= 0.0).then_some((a, b)),
            Side::BackRefl => (b[2] <= 0.0 && a[2] <= 0.0).then_some((a, b)),
            Side::FrontTrans => {
                if b[2] > 0.0 {
                    (a[2] <= 0.0).then_some((b, a))
                } else {
                    (a[2] >= 0.0).then_some((a, b))
                }
            }
            Side::BackTrans => {
                if a[2] > 0.0 {
                    (b[2] <= 0.0).then_some((b, a))
                } else {
                    (b[2] >= 0.0).then_some((a, b))
                }
            }
        }
    }

    /// The leaf for the pair `(a, b)` in Radiance's tree-query order.
    fn query(&self, a: [f64; 3], b: [f64; 3]) -> Option<Leaf> {
        Some(self.locate(a, b)?.1)
    }

    /// Tree position and leaf of the pair `(a, b)` in Radiance's tree-query order.
    fn locate(&self, a: [f64; 3], b: [f64; 3]) -> Option<([f64; 4], Leaf)> {
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
    fn position(&self, i: [f64; 3], o: [f64; 3]) -> [f64; 4] {
        let mut pos = [0.0; 4];
        if self.rank == 3 {
            let theta = -(-i[1]).atan2(-i[0]);
            let r = spin_z(o, theta);
            pos[0] = (0.5 - FTINY) - 0.5 * (i[0] * i[0] + i[1] * i[1]).sqrt();
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

    /// The tree's BSDF value for the pair as Radiance returns it (float, with its
    /// position-dependent factor).
    /// The tree's BSDF coefficients for the pair as Radiance returns them: one (grey) or three
    /// (Sharp RGB weighted by the primaries' luminances, from the value and the u′, v′ trees).
    fn coefs(&self, a: [f64; 3], b: [f64; 3]) -> Option<([f32; 3], usize)> {
        let (pos, leaf) = self.locate(a, b)?;
        let mut d = 0.0;
        for i in (0..self.rank).rev() {
            let x = f64::from(2u32 << i) / (leaf.corner[i] + 0.01687);
            d += x - x.trunc() - 0.5;
        }
        let y = (f64::from(leaf.value) * (1.0 + 1e-4 * d)) as f32;
        let (Some(u), Some(v)) = (&self.u, &self.v) else {
            return Some(([y, 0.0, 0.0], 1));
        };
        let up = lookup_node(u, self.rank, &pos).value;
        let vp = lookup_node(v, self.rank, &pos).value;
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
    fn split_colour(&mut self) -> Lambertian {
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
                avg_box(u, r, cmin, &cmax),
                avg_box(v, r, cmin, &cmax),
            );
            for c in 0..3 {
                if rgb[c] < min[c] {
                    min[c] = rgb[c];
                }
            }
        });
        let (ymin, cs) = from_sharp(min);
        if ymin >= 0.5e10 || ymin <= 0.01 / PI {
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
                let yval = avg_box(&self.root, r, cmin, &cmax);
                let (um, vm) = if is_u {
                    (f64::from(val), avg_box(v, r, cmin, &cmax))
                } else {
                    (avg_box(u, r, cmin, &cmax), f64::from(val))
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
    fn proj_sa(&self, a: [f64; 3], b: Option<[f64; 3]>) -> Option<f64> {
        match b {
            Some(b) => {
                let e = self.query(a, b)?.edge;
                Some(e * (e * PI))
            }
            None => {
                if self.rank != 4 {
                    return None;
                }
                // Radiance's cumulative distribution for incident direction a: a tree used in
                // reverse (light arriving on the other side) slices its outgoing dimensions.
                let front = a[2] > 0.0;
                let reverse = match self.side {
                    Side::FrontRefl => {
                        if !front {
                            return Some(0.0);
                        }
                        false
                    }
                    Side::BackRefl => {
                        if a[2] > 0.0 {
                            return Some(0.0);
                        }
                        false
                    }
                    Side::FrontTrans => a[2] < 0.0,
                    Side::BackTrans => a[2] > 0.0,
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

/// The leaf of `node` (a tree of rank `rank`) at `pos`: value and hypercube, as Radiance's
/// lookup finds it.
fn lookup_node(node: &Node, r: usize, pos: &[f64; 4]) -> Leaf {
    let mut p = *pos;

    let mut corner = [0.0; 4];
    let mut edge = 1.0;
    let mut node = node;
    loop {
        match node {
            Node::Branch(ch) => {
                edge *= 0.5;
                let mut n = 0;
                for i in (0..r).rev() {
                    let s = 2.0 * p[i];
                    let t = usize::from(s >= 1.0);
                    n |= t << i;
                    p[i] = s - t as f64;
                    corner[i] += t as f64 * edge;
                }
                node = &ch[n];
            }
            Node::Grid { log2, values } => {
                if *log2 == 0 {
                    return Leaf {
                        value: values[0],
                        corner,
                        edge,
                    };
                }
                let cells = (1u64 << log2) as f64;
                let top = (1usize << log2) - 1;
                let mut n = 0usize;
                for v in &p[..r] {
                    n = (n << log2) + ((cells * v) as usize).min(top);
                }
                edge /= cells;
                for i in (0..r).rev() {
                    corner[i] += (cells * p[i]).floor().min(top as f64) * edge;
                }
                return Leaf {
                    value: values[n],
                    corner,
                    edge,
                };
            }
        }
    }
}

/// Sharp RGB (single precision) of luminance `y` and CIE (u′, v′), as Radiance converts it.
fn yuv_to_sharp(y: f64, u: f64, v: f64) -> [f32; 3] {
    let df = 1.0 / (6.0 * u - 16.0 * v + 12.0);
    to_sharp(((9.0 * u * df) as f32, (4.0 * v * df) as f32), y)
}

/// Calls `f(value, lower corner, edge)` for every leaf of `node` (lower corner `cmin`, edge
/// `csiz`).
fn visit_leaves(
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
                let mut lo = *cmin;
                for (i, l) in lo.iter_mut().enumerate().take(r) {
                    if n >> i & 1 == 1 {
                        *l += half;
                    }
                }
                visit_leaves(c, r, &lo, half, f);
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

/// Lower corner of cell `k` (dimension 0 slowest) of a grid of `cells` per dimension and cell
/// edge `cell` whose corner is `cmin`.
fn cell_corner(cmin: &[f64; 4], r: usize, cells: usize, cell: f64, k: usize) -> [f64; 4] {
    let mut lo = *cmin;
    for (i, l) in lo.iter_mut().enumerate().take(r) {
        let ci = k / cells.pow((r - 1 - i) as u32) % cells;
        *l += cell * ci as f64;
    }
    lo
}

/// `node` with every leaf value replaced by `f(value, lower corner, edge)`.
fn map_leaves(
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
                let mut lo = *cmin;
                for (i, l) in lo.iter_mut().enumerate().take(r) {
                    if n >> i & 1 == 1 {
                        *l += half;
                    }
                }
                out.push(map_leaves(c, r, &lo, half, f));
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

/// Radiance's average of a tree's leaves over the box `[bmin, bmax)` (overlap-weighted over
/// branches, a plain mean over the grid cells the box touches).
fn avg_box(node: &Node, r: usize, bmin: &[f64; 4], bmax: &[f64; 4]) -> f64 {
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
                    sum += w * avg_box(&ch[n], r, &lo, &hi);
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
            iter_sum(values, r, *log2, &imin[..r], &imax[..r]) / n as f64
        }
    }
}

/// Sum of a grid's values over an index box, in Radiance's order (dimension 0 outermost).
fn iter_sum(va: &[f32], nd: usize, log2: u32, imin: &[usize], imax: &[usize]) -> f64 {
    let skip = 1usize << ((nd - 1) as u32 * log2);
    let mut sum = 0.0;
    if skip == 1 {
        for &v in &va[imin[0]..imax[0]] {
            sum += f64::from(v);
        }
    } else {
        for i in imin[0]..imax[0] {
            sum += iter_sum(&va[i * skip..], nd - 1, log2, &imin[1..], &imax[1..]);
        }
    }
    sum
}

/// Rotation about z by `theta` (Radiance's `spinvector` with the z axis).
fn spin_z(v: [f64; 3], theta: f64) -> [f64; 3] {
    if theta == 0.0 {
        return v;
    }
    let (s, c) = theta.sin_cos();
    [v[0] * c - v[1] * s, v[1] * c + v[0] * s, v[2]]
}

/// Shirley–Chiu disk → square, as Radiance computes it.
fn disk_to_square(x: f64, y: f64) -> (f64, f64) {
    crate::tree::disk_to_square(x, y)
}

/// Shirley–Chiu square → disk, as Radiance computes it.
fn square_to_disk(u: f64, v: f64) -> (f64, f64) {
    let a = 2.0 * u - 1.0;
    let b = 2.0 * v - 1.0;
    let (r, phi) = if a > -b {
        if a > b {
            (a, FRAC_PI_4 * (b / a))
        } else {
            (b, FRAC_PI_4 * (2.0 - a / b))
        }
    } else if a < b {
        (-a, FRAC_PI_4 * (4.0 + b / a))
    } else {
        (
            -b,
            if b != 0.0 {
                FRAC_PI_4 * (6.0 - a / b)
            } else {
                0.0
            },
        )
    };
    let r = r * 0.9999999999999;
    (r * phi.cos(), r * phi.sin())
}

/// The loaded file as far as the reciprocity check needs it.
struct Loaded {
    rank: usize,
    /// Radiance's rf, rb, tf, tb.
    rf: Option<Tree>,
    rb: Option<Tree>,
    tf: Option<Tree>,
    tb: Option<Tree>,
    /// Lambertian parts (hemispherical fractions): rf, rb, tf, tb sides.
    r_lamb_front: f64,
    r_lamb_back: f64,
    t_lamb_front: f64,
    t_lamb_back: f64,
}

/// Outcome of one row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SampledRow {
    /// min, mean, max over the sampled pairs.
    Values(Reciprocity),
    /// No component (Radiance prints `0 0 0`).
    Absent,
    /// Radiance stops the row without printing it (a sample fell on the disk's rim).
    Dropped,
    /// A sampled pair met a colour leaf without a chromaticity (its value is NaN; Radiance
    /// prints NaN): reported as an error.
    NoColour,
}

struct Stats {
    lo: f64,
    hi: f64,
    sum: f64,
    n: u64,
    /// A pair without a value (a colour leaf without chromaticity).
    nan: bool,
}

impl Loaded {
    /// Total BSDF (Y, sr⁻¹) for light arriving from `inc` and leaving towards `out`.
    fn eval(&self, out: [f64; 3], inc: [f64; 3]) -> f64 {
        let (fi, fo) = (inc[2] > 0.0, out[2] > 0.0);
        let (lamb, tree) = if fi && fo {
            (self.r_lamb_front, self.rf.as_ref())
        } else if !fi && !fo {
            (self.r_lamb_back, self.rb.as_ref())
        } else if fi {
            (self.t_lamb_front, self.tf.as_ref().or(self.tb.as_ref()))
        } else {
            (self.t_lamb_back, self.tb.as_ref().or(self.tf.as_ref()))
        };
        let mut y = lamb * (1.0 / PI);
        if let Some((c, n)) = tree.and_then(|t| t.coefs(out, inc)) {
            for v in c[..n].iter().rev() {
                y += f64::from(*v);
            }
        }
        y
    }

    /// Radiance's smallest projected solid angle for sample `v1` (and `v2`); `None` when a
    /// tree refuses the pair (Radiance reports an internal error and stops the row).
    fn size(&self, v1: [f64; 3], v2: Option<[f64; 3]>) -> Option<f64> {
        let front = v1[2] > 0.0;
        let (mut r, mut t) = if front {
            (self.rf.as_ref(), self.tf.as_ref().or(self.tb.as_ref()))
        } else {
            (self.rb.as_ref(), self.tb.as_ref().or(self.tf.as_ref()))
        };
        if let Some(v2) = v2 {
            if front != (v2[2] > 0.0) {
                r = None;
            } else {
                t = None;
            }
        }
        let mut psa: f64 = 10.0;
        let mut any = false;
        for tree in [r, t].into_iter().flatten() {
            let p = tree.proj_sa(v1, v2)?;
            any = true;
            if p > 0.0 && p < psa {
                psa = p;
            }
        }
        Some(if any { psa } else { PI })
    }

    /// One quadtree over a hemisphere (`side` ±1) with first direction `v0`, calling `cf` for
    /// every accepted sample; `false` stops everything (as Radiance's `&&` chain does).
    fn quadtree(
        &self,
        rng: &mut Drand48,
        cell: (f64, f64, f64),
        side: f64,
        v0: Option<[f64; 3]>,
        cf: &mut dyn FnMut(&Self, &mut Drand48, [f64; 3]) -> bool,
    ) -> bool {
        let (x, y, siz) = cell;
        if siz < 0.124 {
            // Radiance's build evaluates the two arguments right to left: y draws first.
            let ry = rng.next_f64();
            let rx = rng.next_f64();
            let (dx, dy) = square_to_disk(x + rx * siz, y + ry * siz);
            let z = 1.0 - dx * dx - dy * dy;
            if z <= 0.0 {
                return false;
            }
            let v = [dx, dy, side * z.sqrt()];
            let Some(sa) = self.size(v, v0) else {
                return false;
            };
            if sa >= PI * siz * siz - FTINY {
                return cf(self, rng, v);
            }
        }
        let h = siz * 0.5;
        self.quadtree(rng, (x, y, h), side, v0, cf)
            && self.quadtree(rng, (x + h, y, h), side, v0, cf)
            && self.quadtree(rng, (x, y + h, h), side, v0, cf)
            && self.quadtree(rng, (x + h, y + h, h), side, v0, cf)
    }

    fn pair(&self, st: &mut Stats, v1: [f64; 3], v0: [f64; 3]) {
        let other = self.eval(v0, v1);
        let y = self.eval(v1, v0);
        let e = if y > other {
            (y - other) / (y + FTINY)
        } else {
            (other - y) / (other + FTINY)
        };
        st.nan |= e.is_nan();
        st.lo = st.lo.min(e);
        st.hi = st.hi.max(e);
        st.sum += e;
        st.n += 1;
    }

    fn row(&self, rng: &mut Drand48, side1: f64, side2: f64) -> SampledRow {
        let df = if side1 == side2 {
            if side1 > 0.0 {
                self.rf.as_ref()
            } else {
                self.rb.as_ref()
            }
        } else if self.tf.is_none() || self.tb.is_none() {
            None
        } else {
            self.tf.as_ref()
        };
        let Some(df) = df else {
            return SampledRow::Absent;
        };
        let mut st = Stats {
            lo: 1e10,
            hi: -1e10,
            sum: 0.0,
            n: 0,
            nan: false,
        };
        let ok = if self.rank == 3 {
            let w = df.smallest_leaf();
            let step = ((PI * w * w) / PI).sqrt();
            let mut x = 0.5 * step;
            let mut ok = true;
            while x < 1.0 {
                let vin = [x, 0.0, side1 * (1.0 - x * x).sqrt()];
                let mut cf = |l: &Self, _: &mut Drand48, v: [f64; 3]| {
                    l.pair(&mut st, v, vin);
                    true
                };
                if !self.quadtree(rng, (0.0, 0.0, 1.0), side2, Some(vin), &mut cf) {
                    ok = false;
                    break;
                }
                x += step;
            }
            ok
        } else {
            let reflect = side1 == side2;
            let mut outer = |l: &Self, rng: &mut Drand48, v1: [f64; 3]| {
                let below = v1[2] < 0.0;
                let side = if reflect == below { -1.0 } else { 1.0 };
                let mut cf = |l: &Self, _: &mut Drand48, v: [f64; 3]| {
                    l.pair(&mut st, v, v1);
                    true
                };
                l.quadtree(rng, (0.0, 0.0, 1.0), side, Some(v1), &mut cf)
            };
            self.quadtree(rng, (0.0, 0.0, 1.0), side1, None, &mut outer)
        };
        if !ok {
            return SampledRow::Dropped;
        }
        if st.nan {
            return SampledRow::NoColour;
        }
        if st.n == 0 {
            return SampledRow::Absent;
        }
        SampledRow::Values(Reciprocity {
            min: st.lo,
            mean: st.sum / st.n as f64,
            max: st.hi,
        })
    }
}

/// Parses one `ScatteringData` tree as Radiance loads it (negative values read as 0).
fn parse_tree(rank: usize, text: &str) -> Result<Node, String> {
    let s = text.as_bytes();
    let mut i = 0usize;
    fn skip(s: &[u8], i: &mut usize) {
        while *i < s.len() && (s[*i].is_ascii_whitespace() || s[*i] == b',') {
            *i += 1;
        }
    }
    fn node(s: &[u8], i: &mut usize, rank: usize) -> Result<Node, String> {
        skip(s, i);
        if s.get(*i) != Some(&b'{') {
            return Err(format!("expected '{{' at byte {i}"));
        }
        *i += 1;
        skip(s, i);
        if s.get(*i) == Some(&b'{') {
            let mut ch = Vec::with_capacity(1 << rank);
            for _ in 0..1 << rank {
                ch.push(node(s, i, rank)?);
            }
            skip(s, i);
            if s.get(*i) != Some(&b'}') {
                return Err(format!("expected '}}' at byte {i}"));
            }
            *i += 1;
            return Ok(Node::Branch(ch));
        }
        let mut values = Vec::new();
        loop {
            skip(s, i);
            match s.get(*i) {
                Some(b'}') => {
                    *i += 1;
                    break;
                }
                None => return Err("unexpected end of tree data".into()),
                _ => {}
            }
            let start = *i;
            while *i < s.len()
                && !matches!(s[*i], b'}' | b'{' | b',')
                && !s[*i].is_ascii_whitespace()
            {
                *i += 1;
            }
            let tok = std::str::from_utf8(&s[start..*i]).unwrap_or("?");
            let v: f64 = tok
                .parse()
                .map_err(|_| format!("bad number '{tok}' at byte {start}"))?;
            values.push((v as f32).max(0.0));
        }
        let mut log2 = 0u32;
        let mut k = 1usize;
        while k < values.len() {
            k <<= rank;
            log2 += 1;
        }
        if k != values.len() {
            return Err(format!(
                "illegal value count {} in a tree leaf",
                values.len()
            ));
        }
        Ok(Node::Grid { log2, values })
    }
    let root = node(s, &mut i, rank)?;
    skip(s, &mut i);
    if i < s.len() {
        return Err(format!("extra characters after the tree at byte {i}"));
    }
    Ok(root)
}

/// A Lambertian part split off on loading: CIE Y and XYZ as hemispherical fractions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lambertian {
    /// π × the Y value split off.
    pub y: f64,
    /// CIE X, Y, Z (grey: all equal to `y`).
    pub xyz: [f64; 3],
}

/// A tensor-tree file as Radiance's BSDF library holds it after loading: the `Visible` trees
/// (and CIE-u/v trees of coloured components) of Radiance's rf, rb, tf, tb (XML
/// `Reflection Back`, `Reflection Front`, `Transmission Back`, `Transmission Front`) with their
/// Lambertian parts split off.
pub struct TreeFile {
    rank: usize,
    trees: [Option<Tree>; 4],
    lamb: [Lambertian; 4],
    max_hemi: [Option<f64>; 4],
    /// Per component: (directional total at normal incidence, total for diffuse incidence,
    /// smallest leaf), from the tree before its Lambertian part was split off.
    totals: [Option<(f64, f64, f64)>; 4],
}

impl TreeFile {
    /// Loads the trees of a tensor-tree BSDF file's text; `Ok(None)` for other files.
    pub fn load(xml: &str) -> Result<Option<TreeFile>, String> {
        let root = crate::dom::parse(xml).map_err(|(m, p)| format!("{m} (byte {p})"))?;
        let Some(layer) = root.child("Optical").and_then(|o| o.child("Layer")) else {
            return Ok(None);
        };
        let rank = match layer
            .child("DataDefinition")
            .and_then(|d| d.child_text("IncidentDataStructure"))
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("tensortree3") => 3,
            Some("tensortree4") => 4,
            _ => return Ok(None),
        };
        // Per component (rf, rb, tf, tb): Visible, CIE-u, CIE-v trees.
        let mut nodes: [[Option<Node>; 3]; 4] = Default::default();
        for wd in layer.children_named("WavelengthData") {
            let wl = wd
                .child_text("Wavelength")
                .unwrap_or("")
                .to_ascii_lowercase();
            let ct = match wl.as_str() {
                "visible" => 0,
                "cie-u" => 1,
                "cie-v" => 2,
                _ => continue,
            };
            for blk in wd.children_named("WavelengthDataBlock") {
                let Some(d) = blk
                    .child_text("WavelengthDataDirection")
                    .and_then(Direction::parse)
                else {
                    continue;
                };
                let text = blk.child("ScatteringData").map_or("", |e| e.text.as_str());
                let node = parse_tree(rank, text).map_err(|e| format!("{}: {e}", d.xml_name()))?;
                nodes[slot(d)][ct] = Some(node);
            }
        }
        let sides = [
            Side::FrontRefl,
            Side::BackRefl,
            Side::FrontTrans,
            Side::BackTrans,
        ];
        let mut k = 0;
        let mut trees = nodes.map(|[y, u, v]| {
            let side = sides[k];
            k += 1;
            y.map(|root| Tree {
                rank,
                side,
                root,
                u,
                v,
                memo: Memo::default(),
            })
        });
        let none = Lambertian {
            y: 0.0,
            xyz: [0.0; 3],
        };
        let max_hemi = std::array::from_fn(|k| trees[k].as_ref().map(Tree::max_hemi));
        let totals = std::array::from_fn(|k| {
            trees[k]
                .as_ref()
                .map(|t| (t.normal_total(), t.diffuse_total(), t.smallest_leaf()))
        });
        let mut lamb = [none; 4];
        for (t, l) in trees.iter_mut().zip(lamb.iter_mut()) {
            if let Some(t) = t {
                *l = if t.u.is_some() && t.v.is_some() {
                    t.split_colour()
                } else {
                    let y = t.split_lambertian();
                    Lambertian { y, xyz: [y; 3] }
                };
            }
        }
        // One Lambertian transmission copied to the side without a tree.
        match (trees[2].is_some(), trees[3].is_some()) {
            (false, true) => lamb[2] = lamb[3],
            (true, false) => lamb[3] = lamb[2],
            _ => {}
        }
        Ok(Some(TreeFile {
            rank,
            trees,
            lamb,
            max_hemi,
            totals,
        }))
    }

    /// The Lambertian parts split off XML `Reflection Back`, `Reflection Front`,
    /// `Transmission Back`, `Transmission Front` (a missing transmission shows the other's).
    pub fn lambertians(&self) -> [Lambertian; 4] {
        self.lamb
    }

    /// Radiance's largest directional-hemispherical total of XML `Reflection Back`,
    /// `Reflection Front`, `Transmission Back`, `Transmission Front` (Lambertian part included):
    /// π × the largest mean of the tree over incident strips of the smallest leaf's width, at
    /// least 1/32 (rank 3: strips of the reachable half; rank 4: squares).
    pub fn max_totals(&self) -> [Option<f64>; 4] {
        self.max_hemi
    }

    /// The component table of XML `Reflection Back`, `Reflection Front`, `Transmission Back`,
    /// `Transmission Front` (index 0…3; `None` without that tree): Radiance's Lambertian part,
    /// largest directional total and angle, plus fenestra's totals for normal and diffuse
    /// incidence (integrated leaf by leaf: exact for the nearest-leaf tree; `totals` is left
    /// empty).
    pub fn component(&self, k: usize) -> Option<crate::check::ComponentCheck> {
        let (normal_total, diffuse_total, leaf) = self.totals[k]?;
        let l = self.lamb[k];
        Some(crate::check::ComponentCheck {
            lambertian_xyz: l.xyz,
            lambertian_y: l.y / PI,
            max_total: self.max_hemi[k]?,
            min_angle_deg: ((PI * leaf * leaf) / PI).sqrt() * (360.0 / PI),
            normal_total,
            diffuse_total,
            totals: Vec::new(),
        })
    }

    /// Whether a component has colour trees (CIE-u/v).
    pub fn has_colour(&self) -> bool {
        self.trees
            .iter()
            .flatten()
            .any(|t| t.u.is_some() || t.v.is_some())
    }

    /// Radiance's `Color:` flag: the u′ tree of the first component kept among XML
    /// `Transmission Front`, `Transmission Back`, `Reflection Back`, `Reflection Front` (see
    /// [`TreeFile::rows`] for `max_totals`).
    pub fn colour_flag(&self, max_totals: [Option<f64>; 4]) -> bool {
        [3, 2, 0, 1]
            .into_iter()
            .find(|&k| self.kept(k, &max_totals))
            .and_then(|k| self.trees[k].as_ref())
            .is_some_and(|t| t.u.is_some())
    }

    fn kept(&self, k: usize, max_totals: &[Option<f64>; 4]) -> bool {
        self.trees[k].is_some() && max_totals[k].is_some_and(|m| m - self.lamb[k].y > 0.001)
    }

    /// Radiance's three reciprocity rows (Interior Refl, Exterior Refl, Transmission), drawing
    /// from `rng`. `max_totals`: the largest directional totals of XML `Reflection Back`,
    /// `Reflection Front`, `Transmission Back`, `Transmission Front` as the component table gives
    /// them (Radiance drops a component with at most 0.001 left after its Lambertian part).
    pub fn rows(self, max_totals: [Option<f64>; 4], rng: &mut Drand48) -> [SampledRow; 3] {
        let keep: [bool; 4] = std::array::from_fn(|k| self.kept(k, &max_totals));
        let [rf, rb, tf, tb] = self.trees;
        let pick = |t: Option<Tree>, k: usize| t.filter(|_| keep[k]);
        let loaded = Loaded {
            rank: self.rank,
            rf: pick(rf, 0),
            rb: pick(rb, 1),
            tf: pick(tf, 2),
            tb: pick(tb, 3),
            r_lamb_front: self.lamb[0].y,
            r_lamb_back: self.lamb[1].y,
            t_lamb_front: self.lamb[2].y,
            t_lamb_back: self.lamb[3].y,
        };
        [
            loaded.row(rng, 1.0, 1.0),
            loaded.row(rng, -1.0, -1.0),
            loaded.row(rng, -1.0, 1.0),
        ]
    }
}

/// Index of an XML direction in Radiance's rf, rb, tf, tb order.
fn slot(d: Direction) -> usize {
    match d {
        Direction::ReflectionBack => 0,
        Direction::ReflectionFront => 1,
        Direction::TransmissionBack => 2,
        Direction::TransmissionFront => 3,
    }
}

/// [`TreeFile::load`] then [`TreeFile::rows`]: `Ok(None)` for files that are not tensor trees.
pub fn tree_rows(
    xml: &str,
    max_totals: [Option<f64>; 4],
    rng: &mut Drand48,
) -> Result<Option<[SampledRow; 3]>, String> {
    Ok(TreeFile::load(xml)?.map(|f| f.rows(max_totals, rng)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rank-3 grey file holding one `Reflection Back` tree.
    fn refl_file(tree: &str) -> String {
        format!(
            "<WindowElement><Optical><Layer><DataDefinition>\
             <IncidentDataStructure>TensorTree3</IncidentDataStructure></DataDefinition>\
             <WavelengthData><Wavelength>Visible</Wavelength><WavelengthDataBlock>\
             <WavelengthDataDirection>Reflection Back</WavelengthDataDirection>\
             <ScatteringData>{tree}</ScatteringData></WavelengthDataBlock></WavelengthData>\
             </Layer></Optical></WindowElement>"
        )
    }

    fn rows(xml: &str, rng: &mut Drand48) -> [SampledRow; 3] {
        let b = crate::read::parse(xml, "test.xml").unwrap();
        let totals = [
            Direction::ReflectionBack,
            Direction::ReflectionFront,
            Direction::TransmissionBack,
            Direction::TransmissionFront,
        ]
        .map(|d| crate::check::tree_component(&b, d).map(|c| c.max_total));
        tree_rows(xml, totals, rng).unwrap().unwrap()
    }

    /// Draws per first direction: 256 cells of 1/16 with one point each, and where leaves are
    /// smaller each cell's point is dropped and its four quarters draw again.
    #[test]
    fn draw_counts_follow_leaf_size() {
        // Constant rank-3 tree of 2 cells per side: radii 0.25 and 0.75, 256 points each.
        let xml = refl_file("{ 1 1 1 1 1 1 1 1 }");
        let mut rng = Drand48::new();
        let r = rows(&xml, &mut rng);
        let mut want = Drand48::new();
        for _ in 0..2 * 256 * 2 {
            want.next_f64();
        }
        assert_eq!(rng.next_f64(), want.next_f64());
        // A constant tree is reciprocal: every pair 0 (Radiance's factor 1 + 1e-4·d is the
        // same for a pair and its reverse only when they share a leaf, so not exactly 0).
        match r[0] {
            SampledRow::Values(v) => assert!(v.max < 3e-4 && v.min >= 0.0, "{v:?}"),
            other => panic!("{other:?}"),
        }
        assert_eq!(r[1], SampledRow::Absent);
        assert_eq!(r[2], SampledRow::Absent);
        // 32 cells per side (leaves of 1/32): 32 radii, each 256 points dropped and 1024 kept.
        let vals = vec!["1"; 1 << 15].join(" ");
        let xml = refl_file(&format!("{{ {vals} }}"));
        let mut rng = Drand48::new();
        rows(&xml, &mut rng);
        let mut want = Drand48::new();
        for _ in 0..32 * (256 + 1024) * 2 {
            want.next_f64();
        }
        assert_eq!(rng.next_f64(), want.next_f64());
    }

    #[test]
    fn lambertian_split_and_lookup_cube() {
        let node = parse_tree(
            3,
            "{ {1} {2} {3} {4} {0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8} {6} {7} {8} }",
        )
        .unwrap();
        let mut t = Tree {
            rank: 3,
            side: Side::FrontRefl,
            root: node,
            u: None,
            v: None,
            memo: Memo::default(),
        };
        // Only children 0, 2, 4, 6 (lower half of dimension 0) count: minimum 0.1, subtracted
        // in float.
        assert_eq!(t.lambertian_min(), 0.1);
        assert_eq!(t.split_lambertian(), PI * f64::from(0.1f32));
        // Child 4 (dimension 2 upper), its grid cell (1, 0, 1) = value 5.
        let leaf = t.lookup(&[0.3, 0.2, 0.8, 0.0]);
        assert_eq!(leaf.value, 0.6f32 - 0.1f32);
        assert_eq!(leaf.corner, [0.25, 0.0, 0.75, 0.0]);
        assert_eq!(leaf.edge, 0.25);
        assert_eq!(t.smallest_leaf(), 0.25);
        assert!(parse_tree(3, "{ 1 2 3 }").is_err());
        assert!(parse_tree(3, "{ 1 } x").is_err());
    }
}

#[cfg(test)]
mod table_tests {
    use super::*;

    /// The leaf-by-leaf totals equal the finest-grid integration of [`crate::check::tree_component`]
    /// (to rounding) on genBSDF's rank-3 and rank-4 blinds.
    #[test]
    fn leafwise_totals_match_grid_integration() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/fixtures/dctimestep");
        for f in ["blinds_t3.xml", "blinds_t4.xml"] {
            let p = dir.join(f);
            let xml = std::fs::read_to_string(&p).unwrap();
            let b = crate::read::parse(&xml, f).unwrap();
            let t = TreeFile::load(&xml).unwrap().unwrap();
            let dirs = [
                Direction::ReflectionBack,
                Direction::ReflectionFront,
                Direction::TransmissionBack,
                Direction::TransmissionFront,
            ];
            for (k, d) in dirs.into_iter().enumerate() {
                let (Some(grid), Some(leaf)) =
                    (crate::check::tree_component(&b, d), t.component(k))
                else {
                    assert!(t.component(k).is_none(), "{f} {d:?}");
                    continue;
                };
                for (a, g) in [
                    (leaf.normal_total, grid.normal_total),
                    (leaf.diffuse_total, grid.diffuse_total),
                    (leaf.min_angle_deg, grid.min_angle_deg),
                ] {
                    assert!(
                        (a - g).abs() < 1e-9 * g.abs().max(1.0),
                        "{f} {d:?}: {a} vs {g}"
                    );
                }
                // Radiance's strip means and the finest-grid totals agree on these trees
                // (strips of the finest cell).
                assert!((leaf.max_total - grid.max_total).abs() < 1e-6, "{f} {d:?}");
            }
        }
    }
}
