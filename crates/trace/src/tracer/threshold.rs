//! Source thresholding (rtrace `-dt`/`-dc`), after Radiance's `direct()` as its source
//! and documentation describe it (own code):
//!
//! 1. Every source sample is given its potential contribution — the BSDF coefficient times
//!    the source's radiance, as if nothing were in the way — except samples that a
//!    cached obstructor provably blocks (counted as a failed shadow test of their source).
//! 2. Samples are sorted by the brightness of that potential, brightest first.
//! 3. They are shadow-tested in that order; after the first [`MIN_TESTS`], testing stops
//!    when the next ⌊n^dc + ½⌋ potentials together (n = number of samples) are below
//!    `dt / weight` times the brightness of what the ray has gathered so far.
//! 4. Each untested sample is added with its potential times an estimated visibility:
//!    its source's hit rate so far (hits / tests, starting at 1/2) scaled by how this
//!    point's tested samples did against their sources' rates.
//!
//! Radiance keeps the hit counts and its obstructor caches for the whole run, so its
//! results depend on the order of the input rays and on its processes. fenestra keeps
//! them in a [`DirectState`] the caller carries from ray to ray; rtrace forks it for
//! blocks of records traced in parallel and merges the blocks' changes back in record
//! order ([`DirectState::fork`], [`DirectState::merge`]), so its output is the same for
//! any number of threads.
//!
//! One file on purpose (about 930 lines): the obstructor caches, the hit statistics and
//! the thresholded direct-light loop that reads and updates them are Radiance's `direct()`
//! and its source tests, kept together so that the carried state is in one place.

use super::*;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

/// Shadow tests always made before the threshold applies (Radiance's MINSHADCNT).
pub(super) const MIN_TESTS: usize = 2;
/// Obstructor cache resolution (cells per side of a cube face; Radiance's SHADCACHE).
const RES: usize = 20;
/// Sources after this many start with an empty obstructor cache instead of a cast one
/// (Radiance's MAX2SHADE).
const MAX_PRECAST: usize = 200;

/// Photopic brightness of an RGB colour (Radiance's default primaries).
fn bright(c: DVec3) -> f64 {
    0.265074126 * c.x + 0.670114631 * c.y + 0.064811243 * c.z
}

/// One source sample seen from a point.
#[derive(Debug, Clone, Copy)]
pub(super) struct SourceSample {
    /// Unit direction toward the sample.
    pub l: DVec3,
    /// Solid angle it stands for.
    pub omega: f64,
    /// Shadow-ray length.
    pub tmax: f64,
    /// Samples drawn for its source from this point.
    pub count: usize,
}

/// A sample with a potential contribution.
#[derive(Debug, Clone, Copy)]
pub(super) struct Candidate {
    si: usize,
    l: DVec3,
    tmax: f64,
    coef: DVec3,
    val: DVec3,
    /// Brightness of `val`, in single precision as Radiance keeps its sort keys and their
    /// running tail sums (a threshold decision near a tie then goes the same way).
    brt: f32,
    /// Its source has only this sample here (obstructor-cache lookups and records).
    single: bool,
}

/// Hit statistics and obstructor caches of source thresholding, carried from one input
/// ray to the next (see the module documentation). Made by [`Tracer::direct_state`] for
/// that tracer's sources.
///
/// A state can be [`fork`](Self::fork)ed into states that go on from it independently
/// (one per block of records, traced in parallel), whose changes are then
/// [`merge`](Self::merge)d back in a fixed order: the counts added, the cache cells each
/// set in turn. That keeps a whole run's statistics, as Radiance does, while the result
/// does not depend on which thread traced which block.
#[derive(Debug, Clone)]
pub struct DirectState {
    ntests: Vec<u64>,
    nhits: Vec<u64>,
    /// Counts when forked (merging adds the difference).
    ntests0: Vec<u64>,
    nhits0: Vec<u64>,
    /// Per source: the number of cells of its obstructor cache (0: not cached).
    lens: Arc<[usize]>,
    /// Per source: the cells as this state has them ([`UNCAST`]: the initial cell; None:
    /// all initial). Shared with forks until one side changes a source's cells.
    cells: Arc<Vec<Option<Arc<Vec<u32>>>>>,
    /// The cell changes since the fork, in order: (source, cell, value); not kept by a
    /// state that was not forked (nothing merges it).
    log: Vec<(usize, usize, u32)>,
    forked: bool,
    cands: Vec<Candidate>,
    tail: Vec<f32>,
}

