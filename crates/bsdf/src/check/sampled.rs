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
//! loader does (grey: the reachable minimum; coloured: `Tree::split_colour`). The generator is
//! the process's one (the colour dither's): state runs on from file to file.

use std::f64::consts::PI;

use crate::check::{ComponentCheck, Reciprocity};
use crate::model::{BlockData, Bsdf, DataStructure, Direction, Wavelength};
use crate::radiance::Drand48;
use crate::tree::{square_to_disk, Node};
use crate::tree_load::{Memo, Side, Tree, SIDES};

/// The small margin the reproduced arithmetic uses: normal incidence sits this far below the
/// middle of a rank-3 tree's incident coordinate, strip loops stop this short of their end, a
/// cell's solid angle is compared with this much slack, and pair errors divide by the larger
/// value plus this.
const TINY: f64 = 1e-6;

/// The trees the reciprocity rows sample (dropped components left out) and the Lambertian parts
/// (hemispherical fractions), indexed like `SIDES`.
struct Loaded {
    rank: usize,
    trees: [Option<Tree>; 4],
    lamb: [f64; 4],
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
    fn tree(&self, side: Side) -> Option<&Tree> {
        self.trees[side as usize].as_ref()
    }

    /// The transmission tree for light from the interior (`from_interior`) or the exterior; a
    /// file with one transmission tree uses it both ways.
    fn trans(&self, from_interior: bool) -> Option<&Tree> {
        let (a, b) = if from_interior {
            (Side::IntExt, Side::ExtInt)
        } else {
            (Side::ExtInt, Side::IntExt)
        };
        self.tree(a).or(self.tree(b))
    }

    /// Total BSDF (Y, sr⁻¹) for light arriving from `inc` and leaving towards `out`: the
    /// Lambertian part of the component plus the tree's coefficients, added from the last
    /// channel to the first.
    fn eval(&self, out: [f64; 3], inc: [f64; 3]) -> f64 {
        let (fi, fo) = (inc[2] > 0.0, out[2] > 0.0);
        let (side, tree) = if fi && fo {
            (Side::IntRefl, self.tree(Side::IntRefl))
        } else if !fi && !fo {
            (Side::ExtRefl, self.tree(Side::ExtRefl))
        } else if fi {
            (Side::IntExt, self.trans(true))
        } else {
            (Side::ExtInt, self.trans(false))
        };
        let mut y = self.lamb[side as usize] * (1.0 / PI);
        if let Some((c, n)) = tree.and_then(|t| t.coefs(out, inc)) {
            for v in c[..n].iter().rev() {
                y += f64::from(*v);
            }
        }
        y
    }

    /// The smallest projected solid angle the trees give for sample `v1` (with `v2`: the leaf of
    /// the pair in the tree joining them; without: the smallest leaf in the slices of `v1` of the
    /// reflection and transmission trees on its side), π when no tree answers, `None` when a
    /// tree refuses the pair (the reference then stops the row).
    fn size(&self, v1: [f64; 3], v2: Option<[f64; 3]>) -> Option<f64> {
        let interior = v1[2] > 0.0;
        let (mut r, mut t) = if interior {
            (self.tree(Side::IntRefl), self.trans(true))
        } else {
            (self.tree(Side::ExtRefl), self.trans(false))
        };
        if let Some(v2) = v2 {
            if interior != (v2[2] > 0.0) {
                r = None;
            } else {
                t = None;
            }
        }
        let mut smallest: f64 = 10.0;
        let mut any = false;
        for tree in [r, t].into_iter().flatten() {
            let p = tree.solid_angle(v1, v2)?;
            any = true;
            if p > 0.0 && p < smallest {
                smallest = p;
            }
        }
        Some(if any { smallest } else { PI })
    }

    /// One quadtree over a hemisphere (`side` ±1) with first direction `v0`, calling
    /// `on_sample` for every accepted sample. Cells of 1/8 and more split without drawing; a
    /// smaller cell draws a point (y first, then x: the reference's compiler evaluated the two
    /// draws right to left) and keeps it when the trees' leaf there is not smaller than the
    /// cell, else splits; quarters in the order lower-left, lower-right, upper-left,
    /// upper-right. `false` (a point on the rim, a refused pair, or from `on_sample`) stops
    /// the whole walk.
    fn quadtree(
        &self,
        rng: &mut Drand48,
        cell: (f64, f64, f64),
        side: f64,
        v0: Option<[f64; 3]>,
        on_sample: &mut dyn FnMut(&Self, &mut Drand48, [f64; 3]) -> bool,
    ) -> bool {
        let (x, y, siz) = cell;
        if siz < 0.124 {
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
            if sa >= PI * siz * siz - TINY {
                return on_sample(self, rng, v);
            }
        }
        let h = siz * 0.5;
        self.quadtree(rng, (x, y, h), side, v0, on_sample)
            && self.quadtree(rng, (x + h, y, h), side, v0, on_sample)
            && self.quadtree(rng, (x, y + h, h), side, v0, on_sample)
            && self.quadtree(rng, (x + h, y + h, h), side, v0, on_sample)
    }

