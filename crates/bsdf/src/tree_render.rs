//! Tensor-tree BSDFs for rendering (grey, the `Visible` trees): values at the nearest leaf
//! with Radiance's position factor, after the Lambertian parts Radiance's loader splits
//! off (`tree_load`), and the outgoing distribution of a view (the tree's slice at the
//! view's incident position) for hemispherical totals and importance sampling. Local
//! frame as Radiance's: +Z is the normal side (the XML back, interior); directions point
//! away from the surface; the view vector takes the place of the incident one
//! (reciprocity), as Radiance's renderer queries BSDFs.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

use crate::check::sampled::TreeFile;
use crate::model::Bsdf;
use crate::tree::{disk_to_square, leaf_at, smallest_leaf_edge, square_to_disk, Node};
use crate::tree_load::{cell_corner, child_corner, leaf_value, orient, position, spin_z, Side};

/// A lobe of a BSDF seen from one side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lobe {
    /// Light returned to the view's side.
    Reflection,
    /// Light passed to the other side.
    Transmission,
}

/// One component's grey tree.
#[derive(Debug)]
struct Comp {
    rank: usize,
    side: Side,
    root: Node,
    /// Edge of the smallest leaf: views in the same cell of this size share a slice.
    finest: f64,
    /// CIE u′ and v′ trees of a coloured component (same rank and coordinates as `root`).
    uv: Option<(Node, Node)>,
}

impl Comp {
    /// RGB per unit luminance at tree position `pos` (ones for a grey component).
    fn colour_at(&self, pos: &[f64; 4]) -> [f64; 3] {
        match &self.uv {
            Some((u, v)) => {
                let up = f64::from(leaf_at(u, self.rank, pos).value);
                let vp = f64::from(leaf_at(v, self.rank, pos).value);
                uv_rgb(up, vp)
            }
            None => [1.0; 3],
        }
    }
}

/// RGB (the renderer's primaries) of CIE (u′, v′) at unit luminance, desaturated into the
/// gamut as the Klems colours are; grey for a degenerate chromaticity.
fn uv_rgb(u: f64, v: f64) -> [f64; 3] {
    let d = 6.0 * u - 16.0 * v + 12.0;
    if !(d.is_finite() && d > 0.0 && v > 0.0) {
        return [1.0; 3];
    }
    let (x, y) = (9.0 * u / d, 4.0 * v / d);
    if y <= 0.0 {
        return [1.0; 3];
    }
    let xyz = [x / y, 1.0, (1.0 - x - y) / y];
    // the matrix once per process, not per leaf looked up (the same numbers)
    static M: std::sync::OnceLock<[[f64; 3]; 3]> = std::sync::OnceLock::new();
    let m = M.get_or_init(crate::radiance::xyz_to_rgb_matrix);
    let rgb = [0, 1, 2].map(|r| m[r][0] * xyz[0] + m[r][1] * xyz[1] + m[r][2] * xyz[2]);
    crate::radiance::clip_gamut(rgb, 1.0)
}

/// The leaves of one slice: (cumulative weight, lower corner in the free dimensions, edge),
/// and the projected solid angle of the smallest.
#[derive(Debug, Default)]
struct Cells {
    leaves: Vec<(f64, [f64; 2], f64)>,
    smallest: f64,
    /// Σ weight × RGB per unit luminance over the leaves (the coloured total).
    rgb: [f64; 3],
}

/// A slice's cache key: component, whether it is used in its own direction, incident cell.
pub type SliceKey = (usize, bool, u32, u32);

/// Most slices kept per BSDF (each a few kilobytes): memory stays bounded whatever the
/// tree's resolution; slices past the limit are computed each time.
const MAX_CACHED: usize = 1 << 14;

/// A tensor-tree BSDF ready for rendering.
#[derive(Debug)]
pub struct TreeBsdf {
    /// Indexed like the sides: interior reflection, exterior reflection, interior to
    /// exterior transmission, exterior to interior transmission.
    comps: [Option<Comp>; 4],
    /// Hemispherical Lambertian part (π × the value split off) per component.
    lamb: [f64; 4],
    /// The same in RGB.
    lamb_rgb: [[f64; 3]; 4],
    /// Slices already computed, by component, direction of use and incident cell.
    cache: Mutex<HashMap<SliceKey, Arc<Cells>>>,
}