impl DirectState {
    /// A fresh state for `lens.len()` sources (every one at a 1/2 hit rate, initial caches
    /// of `lens[si]` cells).
    fn new(lens: Vec<usize>) -> DirectState {
        let n = lens.len();
        DirectState {
            ntests: vec![2; n],
            nhits: vec![1; n],
            ntests0: vec![2; n],
            nhits0: vec![1; n],
            lens: lens.into(),
            cells: Arc::new(vec![None; n]),
            log: Vec::new(),
            forked: false,
            cands: Vec::new(),
            tail: Vec::new(),
        }
    }

    /// Number of sources this state is for.
    pub(super) fn sources(&self) -> usize {
        self.lens.len()
    }

    fn rate(&self, si: usize) -> f64 {
        self.nhits[si] as f64 / self.ntests[si] as f64
    }

    /// Cell `k` of source `si`'s cache as this state has it ([`UNCAST`]: initial).
    fn cell(&self, si: usize, k: usize) -> u32 {
        self.cells[si].as_ref().map_or(UNCAST, |c| c[k])
    }

    fn set_cell(&mut self, si: usize, k: usize, v: u32) {
        let len = self.lens[si];
        let c =
            Arc::make_mut(&mut self.cells)[si].get_or_insert_with(|| Arc::new(vec![UNCAST; len]));
        Arc::make_mut(c)[k] = v;
        if self.forked {
            self.log.push((si, k, v));
        }
    }

    /// A state that goes on from this one (its statistics and caches as they are now).
    pub fn fork(&self) -> DirectState {
        DirectState {
            ntests: self.ntests.clone(),
            nhits: self.nhits.clone(),
            ntests0: self.ntests.clone(),
            nhits0: self.nhits.clone(),
            lens: self.lens.clone(),
            cells: self.cells.clone(),
            log: Vec::new(),
            forked: true,
            cands: Vec::new(),
            tail: Vec::new(),
        }
    }

    /// Adds what `children` (forked from this state, or from a state forked from it
    /// before it changed) learnt, in their order: their test and hit counts, then their
    /// cache changes in the order they made them, over this state's own. Merging the
    /// children of one fork in a fixed order gives the same state whatever order they
    /// were traced in. The children are dropped before their changes are applied, so
    /// cells they shared with this state are changed in place, not copied.
    pub fn merge(&mut self, children: impl IntoIterator<Item = DirectState>) {
        let mut logs = Vec::new();
        for child in children {
            assert_eq!(
                child.sources(),
                self.sources(),
                "DirectState::merge: states of different tracers"
            );
            for si in 0..self.ntests.len() {
                self.ntests[si] += child.ntests[si] - child.ntests0[si];
                self.nhits[si] += child.nhits[si] - child.nhits0[si];
            }
            logs.push(child.log);
        }
        for (si, k, v) in logs.into_iter().flatten() {
            self.set_cell(si, k, v);
        }
    }
}

/// Where one source's obstructor cells lie: each cell holds the surface that last
/// blocked a shadow ray toward the source through that cell (0 = none, else index + 1).
#[derive(Debug, Clone)]
pub(super) enum CacheGeom {
    /// A sphere: a cube map of directions from its centre.
    Round { c: DVec3, r: f64 },
    /// A flat source: the front half of a cube map in its frame (a, b, normal n).
    Flat {
        c: DVec3,
        a: DVec3,
        b: DVec3,
        n: DVec3,
        reach: f64,
    },
    /// A distant source (unit direction s): a grid across the scene's bounding sphere
    /// (centre c, radius r), perpendicular to s.
    Distant {
        s: DVec3,
        a: DVec3,
        b: DVec3,
        c: DVec3,
        r: f64,
    },
}

/// A source's obstructor cache as the scene alone gives it (before any ray). Radiance
/// casts every cell when the source is first looked up; fenestra casts a cell when it is
/// first looked up, by whichever thread needs it — its content depends on the scene only.
#[derive(Debug)]
pub(super) struct ObsCache {
    geom: CacheGeom,
    /// Per cell: [`UNCAST`], or 0 (no blocker) or blocker index + 1.
    cells: Vec<AtomicU32>,
}

/// A cell not cast yet.
const UNCAST: u32 = u32::MAX;