    /// Adds the error of the pair (`v1` from the quadtree, `v0` the first direction): light
    /// from `v1` to `v0` against light from `v0` to `v1`, relative to the larger.
    fn pair(&self, st: &mut Stats, v1: [f64; 3], v0: [f64; 3]) {
        let other = self.eval(v0, v1);
        let y = self.eval(v1, v0);
        let e = if y > other {
            (y - other) / (y + TINY)
        } else {
            (other - y) / (other + TINY)
        };
        st.nan |= e.is_nan();
        st.lo = st.lo.min(e);
        st.hi = st.hi.max(e);
        st.sum += e;
        st.n += 1;
    }

    /// One row: pairs with the first direction on side `first` (±1: interior, exterior) and the
    /// second on `second`.
    fn row(&self, rng: &mut Drand48, first: f64, second: f64) -> SampledRow {
        let forward = if first == second {
            self.tree(if first > 0.0 {
                Side::IntRefl
            } else {
                Side::ExtRefl
            })
        } else if self.tree(Side::IntExt).is_none() || self.tree(Side::ExtInt).is_none() {
            None
        } else {
            self.tree(Side::IntExt)
        };
        let Some(forward) = forward else {
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
            // The first direction walks radii (k + 1/2)·w along +x, w the forward tree's
            // smallest leaf (taken through its projected solid angle and back).
            let w = forward.smallest_leaf();
            let step = ((PI * w * w) / PI).sqrt();
            let mut x = 0.5 * step;
            let mut ok = true;
            while x < 1.0 {
                let vin = [x, 0.0, first * (1.0 - x * x).sqrt()];
                let mut on_sample = |l: &Self, _: &mut Drand48, v: [f64; 3]| {
                    l.pair(&mut st, v, vin);
                    true
                };
                if !self.quadtree(rng, (0.0, 0.0, 1.0), second, Some(vin), &mut on_sample) {
                    ok = false;
                    break;
                }
                x += step;
            }
            ok
        } else {
            // The first direction from a quadtree of its own, each of its samples running a
            // quadtree for the second.
            let reflect = first == second;
            let mut outer = |l: &Self, rng: &mut Drand48, v1: [f64; 3]| {
                let below = v1[2] < 0.0;
                let side = if reflect == below { -1.0 } else { 1.0 };
                let mut on_sample = |l: &Self, _: &mut Drand48, v: [f64; 3]| {
                    l.pair(&mut st, v, v1);
                    true
                };
                l.quadtree(rng, (0.0, 0.0, 1.0), side, Some(v1), &mut on_sample)
            };
            self.quadtree(rng, (0.0, 0.0, 1.0), first, None, &mut outer)
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

pub use crate::tree_load::Lambertian;

/// A tensor-tree file as the reference loads it: the `Visible` trees (and CIE-u/v trees of
/// coloured components) with their Lambertian parts split off, indexed like `SIDES`.
pub struct TreeFile {
    pub(crate) rank: usize,
    pub(crate) trees: [Option<Tree>; 4],
    pub(crate) lamb: [Lambertian; 4],
    /// Largest directional-hemispherical total (Lambertian part included).
    max_hemi: [Option<f64>; 4],
    /// Per component: (directional total at normal incidence, total for diffuse incidence,
    /// smallest leaf), from the tree before its Lambertian part was split off.
    totals: [Option<(f64, f64, f64)>; 4],
}

impl TreeFile {
    /// The tensor trees of an already read file; `None` when it holds none.
    pub fn load(b: &Bsdf) -> Option<TreeFile> {
        let rank = match b.structure? {
            DataStructure::TensorTree3 => 3,
            DataStructure::TensorTree4 => 4,
            DataStructure::Columns | DataStructure::Rows => return None,
        };
        // Per component: Visible, CIE-u, CIE-v trees (a later block of the same kind replaces an
        // earlier one).
        let mut nodes: [[Option<Node>; 3]; 4] = Default::default();
        for blk in &b.blocks {
            let BlockData::Tree(t) = &blk.data else {
                continue;
            };
            let kind = match blk.wavelength {
                Wavelength::Visible => 0,
                Wavelength::CieU => 1,
                Wavelength::CieV => 2,
                _ => continue,
            };
            nodes[slot(blk.direction)][kind] = Some(t.root().clone());
        }
        let mut k = 0;
        let mut trees = nodes.map(|[y, u, v]| {
            let side = SIDES[k].0;
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
        // One Lambertian transmission, copied to the side without a tree.
        let (ie, ei) = (Side::IntExt as usize, Side::ExtInt as usize);
        match (trees[ie].is_some(), trees[ei].is_some()) {
            (false, true) => lamb[ie] = lamb[ei],
            (true, false) => lamb[ei] = lamb[ie],
            _ => {}
        }
        Some(TreeFile {
            rank,
            trees,
            lamb,
            max_hemi,
            totals,
        })
    }

    /// The component-table entry of XML direction `d` (`None` without that tree): the Lambertian
    /// part, the largest directional total (π × the largest mean over incident strips of the
    /// smallest leaf's width, at least 1/32) and the angle, plus fenestra's totals for normal and
    /// diffuse incidence (integrated leaf by leaf: exact for the nearest-leaf tree; `totals` is
    /// left empty).
    pub fn component(&self, d: Direction) -> Option<ComponentCheck> {
        let k = slot(d);
        let (normal_total, diffuse_total, leaf) = self.totals[k]?;
        let l = self.lamb[k];
        Some(ComponentCheck {
            lambertian_xyz: l.xyz,
            lambertian_y: l.y / PI,
            max_total: self.max_hemi[k]?,
            min_angle_deg: ((PI * leaf * leaf) / PI).sqrt() * (360.0 / PI),
            normal_total,
            diffuse_total,
            totals: Vec::new(),
        })
    }

    /// The `Color:` flag: whether the first component kept among XML `Transmission Front`,
    /// `Transmission Back`, `Reflection Back`, `Reflection Front` still has its u′ tree.
    pub fn colour_flag(&self) -> bool {
        [Side::ExtInt, Side::IntExt, Side::IntRefl, Side::ExtRefl]
            .into_iter()
            .map(|s| s as usize)
            .find(|&k| self.kept(k))
            .and_then(|k| self.trees[k].as_ref())
            .is_some_and(|t| t.u.is_some())
    }

    /// Whether component `k` is kept: it has more than 0.001 left of its largest directional total
    /// after its Lambertian part.
    fn kept(&self, k: usize) -> bool {
        self.trees[k].is_some() && self.max_hemi[k].is_some_and(|m| m - self.lamb[k].y > 0.001)
    }

    /// The three reciprocity rows (Interior Refl, Exterior Refl, Transmission), drawing from
    /// `rng`.
    pub fn rows(self, rng: &mut Drand48) -> [SampledRow; 3] {
        let keep: [bool; 4] = std::array::from_fn(|k| self.kept(k));
        let mut k = 0;
        let trees = self.trees.map(|t| {
            k += 1;
            t.filter(|_| keep[k - 1])
        });
        let loaded = Loaded {
            rank: self.rank,
            trees,
            lamb: self.lamb.map(|l| l.y),
        };
        [
            loaded.row(rng, 1.0, 1.0),
            loaded.row(rng, -1.0, -1.0),
            loaded.row(rng, -1.0, 1.0),
        ]
    }
}

/// Index of an XML direction in [`SIDES`].
fn slot(d: Direction) -> usize {
    SIDES.iter().position(|&(_, e)| e == d).unwrap_or(0)
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
        TreeFile::load(&b).unwrap().rows(rng)
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

    /// A colour leaf without a chromaticity (NaN, as a recoloured leaf becomes where a mean has
    /// v′ = 0) makes the row [`SampledRow::NoColour`], never NaN statistics.
    #[test]
    fn nan_colour_leaf_is_reported() {
        let grid = |v: f32| Node::Grid {
            log2: 1,
            values: vec![v; 8],
        };
        let mut u_values = vec![0.2f32; 8];
        u_values[0] = f32::NAN;
        let tree = Tree {
            rank: 3,
            side: Side::IntRefl,
            root: grid(0.5),
            u: Some(Node::Grid {
                log2: 1,
                values: u_values,
            }),
            v: Some(grid(0.47)),
            memo: Memo::default(),
        };
        let mut loaded = Loaded {
            rank: 3,
            trees: [Some(tree), None, None, None],
            lamb: [0.0; 4],
        };
        assert_eq!(
            loaded.row(&mut Drand48::new(), 1.0, 1.0),
            SampledRow::NoColour
        );
        // The same tree with a valid u′ leaf: values.
        if let Some(t) = &mut loaded.trees[0] {
            t.u = Some(grid(0.2));
        }
        assert!(matches!(
            loaded.row(&mut Drand48::new(), 1.0, 1.0),
            SampledRow::Values(_)
        ));
    }

    #[test]
    fn lambertian_split_and_lookup_cube() {
        let node = crate::tree::TensorTree::parse(
            3,
            "{ {1} {2} {3} {4} {0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8} {6} {7} {8} }",
        )
        .unwrap()
        .root()
        .clone();
        let mut t = Tree {
            rank: 3,
            side: Side::IntRefl,
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
    }
}

#[cfg(test)]
mod table_tests {
    use super::*;
    use crate::tree::{smallest_leaf_edge, TensorTree};

    /// Totals of a tree integrated on its finest grid (the square ↔ disk map keeps projected
    /// solid angle: a cell of area `a` covers `π·a`): (normal incidence, diffuse incidence,
    /// largest directional total, angle in degrees = 2 × the finest cell in radians). Rank 3:
    /// incident position 0.5 − r/2 covers [0, 0.5) from r = 1 (grazing) to 0 (normal).
    fn grid_totals(t: &TensorTree) -> (f64, f64, f64, f64) {
        let cell = smallest_leaf_edge(t.root());
        let n = (1.0 / cell).round().max(1.0) as usize;
        let c = |k: usize| (k as f64 + 0.5) / n as f64;
        let hemi = |inc: &[f64]| -> f64 {
            let mut sum = 0.0;
            let mut pos = [0.0; 4];
            let r = inc.len();
            pos[..r].copy_from_slice(inc);
            for a in 0..n {
                for b in 0..n {
                    pos[r] = c(a);
                    pos[r + 1] = c(b);
                    sum += t.lookup(&pos[..r + 2]);
                }
            }
            PI * sum / (n * n) as f64
        };
        let mut totals = Vec::new();
        if t.rank() == 3 {
            for j in 0..n.div_ceil(2) {
                totals.push(hemi(&[c(j)]));
            }
        } else {
            for i in 0..n {
                for j in 0..n {
                    totals.push(hemi(&[c(i), c(j)]));
                }
            }
        }
        let normal = if t.rank() == 4 {
            hemi(&[0.5, 0.5])
        } else {
            totals.last().copied().unwrap_or(0.0)
        };
        // Diffuse incidence: incident cells weighted by their projected solid angle (uniform
        // in the square for rank 4; rank 3: cell j covers radii [1 − 2(j+1)/n, 1 − 2j/n]).
        let diffuse = if t.rank() == 3 {
            let mut acc = 0.0;
            for (j, tot) in totals.iter().enumerate() {
                let r_hi = (1.0 - 2.0 * j as f64 / n as f64).clamp(0.0, 1.0);
                let r_lo = (1.0 - 2.0 * (j + 1) as f64 / n as f64).clamp(0.0, 1.0);
                acc += tot * (r_hi * r_hi - r_lo * r_lo);
            }
            acc
        } else {
            totals.iter().sum::<f64>() / totals.len() as f64
        };
        let max = totals.iter().copied().fold(0.0, f64::max);
        (normal, diffuse, max, (2.0 * cell).to_degrees())
    }

    /// The leaf-by-leaf totals equal the finest-grid integration (to rounding) on genBSDF's
    /// rank-3 and rank-4 blinds, and the strip means of the largest total the finest-grid
    /// maximum (strips of the finest cell there).
    #[test]
    fn leafwise_totals_match_grid_integration() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/fixtures/dctimestep");
        for f in ["blinds_t3.xml", "blinds_t4.xml"] {
            let xml = std::fs::read_to_string(dir.join(f)).unwrap();
            let b = crate::read::parse(&xml, f).unwrap();
            let t = TreeFile::load(&b).unwrap();
            let mut checked = 0;
            for (_, d) in SIDES {
                let Some(leaf) = t.component(d) else {
                    assert!(b.block(d, &Wavelength::Visible).is_none(), "{f} {d:?}");
                    continue;
                };
                let Some(BlockData::Tree(tree)) =
                    b.block(d, &Wavelength::Visible).map(|blk| &blk.data)
                else {
                    panic!("{f} {d:?}: no tree block");
                };
                let (normal, diffuse, max, angle) = grid_totals(tree);
                for (a, g) in [
                    (leaf.normal_total, normal),
                    (leaf.diffuse_total, diffuse),
                    (leaf.min_angle_deg, angle),
                ] {
                    assert!(
                        (a - g).abs() < 1e-9 * g.abs().max(1.0),
                        "{f} {d:?}: {a} vs {g}"
                    );
                }
                assert!((leaf.max_total - max).abs() < 1e-6, "{f} {d:?}");
                checked += 1;
            }
            assert!(checked >= 2, "{f}");
        }
    }
}