/// The components a view on the front (+Z) or back side uses for `lobe`: the preferred one
/// and, for transmission, the other side's tree through reciprocity.
fn candidates(lobe: Lobe, front: bool) -> &'static [usize] {
    match (lobe, front) {
        (Lobe::Reflection, true) => &[0],
        (Lobe::Reflection, false) => &[1],
        (Lobe::Transmission, true) => &[2, 3],
        (Lobe::Transmission, false) => &[3, 2],
    }
}

impl TreeBsdf {
    /// The tensor trees of a read file (`None` for a Klems file).
    pub fn load(b: &Bsdf) -> Option<TreeBsdf> {
        let f = TreeFile::load(b)?;
        let lamb = std::array::from_fn(|k| f.lamb[k].y);
        let m = crate::radiance::xyz_to_rgb_matrix();
        let lamb_rgb = std::array::from_fn(|k| {
            let (xyz, y) = (f.lamb[k].xyz, f.lamb[k].y);
            let rgb = [0, 1, 2].map(|r| m[r][0] * xyz[0] + m[r][1] * xyz[1] + m[r][2] * xyz[2]);
            crate::radiance::clip_gamut(rgb, y)
        });
        let comps = f.trees.map(|t| {
            t.map(|t| Comp {
                rank: t.rank,
                side: t.side,
                finest: smallest_leaf_edge(&t.root),
                uv: t.u.zip(t.v),
                root: t.root,
            })
        });
        Some(TreeBsdf {
            comps,
            lamb,
            lamb_rgb,
            cache: Mutex::new(HashMap::new()),
        })
    }

    /// The hemispherical Lambertian part of `lobe` for a view on the front or back side.
    pub fn lambertian(&self, lobe: Lobe, front: bool) -> f64 {
        self.lamb[candidates(lobe, front)[0]]
    }

    /// [`TreeBsdf::lambertian`] in RGB (the Lambertian part's own colour).
    pub fn lambertian_rgb(&self, lobe: Lobe, front: bool) -> [f64; 3] {
        self.lamb_rgb[candidates(lobe, front)[0]]
    }

    /// Colour (RGB per unit luminance) of the leaf holding view `v` and light `l`: from the
    /// component's u′, v′ trees, ones for a grey component.
    pub fn colour(&self, lobe: Lobe, front: bool, v: [f64; 3], l: [f64; 3]) -> [f64; 3] {
        for &k in candidates(lobe, front) {
            let Some(c) = &self.comps[k] else { continue };
            if let Some((i, o)) = orient(c.side, v, l) {
                if c.uv.is_none() {
                    // a grey component: no tree position to work out
                    return [1.0; 3];
                }
                return c.colour_at(&position(c.rank, i, o));
            }
        }
        [1.0; 3]
    }

    /// Whether the lobe has a tree (its own or, for transmission, the other side's).
    pub fn has(&self, lobe: Lobe, front: bool) -> bool {
        candidates(lobe, front)
            .iter()
            .any(|&k| self.comps[k].is_some())
    }

    /// Projected solid angle of the smallest leaf of the tree `lobe` uses (Radiance's
    /// `minProjSA`), 0 without one.
    pub fn min_size(&self, lobe: Lobe, front: bool) -> f64 {
        candidates(lobe, front)
            .iter()
            .find_map(|&k| self.comps[k].as_ref())
            .map_or(0.0, |c| PI * c.finest * c.finest)
    }

    /// BSDF value (sr⁻¹, Lambertian part removed) for view `v` and light `l`, and the
    /// projected solid angle of the leaf holding the pair.
    pub fn eval(&self, lobe: Lobe, front: bool, v: [f64; 3], l: [f64; 3]) -> (f64, f64) {
        for &k in candidates(lobe, front) {
            let Some(c) = &self.comps[k] else { continue };
            if let Some((i, o)) = orient(c.side, v, l) {
                let leaf = leaf_at(&c.root, c.rank, &position(c.rank, i, o));
                let value = f64::from(leaf_value(c.rank, &leaf)).max(0.0);
                return (value, PI * leaf.edge * leaf.edge);
            }
        }
        (0.0, 0.0)
    }