/// Cell of a coordinate in [-1, 1] at `n` cells. The scale is a hair under n/2 so that
/// a coordinate on a cell boundary (as 0.5 is) goes to the lower cell, as in Radiance:
/// the caches then agree on which surface a cell holds.
fn bin(x: f64, n: usize) -> usize {
    ((n as f64 * (0.5 - 1e-6) * (1.0 + x)).max(0.0) as usize).min(n - 1)
}

/// Centre of cell `i` of `n` over [-1, 1].
fn centre(i: usize, n: usize) -> f64 {
    (i as f64 + 0.5) / n as f64 * 2.0 - 1.0
}

impl CacheGeom {
    fn len(&self) -> usize {
        match self {
            CacheGeom::Round { .. } => 6 * RES * RES,
            CacheGeom::Flat { .. } => RES * RES + 4 * (RES / 2) * RES,
            CacheGeom::Distant { .. } => 4 * RES * RES,
        }
    }

    /// The cell of a shadow ray starting at `p` with unit direction `l` (toward the
    /// source). A sphere's cells are indexed by `l` (the largest component, ties to the
    /// last axis, and the other two over it), a flat source's by `-l` in its frame.
    fn cell(&self, p: DVec3, l: DVec3) -> Option<usize> {
        match self {
            CacheGeom::Round { .. } => {
                let m = l.abs();
                // the largest component, ties to the last axis; the other two in turn
                let (ax, big, x, y) = if m.x > m.y.max(m.z) {
                    (0, l.x, l.y, l.z)
                } else if m.y > m.z {
                    (1, l.y, l.z, l.x)
                } else {
                    (2, l.z, l.x, l.y)
                };
                if big == 0.0 {
                    return None;
                }
                let inv = 1.0 / big.abs();
                let face = 2 * ax + usize::from(big < 0.0);
                Some(face * RES * RES + bin(x * inv, RES) * RES + bin(y * inv, RES))
            }
            CacheGeom::Flat { a, b, n, .. } => {
                let u = -l;
                let (x, y, z) = (u.dot(*a), u.dot(*b), u.dot(*n));
                if z <= 0.0 {
                    return None;
                }
                let (mx, my) = (x.abs(), y.abs());
                if z >= mx && z >= my {
                    return Some(bin(x / z, RES) * RES + bin(y / z, RES));
                }
                let half = RES / 2;
                let (side, main, other) = if mx >= my {
                    (usize::from(x < 0.0), mx, y)
                } else {
                    (2 + usize::from(y < 0.0), my, x)
                };
                // 0 next to the front face's edge, half - 1 at the horizon
                let k = bin(-z / main, RES).min(half - 1);
                Some(RES * RES + side * half * RES + k * RES + bin(other / main, RES))
            }
            CacheGeom::Distant { a, b, c, r, .. } => {
                let d = p - *c;
                let m = 2 * RES;
                let x = (d.dot(*a) + r) / (2.0 * r) * m as f64;
                let y = (d.dot(*b) + r) / (2.0 * r) * m as f64;
                if !(0.0..m as f64).contains(&x) || !(0.0..m as f64).contains(&y) {
                    return None;
                }
                Some(x as usize * m + y as usize)
            }
        }
    }

    /// The ray cast from the source outward through the middle of cell `k` (origin,
    /// unit direction): its first reliable blocker is the cell's initial content.
    fn cast(&self, k: usize) -> (DVec3, DVec3) {
        let nn = RES * RES;
        match self {
            CacheGeom::Round { c, r } => {
                let (face, i, j) = (k / nn, (k / RES) % RES, k % RES);
                let ax = face / 2;
                // cells are indexed by the direction toward the source: cast the other way
                let mut l = DVec3::ZERO;
                l[ax] = if face % 2 == 1 { -1.0 } else { 1.0 };
                l[(ax + 1) % 3] = centre(i, RES);
                l[(ax + 2) % 3] = centre(j, RES);
                let u = -l.normalize();
                (*c + u * (1.05 * r), u)
            }
            CacheGeom::Flat { c, a, b, n, reach } => {
                let o = *c + *n * (0.01 * reach);
                if k < nn {
                    let u = *a * centre(k / RES, RES) + *b * centre(k % RES, RES) + *n;
                    return (o, u.normalize());
                }
                let half = RES / 2;
                let k = k - nn;
                let (side, row, j) = (k / (half * RES), (k / RES) % half, k % RES);
                let (main, other) = match side {
                    0 => (*a, *b),
                    1 => (-*a, *b),
                    2 => (*b, *a),
                    _ => (-*b, *a),
                };
                let u = main + other * centre(j, RES) - *n * centre(row, RES);
                (o, u.normalize())
            }
            CacheGeom::Distant { s, a, b, c, r } => {
                let m = 2 * RES;
                let o =
                    *c + *a * (centre(k / m, m) * r) + *b * (centre(k % m, m) * r) + *s * (2.0 * r);
                (o, -*s)
            }
        }
    }
}