    /// The distribution of `lobe` for view `v`: every leaf of the tree's slice at the
    /// view's position, with its share of the hemispherical total.
    pub fn slice(&self, lobe: Lobe, front: bool, v: [f64; 3]) -> Option<Slice> {
        let &k = candidates(lobe, front)
            .iter()
            .find(|&&k| self.comps[k].is_some())?;
        let c = self.comps[k].as_ref()?;
        let own = k == candidates(lobe, front)[0];
        // outgoing side of the tree's own orientation: interior (+Z) for interior
        // reflection and exterior-to-interior transmission
        let out_sign = match c.side {
            Side::IntRefl | Side::ExtInt => 1.0,
            Side::ExtRefl | Side::IntExt => -1.0,
        };
        let mut s = Slice {
            cells: Arc::new(Cells::default()),
            total: 0.0,
            rank: c.rank,
            theta: 0.0,
            reverse: !own,
            sign: if own { out_sign } else { -out_sign },
            key: (k, own, 0, 0),
        };
        let mut fixed = [0.0; 4];
        let mask: u32;
        if c.rank == 4 {
            if own {
                let (u, w) = disk_to_square(-v[0], -v[1]);
                fixed[0] = u;
                fixed[1] = w;
                mask = 0b0011;
            } else {
                let (u, w) = disk_to_square(v[0], v[1]);
                fixed[2] = u;
                fixed[3] = w;
                mask = 0b1100;
            }
        } else {
            if !own {
                return None; // a rank-3 tree used in reverse: not sampled
            }
            s.theta = -(-v[1]).atan2(-v[0]);
            fixed[0] = (0.5 - 1e-6) - 0.5 * (v[0] * v[0] + v[1] * v[1]).sqrt();
            mask = 0b0001;
        }
        // views in the same finest incident cell meet the same leaves
        let fixed_dims: Vec<usize> = (0..c.rank).filter(|i| mask >> i & 1 == 1).collect();
        let q = |x: f64| (x / c.finest).clamp(0.0, f64::from(u32::MAX - 1)) as u32;
        let key = (
            k,
            own,
            q(fixed[fixed_dims[0]]),
            fixed_dims.get(1).map_or(0, |&d| q(fixed[d])),
        );
        s.key = key;
        let cached = self.cache.lock().ok().and_then(|m| m.get(&key).cloned());
        let cells = match cached {
            Some(cells) => cells,
            None => {
                let free: Vec<usize> = (0..c.rank).filter(|i| mask >> i & 1 == 0).collect();
                let mut cells = Cells::default();
                let mut total = 0.0;
                let mut smallest = f64::INFINITY;
                let mut rgb = [0.0; 3];
                slice_leaves(
                    &c.root,
                    c.rank,
                    mask,
                    &fixed,
                    &[0.0; 4],
                    1.0,
                    &mut |val, cmin, edge| {
                        let w = f64::from(val).max(0.0) * PI * edge * edge;
                        if w > 0.0 {
                            total += w;
                            smallest = smallest.min(PI * edge * edge);
                            // the leaf's colour at its centre (the fixed dimensions as given)
                            let mut pos = fixed;
                            for &d in &free {
                                pos[d] = cmin[d] + 0.5 * edge;
                            }
                            let col = c.colour_at(&pos);
                            for (a, b) in rgb.iter_mut().zip(col) {
                                *a += w * b;
                            }
                            cells
                                .leaves
                                .push((total, [cmin[free[0]], cmin[free[1]]], edge));
                        }
                    },
                );
                cells.smallest = if smallest.is_finite() { smallest } else { 0.0 };
                cells.rgb = rgb;
                let cells = Arc::new(cells);
                if let Ok(mut m) = self.cache.lock() {
                    if m.len() < MAX_CACHED {
                        m.insert(key, cells.clone());
                    }
                }
                cells
            }
        };
        s.total = cells.leaves.last().map_or(0.0, |c| c.0);
        s.cells = cells;
        Some(s)
    }
}