impl Tracer {
    /// Whether rtrace should carry a [`DirectState`] from ray to ray: `-dt > 0` and
    /// light sources that can give more than [`MIN_TESTS`] samples at a point.
    pub fn thresholding(&self) -> bool {
        self.obs.is_some()
    }

    /// A fresh thresholding state (every source at a 1/2 hit rate, initial caches); with
    /// thresholding off, a state for no sources (never used).
    pub fn direct_state(&self) -> DirectState {
        DirectState::new(match &self.obs {
            Some(obs) => obs
                .iter()
                .map(|c| c.as_ref().map_or(0, |c| c.cells.len()))
                .collect(),
            None => Vec::new(),
        })
    }

    /// The state a ray carries (None with thresholding off). Panics if `st` was not made
    /// by this tracer's [`direct_state`](Self::direct_state) (its caches would not fit).
    pub(super) fn state_for<'a>(&self, st: &'a mut DirectState) -> Option<&'a mut DirectState> {
        let obs = self.obs.as_ref()?;
        assert!(
            st.sources() == obs.len()
                && obs
                    .iter()
                    .zip(st.lens.iter())
                    .all(|(c, &n)| c.as_ref().map_or(0, |c| c.cells.len()) == n),
            "a DirectState made by another tracer"
        );
        Some(st)
    }

    /// The most source samples a point can get: one per sphere, distant or virtual
    /// source; with `-ds > 0` up to 64 per flat source (polygon, ring) and 64 per
    /// cylinder (a point close enough to it), else one.
    pub(super) fn most_samples(opts: &TraceOptions, sources: &[Source], shapes: &[Shape]) -> usize {
        sources
            .iter()
            .map(|s| match s.geom {
                SourceGeom::Local(sh) => match shapes[sh] {
                    Shape::Polygon(_) | Shape::Ring { .. } | Shape::Cone { .. }
                        if opts.ds > 0.0 =>
                    {
                        super::MAX_PARTS
                    }
                    _ => 1,
                },
                SourceGeom::Distant(_) | SourceGeom::Virtual { .. } => 1,
            })
            .fold(0, usize::saturating_add)
    }

    /// Whether thresholding applies: `-dt > 0` and more than [`MIN_TESTS`] samples at
    /// some point (with fewer, all are tested anyway).
    pub(super) fn wants_threshold(opts: &TraceOptions, most_samples: usize) -> bool {
        opts.dt > 0.0 && most_samples > MIN_TESTS
    }

    /// The initial obstructor cache of every source (None: not cached — virtual sources,
    /// glows with a radius, spotlights — or beyond [`MAX_PRECAST`]: empty).
    pub(super) fn build_caches(&self) -> Vec<Option<ObsCache>> {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for s in &self.accel.shapes {
            let (a, b) = s.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        let (bc, br) = if lo.x <= hi.x {
            ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-6) * 1.01)
        } else {
            (DVec3::ZERO, 1.0)
        };
        self.sources
            .iter()
            .enumerate()
            .map(|(si, s)| {
                let plain = match &self.mats[&s.mat] {
                    Material::Light { kind, .. } => match kind {
                        LightKind::Glow(r) => !r.is_finite() || *r <= 0.0,
                        LightKind::Spot(..) => false,
                        _ => true,
                    },
                    _ => false,
                };
                if !plain {
                    return None;
                }
                let geom = match s.geom {
                    SourceGeom::Virtual { .. } => return None,
                    SourceGeom::Distant(k) => {
                        let d = self.distant[k].dir;
                        let (a, b) = frame(d);
                        CacheGeom::Distant {
                            s: d,
                            a,
                            b,
                            c: bc,
                            r: br,
                        }
                    }
                    SourceGeom::Local(sh) => match &self.accel.shapes[sh] {
                        Shape::Sphere { c, r, .. } => CacheGeom::Round { c: *c, r: *r },
                        Shape::Polygon(poly) => {
                            let c = poly.centroid();
                            let reach = poly
                                .verts
                                .iter()
                                .map(|v| (*v - c).length())
                                .fold(0.0, f64::max);
                            let (a, b) = frame(poly.normal);
                            CacheGeom::Flat {
                                c,
                                a,
                                b,
                                n: poly.normal,
                                reach,
                            }
                        }
                        Shape::Ring { c, n, r1, .. } => {
                            let (a, b) = frame(*n);
                            CacheGeom::Flat {
                                c: *c,
                                a,
                                b,
                                n: *n,
                                reach: *r1,
                            }
                        }
                        // a cylinder's cache is a sphere's (cube of directions), cast
                        // from 1.05 × half its length around its midpoint
                        Shape::Cone { p0, axis, len, .. } => CacheGeom::Round {
                            c: *p0 + *axis * (0.5 * len),
                            r: 0.5 * len,
                        },
                    },
                };
                let first = if si < MAX_PRECAST { UNCAST } else { 0 };
                let cells = (0..geom.len()).map(|_| AtomicU32::new(first)).collect();
                Some(ObsCache { geom, cells })
            })
            .collect()
    }

    /// Cell `k` of a source's initial cache: the first reliable blocker met by the cell's
    /// cast (0: none, else index + 1).
    fn initial_cell(&self, oc: &ObsCache, k: usize) -> u32 {
        let v = oc.cells[k].load(Ordering::Relaxed);
        if v != UNCAST {
            return v;
        }
        let (o, u) = oc.geom.cast(k);
        let v = self.first_blocker(o, u).map_or(0, |b| b as u32 + 1);
        // threads racing here store the same value
        oc.cells[k].store(v, Ordering::Relaxed);
        v
    }

    /// The first surface along a ray that is a reliable blocker (skipping others).
    fn first_blocker(&self, o: DVec3, u: DVec3) -> Option<usize> {
        let mut t0 = Self::tmin(o);
        for _ in 0..64 {
            let h = self.accel.closest(o, u, t0, f64::INFINITY, None)?;
            if self.blocker[h.shape] {
                return Some(h.shape);
            }
            t0 = h.t + 1e-6 * (1.0 + h.t);
        }
        None
    }

    /// Whether the cached obstructor of source `si` blocks the shadow ray from `p` along
    /// `l` (length `tmax`) before it reaches the source.
    fn cache_blocks(
        &self,
        st: &DirectState,
        si: usize,
        p: DVec3,
        l: DVec3,
        tmax: f64,
        skip: Option<usize>,
    ) -> bool {
        let Some(Some(oc)) = self.obs.as_ref().map(|o| &o[si]) else {
            return false;
        };
        let Some(k) = oc.geom.cell(p, l) else {
            return false;
        };
        let b = match st.cell(si, k) {
            UNCAST => self.initial_cell(oc, k),
            v => v,
        };
        if b == 0 || Some(b as usize - 1) == skip || self.own_emitter(si, b as usize - 1) {
            return false;
        }
        let tmin = Self::tmin(p);
        let Some(tb) = self.accel.shapes[b as usize - 1].intersect(p, l, tmin, tmax) else {
            return false;
        };
        // blocked unless the source itself is met first
        match self.sources[si].geom {
            SourceGeom::Local(sh) => self.accel.shapes[sh]
                .intersect(p, l, tmin, f64::INFINITY)
                .is_none_or(|ts| tb < ts),
            _ => true,
        }
    }

    /// Whether shape `b` is source `si`'s own surface (not a blocker of that source; any
    /// other emitter is, even of the same material).
    fn own_emitter(&self, si: usize, b: usize) -> bool {
        self.surf_prim[b] == self.sources[si].prim
    }

    /// Records the surface that blocked a failed shadow test of source `si` in its cache.
    fn record_blocker(
        &self,
        st: &mut DirectState,
        si: usize,
        p: DVec3,
        l: DVec3,
        tmax: f64,
        skip: Option<usize>,
    ) {
        let Some(Some(oc)) = self.obs.as_ref().map(|o| &o[si]) else {
            return;
        };
        let Some(k) = oc.geom.cell(p, l) else {
            return;
        };
        let Some(h) = self.accel.closest(p, l, Self::tmin(p), tmax, skip) else {
            return;
        };
        if self.blocker[h.shape] && !self.own_emitter(si, h.shape) {
            st.set_cell(si, k, h.shape as u32 + 1);
        }
    }

    /// Radiance a shadow ray `c` (aimed at source `si`) would bring if nothing were in
    /// the way.
    fn potential(&self, c: &Ray, si: usize, cx: &mut Ctx) -> DVec3 {
        let s = &self.sources[si];
        let tmin = Self::tmin(c.org);
        match s.geom {
            SourceGeom::Distant(k) => {
                let d = &self.distant[k];
                self.shade_light(c, d.mat, d.prim, None, cx).0
            }
            SourceGeom::Local(sh) => {
                let shp = &self.accel.shapes[sh];
                if let (
                    Shape::Sphere { inward: false, .. },
                    Material::Light {
                        color,
                        kind: LightKind::Light,
                    },
                ) = (shp, &self.mats[&s.mat])
                {
                    // a plain light sphere seen from outside (the sample is its centre):
                    // its colour, unless a pattern modifies it
                    if self.patterns.get(&s.mat).is_none() {
                        return *color;
                    }
                }
                match shp.intersect(c.org, c.dir, tmin, f64::INFINITY) {
                    Some(t) => {
                        let q = c.org + c.dir * t;
                        let n = shp.normal(q);
                        let at = Surf {
                            shape: sh,
                            p: q,
                            n,
                            rod: -c.dir.dot(n),
                            t,
                        };
                        self.shade_light(c, s.mat, s.prim, Some(&at), cx).0
                    }
                    None => DVec3::ZERO,
                }
            }
            SourceGeom::Virtual { base, mirror, .. } => {
                let shp = &self.accel.shapes[mirror];
                let Some(t) = shp.intersect(c.org, c.dir, tmin, f64::INFINITY) else {
                    return DVec3::ZERO;
                };
                let (Material::Mirror { color }, SourceGeom::Distant(k)) =
                    (&self.mats[&self.surf_mat[mirror]], self.sources[base].geom)
                else {
                    return DVec3::ZERO;
                };
                let q = c.org + c.dir * t;
                let n = shp.normal(q);
                let rod = -c.dir.dot(n);
                let nrm = if rod < 0.0 { -n } else { n };
                let d = &self.distant[k];
                if d.dir.dot(nrm) <= 0.0 {
                    return DVec3::ZERO;
                }
                let mut rc = c.clone();
                rc.org = q;
                rc.dir = (c.dir + nrm * (2.0 * rod.abs())).normalize();
                rc.src = Some(base);
                let v = self.shade_light(&rc, d.mat, d.prim, None, cx);
                *color * v.0
            }
        }
    }

    /// [`Tracer::direct`] with thresholding (see the module documentation).
    pub(super) fn direct_threshold(
        &self,
        r: &Ray,
        lit: Lit,
        prior: DVec3,
        cx: &mut Ctx,
        bsdf: impl Fn(DVec3, f64, f64) -> DVec3,
    ) -> DVec3 {
        let Lit { p, n: nrm, shape } = lit;
        let skip = shape.filter(|&s| self.accel.shapes[s].is_flat());
        let Some(st) = cx.ds.as_deref_mut() else {
            return DVec3::ZERO;
        };
        let mut cands = std::mem::take(&mut st.cands);
        let mut tail = std::mem::take(&mut st.tail);
        cands.clear();
        for si in 0..self.sources.len() {
            self.each_sample(si, p, shape, r.weight, cx, |cx, s| {
                let single = s.count == 1;
                let Some(st) = cx.ds.as_deref_mut() else {
                    return;
                };
                // a sample its cached obstructor blocks counts as a failed test
                if single && self.cache_blocks(st, si, p, s.l, s.tmax, skip) {
                    st.ntests[si] += 1;
                    return;
                }
                let coef = bsdf(s.l, s.omega, s.l.dot(nrm));
                // any coefficient above 0 enters the sort and the counts (without
                // thresholding, `Tracer::shadow` skips those up to FTINY; each is kept as
                // it was, so neither output changes)
                if maxc(coef) <= 0.0 {
                    return;
                }
                let aim = Aim {
                    l: s.l,
                    tmax: s.tmax,
                    si,
                };
                let c = self.shadow_ray(r, Origin::at(p, skip), aim, DVec3::ONE);
                let val = coef * self.potential(&c, si, cx);
                let brt = bright(val) as f32;
                if brt > 0.0 {
                    cands.push(Candidate {
                        si,
                        l: s.l,
                        tmax: s.tmax,
                        coef,
                        val,
                        brt,
                        single,
                    });
                }
            });
        }
        // brightest first; equal ones in source order (a stable sort)
        cands.sort_by(|a, b| b.brt.total_cmp(&a.brt));
        let n = cands.len();
        tail.clear();
        tail.resize(n + 1, 0.0);
        for k in (0..n).rev() {
            tail[k] = tail[k + 1] + cands[k].brt;
        }
        // how many of the next potentials are weighed against the threshold: n^dc
        // rounded, at most all n (-dc > 1 weighs the whole rest, as -dc 1 does; Radiance
        // does the same until n^dc overflows its int, then it crashes); NaN gives 0
        let check = ((n as f64).powf(self.opts.dc) + 0.5).min(n as f64) as usize;
        let thresh = self.opts.dt / r.weight;
        let mut gathered = prior;
        let mut total = DVec3::ZERO;
        let (mut hits, mut expected) = (0u64, 0.0f64);
        let mut tested = 0;
        while tested < n {
            let k = tested;
            if k >= MIN_TESTS {
                let rest = if k.saturating_add(check) >= n {
                    tail[k]
                } else {
                    tail[k] - tail[k + check]
                };
                if (rest as f64) < thresh * bright(gathered) {
                    break;
                }
            }
            let cd = cands[k];
            if let Some(st) = cx.ds.as_deref_mut() {
                st.ntests[cd.si] += 1;
            }
            let aim = Aim {
                l: cd.l,
                tmax: cd.tmax,
                si: cd.si,
            };
            let c = self.shadow_ray(r, Origin::at(p, skip), aim, cd.coef);
            let v = self.trace(&c, cx);
            let Some(st) = cx.ds.as_deref_mut() else {
                break;
            };
            if (v.x + v.y + v.z) / 3.0 > FTINY {
                let val = cd.coef * v;
                total += val;
                gathered += val;
                hits += 1;
                st.nhits[cd.si] += 1;
            } else if cd.single {
                self.record_blocker(st, cd.si, p, cd.l, cd.tmax, skip);
            }
            expected += st.rate(cd.si);
            tested += 1;
        }
        if let Some(st) = cx.ds.as_deref_mut() {
            // untested samples: potential times the source's hit rate, scaled by how
            // this point's tests did against their sources' rates
            let scale = if expected > FTINY {
                hits as f64 / expected
            } else {
                0.5
            };
            for cd in &cands[tested..] {
                let prob = scale * st.rate(cd.si);
                total += if prob < 1.0 { cd.val * prob } else { cd.val };
            }
            st.cands = cands;
            st.tail = tail;
        }
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cell's cast, looked up as a shadow ray coming back along it, lands in that
    /// cell (the cast fills the cell lookups read).
    #[test]
    fn every_cell_cast_comes_back_to_its_cell() {
        let (a, b) = frame(DVec3::new(0.3, -0.2, 0.9).normalize());
        let n = a.cross(b);
        let geoms = [
            CacheGeom::Round {
                c: DVec3::new(1.0, 2.0, 3.0),
                r: 0.1,
            },
            CacheGeom::Flat {
                c: DVec3::new(-1.0, 0.5, 2.0),
                a,
                b,
                n,
                reach: 0.3,
            },
            CacheGeom::Distant {
                s: n,
                a,
                b,
                c: DVec3::new(5.0, 5.0, 1.0),
                r: 8.0,
            },
        ];
        for g in &geoms {
            for k in 0..g.len() {
                let (o, u) = g.cast(k);
                // a point further along the cast, looking back at the source
                let p = o + u * 2.5;
                assert_eq!(g.cell(p, -u), Some(k), "{g:?} cell {k}");
            }
        }
    }

    /// Every cell of every source of `st` (sources with `lens` cells).
    fn all_cells(st: &DirectState) -> Vec<Vec<u32>> {
        (0..st.sources())
            .map(|si| (0..st.lens[si]).map(|k| st.cell(si, k)).collect())
            .collect()
    }

    #[test]
    fn nested_forks_merge_up() {
        let mut base = DirectState::new(vec![10, 0, 5]);
        let mut a = base.fork();
        a.set_cell(0, 3, 7);
        a.ntests[0] += 2;
        a.nhits[0] += 1;
        let mut g = a.fork();
        // the grandchild changes a source its parent never touched
        g.set_cell(2, 4, 9);
        g.ntests[2] += 1;
        a.merge([g]);
        a.set_cell(0, 3, 8);
        base.merge([a]);
        assert_eq!(base.cell(0, 3), 8);
        assert_eq!(base.cell(2, 4), 9);
        let set: usize = all_cells(&base)
            .iter()
            .flatten()
            .filter(|&&v| v != UNCAST)
            .count();
        assert_eq!(set, 2);
        assert_eq!(base.ntests, [4, 2, 3]);
        assert_eq!(base.nhits, [2, 1, 1]);
    }

    #[test]
    fn merge_order_decides_a_cell_both_children_set() {
        let base = DirectState::new(vec![4, 4]);
        let (mut x, mut y) = (base.fork(), base.fork());
        x.set_cell(0, 1, 5);
        x.ntests[1] += 3;
        y.set_cell(0, 1, 6);
        y.set_cell(1, 2, 3);
        y.nhits[1] += 1;
        let (mut xy, mut yx) = (base.clone(), base.clone());
        xy.merge([x.clone()]);
        xy.merge([y.clone()]);
        yx.merge([y]);
        yx.merge([x]);
        assert_eq!(xy.cell(0, 1), 6);
        assert_eq!(yx.cell(0, 1), 5);
        assert_eq!(xy.cell(1, 2), 3);
        assert_eq!(yx.cell(1, 2), 3);
        assert_eq!((&xy.ntests, &xy.nhits), (&yx.ntests, &yx.nhits));
        assert_eq!(xy.ntests, [2, 5]);
        assert_eq!(xy.nhits, [1, 2]);
        // the children's changes never reached the state they were forked from
        assert!(all_cells(&base).iter().flatten().all(|&v| v == UNCAST));
    }

    #[test]
    fn a_wave_merged_at_once_changes_the_cells_in_place() {
        let mut base = DirectState::new(vec![4, 4]);
        let mut first = base.fork();
        first.set_cell(0, 0, 1);
        base.merge([first]);
        let (table, cells0) = (
            Arc::as_ptr(&base.cells),
            Arc::as_ptr(base.cells[0].as_ref().unwrap()),
        );
        // a wave of children: each copies the cells it changes, the parent's are not
        // copied again when their changes come back
        let mut wave: Vec<DirectState> = (0..3).map(|_| base.fork()).collect();
        wave[0].set_cell(0, 1, 5);
        wave[2].set_cell(0, 1, 6);
        wave[1].set_cell(1, 3, 2);
        let mut one_by_one = base.clone();
        for c in wave.clone() {
            one_by_one.merge([c]);
        }
        base.merge(wave);
        assert_eq!(Arc::as_ptr(&base.cells), table);
        assert_eq!(Arc::as_ptr(base.cells[0].as_ref().unwrap()), cells0);
        assert_eq!(
            all_cells(&base),
            [[1, 6, UNCAST, UNCAST], [UNCAST, UNCAST, UNCAST, 2]]
        );
        assert_eq!(all_cells(&base), all_cells(&one_by_one));
    }

    #[test]
    fn merged_changes_go_over_the_states_own() {
        // a forked state traced with (own changes) and then merging a child forked from it
        // earlier: the child's changes come after its own, and both are passed on up
        let mut base = DirectState::new(vec![4]);
        let mut p = base.fork();
        let mut c = p.fork();
        p.set_cell(0, 1, 4);
        p.set_cell(0, 2, 4);
        c.set_cell(0, 1, 9);
        // the child does not see its parent's later changes
        assert_eq!(c.cell(0, 2), UNCAST);
        p.merge([c]);
        assert_eq!((p.cell(0, 1), p.cell(0, 2)), (9, 4));
        assert_eq!(p.log, [(0, 1, 4), (0, 2, 4), (0, 1, 9)]);
        base.merge([p]);
        assert_eq!(all_cells(&base), [[UNCAST, 9, 4, UNCAST]]);
        // an unforked state keeps no log
        assert!(base.log.is_empty());
    }

    #[test]
    fn boundary_coordinates_go_to_the_lower_cell() {
        // 0.5 is the boundary of cells 14 and 15 of 20 over [-1, 1]
        assert_eq!(bin(0.5, RES), 14);
        assert_eq!(bin(0.5 + 1e-9, RES), 14);
        assert_eq!(bin(0.55, RES), 15);
        assert_eq!(bin(-1.0, RES), 0);
        assert_eq!(bin(1.0, RES), RES - 1);
    }
}