/// The leaves of a tree's slice at the coordinates `fixed` in the dimensions of `mask`,
/// each with its value, lower corner and edge.
fn slice_leaves(
    node: &Node,
    rank: usize,
    mask: u32,
    fixed: &[f64; 4],
    cmin: &[f64; 4],
    csiz: f64,
    f: &mut dyn FnMut(f32, &[f64; 4], f64),
) {
    let inside = |lo: &[f64; 4], size: f64| {
        (0..rank).all(|i| {
            mask >> i & 1 == 0
                || (fixed[i] >= lo[i] && (fixed[i] < lo[i] + size || lo[i] + size >= 1.0))
        })
    };
    match node {
        Node::Branch(ch) => {
            let half = 0.5 * csiz;
            for (n, c) in ch.iter().enumerate() {
                let lo = child_corner(cmin, rank, n, half);
                if inside(&lo, half) {
                    slice_leaves(c, rank, mask, fixed, &lo, half, f);
                }
            }
        }
        Node::Grid { log2, values } => {
            let cells = 1usize << log2;
            let cell = csiz / cells as f64;
            for (k, &val) in values.iter().enumerate() {
                let lo = cell_corner(cmin, rank, cells, cell, k);
                if inside(&lo, cell) {
                    f(val, &lo, cell);
                }
            }
        }
    }
}

/// The outgoing distribution of one view (see [`TreeBsdf::slice`]).
#[derive(Debug)]
pub struct Slice {
    /// (cumulative weight, lower corner in the free dimensions, edge) per leaf.
    cells: Arc<Cells>,
    total: f64,
    rank: usize,
    theta: f64,
    reverse: bool,
    sign: f64,
    /// The cache key: views with the same key share this slice.
    key: SliceKey,
}

impl Slice {
    /// Directional-hemispherical total (Σ value · projected solid angle).
    pub fn total(&self) -> f64 {
        self.total
    }

    /// [`Slice::total`] in RGB (each leaf in its colour).
    pub fn total_rgb(&self) -> [f64; 3] {
        self.cells.rgb
    }

    /// Projected solid angle of the smallest leaf of the slice (0 when empty).
    pub fn smallest(&self) -> f64 {
        self.cells.smallest
    }

    /// Spreads the slice over directions: each leaf as a grid of points at most `h` apart in
    /// the unit square (uniform in projected solid angle), each point with its share of the
    /// leaf's value × projected solid angle; `f` receives the direction and the share.
    pub fn spread(&self, h: f64, f: &mut dyn FnMut([f64; 3], f64)) {
        let mut before = 0.0;
        for &(cum, _, edge) in self.cells.leaves.iter() {
            let k = ((edge / h).ceil() as usize).clamp(1, 1024);
            let share = (cum - before) / (k * k) as f64;
            let x = 0.5 * (before + cum) / self.total.max(f64::MIN_POSITIVE);
            before = cum;
            for a in 0..k {
                for b in 0..k {
                    let (u, w) = ((a as f64 + 0.5) / k as f64, (b as f64 + 0.5) / k as f64);
                    if let Some(d) = self.sample(x, u, w) {
                        f(d, share);
                    }
                }
            }
        }
    }

    /// An identity shared by every view whose slice spreads to the same directions (rank-4
    /// trees: views in the same finest cell); `None` for rank 3 (the slice turns with the view).
    pub fn shared_id(&self) -> Option<SliceKey> {
        // the key, not the cells' address: an address can be reused once the cache is
        // full and an uncached slice is freed
        (self.rank == 4).then_some(self.key)
    }

    /// A direction drawn in proportion to value × projected solid angle: `x` picks the
    /// leaf, `u`, `w` the point in it (uniform in projected solid angle).
    pub fn sample(&self, x: f64, u: f64, w: f64) -> Option<[f64; 3]> {
        if self.total <= 0.0 {
            return None;
        }
        let t = x * self.total;
        let leaves = &self.cells.leaves;
        let k = leaves.partition_point(|c| c.0 <= t).min(leaves.len() - 1);
        let (_, lo, edge) = leaves[k];
        let (sx, sy) = square_to_disk(lo[0] + u * edge, lo[1] + w * edge);
        let z = self.sign * (1.0 - sx * sx - sy * sy).max(0.0).sqrt();
        Some(match (self.rank, self.reverse) {
            (4, false) => [sx, sy, z],
            (4, true) => [-sx, -sy, z],
            _ => spin_z([sx, sy, z], -self.theta),
        })
    }
}
