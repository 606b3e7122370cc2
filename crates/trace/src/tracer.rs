//! The integrator: Radiance's shading rules with `-aa 0` (pure Monte Carlo).
//!
//! Every ray carries Radiance's ray-type flags (inherited from its parent), its weight
//! (for `-lw`/`-lr`) and its path coefficient (product of the coefficients back to the
//! primary ray, which rcontrib records). Random numbers come from one stream per input
//! ray ([`Rng::for_ray`]), used in a fixed order, so results do not depend on threads.

use std::f64::consts::PI;

use anyhow::{bail, Result};
use fenestra_scene::Scene;
use glam::DVec3;

use crate::bvh::Accel;
use crate::clip::ClipSet;
use crate::material::{compile, is_pattern, LightKind, Material, FTINY};
use crate::options::TraceOptions;
use crate::pattern::PatternInput;
use crate::rng::Rng;
use crate::shape::Shape;

mod ambient;
use ambient::{frame, square_to_disk};
mod compile;
mod cylinder;
mod direct;
mod flat;
mod query;
mod shade_bsdf;
mod shade_glass;
mod shade_light;
mod shade_normal;

use direct::{Aim, Lit};
use shade_normal::NormalLobes;
mod threshold;

pub use query::{FirstHit, SourceLight};

/// Most parts of a flat or cylinder source under `-ds` (Radiance's MAXSPART).
const MAX_PARTS: usize = 64;

/// Radiance's unrandomised choice of a direction across unit `n` (its `-u-` frame), not
/// yet made unit: the last coordinate axis where |n| < 0.6, crossed with `n`. Flat
/// sources normalise it with `flat::rad_normalize`, cylinder sources with `normalize`.
fn across_unnormalised(n: DVec3) -> DVec3 {
    let i = (0..3).rev().find(|&i| n[i].abs() < 0.6).unwrap_or(0);
    let mut e = DVec3::ZERO;
    e[i] = 1.0;
    e.cross(n)
}
use cylinder::CylSource;
use flat::FlatSource;
pub use threshold::DirectState;
use threshold::{ObsCache, SourceSample};

const SHADOW: u8 = 1;
const REFLECTED: u8 = 2;
const TRANS: u8 = 4;
const AMBIENT: u8 = 8;
const SPECULAR: u8 = 16;
/// rtrace/rcontrib `-i`: while a ray has only this flag (and TRANS), the first surface that
/// shades it gives the irradiance there (Radiance's irradiance hack).
const IRRAD: u8 = 32;

/// One recorded contribution: a ray that reached a surface (or distant source) whose
/// direct modifier is tracked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contribution {
    /// Scene index of the tracked modifier.
    pub modifier: usize,
    /// Path coefficient: product of the ray's and its ancestors' coefficients (rcontrib `-V-`).
    pub coef: [f64; 3],
    /// `coef` times the radiance the ray brought back (rcontrib `-V+`).
    pub value: [f64; 3],
    /// Origin of the ray that hit.
    pub org: DVec3,
    /// Its unit direction (`Dx Dy Dz`).
    pub dir: DVec3,
    /// Hit point (`Px Py Pz`); the ray origin for a distant source.
    pub hit: DVec3,
    /// Surface normal at the hit (`Nx Ny Nz`); `-dir` for a distant source.
    pub normal: DVec3,
    /// Distance from the primary ray's origin (`T`); 1e10 or more for a distant source.
    pub total_dist: f64,
    /// Length of this ray segment (`Ts`).
    pub dist: f64,
}

impl Contribution {
    /// Whether the coefficient is at most 1e-6 in every channel: what rcontrib without `-V`
    /// leaves out (Radiance 6's cut-off; with `-V` the value is held to it instead).
    pub fn negligible_coef(&self) -> bool {
        self.coef.iter().all(|&x| x <= 1e-6)
    }
}

#[derive(Debug, Clone)]
struct Ray {
    org: DVec3,
    dir: DVec3,
    tmax: f64,
    flags: u8,
    weight: f64,
    coef: DVec3,
    depth: i32,
    amb: u32,
    src: Option<usize>,
    skip: Option<usize>,
    /// Distance travelled before this ray's origin.
    start: f64,
    /// Modifiers this ray does not see (inside antimatter).
    clip: ClipSet,
}

/// A map from scene index to value stored densely (indexing is a bounds check, not a hash).
/// Where a ray meets a surface: the shape, the point, the surface normal as stored (not
/// turned toward the ray), `rod` = −ray direction · normal, and the distance travelled.
#[derive(Debug, Clone, Copy)]
struct Surf {
    shape: usize,
    p: DVec3,
    n: DVec3,
    rod: f64,
    t: f64,
}

impl Origin {
    /// A ray's start at `p` (leaving flat surface `skip`), at no distance.
    fn at(p: DVec3, skip: Option<usize>) -> Origin {
        Origin { p, skip, dist: 0.0 }
    }
}

impl Surf {
    /// The same point seen from the surface's other side.
    fn flipped(self) -> Surf {
        Surf {
            n: -self.n,
            rod: -self.rod,
            ..self
        }
    }
}

/// Where a ray that a surface spawns starts: the point, the flat surface it leaves (not
/// hit again), and the distance its parent travelled to get there.
#[derive(Debug, Clone, Copy)]
struct Origin {
    p: DVec3,
    skip: Option<usize>,
    dist: f64,
}

/// What a tracked surface or source reports to rcontrib: the point met, its normal and
/// the distance along the ray.
#[derive(Debug, Clone, Copy)]
struct Met {
    point: DVec3,
    normal: DVec3,
    dist: f64,
}

struct Dense<T>(Vec<Option<T>>);

impl<T> Default for Dense<T> {
    fn default() -> Self {
        Dense(Vec::new())
    }
}

impl<T> Dense<T> {
    fn get(&self, k: &usize) -> Option<&T> {
        self.0.get(*k).and_then(Option::as_ref)
    }
    fn contains_key(&self, k: &usize) -> bool {
        self.get(k).is_some()
    }
    fn insert(&mut self, k: usize, v: T) {
        if self.0.len() <= k {
            self.0.resize_with(k + 1, || None);
        }
        self.0[k] = Some(v);
    }
    fn values(&self) -> impl Iterator<Item = &T> {
        self.0.iter().flatten()
    }
}

impl<T> std::ops::Index<&usize> for Dense<T> {
    type Output = T;
    fn index(&self, k: &usize) -> &T {
        self.get(k).expect("material compiled for every surface")
    }
}

struct Ctx<'a> {
    rng: Rng,
    /// Rays traced in this context by kind ([`RayCounts`] order: primary, shadow, indirect,
    /// specular), added to the tracer's totals once, at the end.
    rays: [u64; 4],
    tracked: &'a [bool],
    sink: Option<&'a mut dyn FnMut(Contribution)>,
    /// Source-thresholding state (only when thresholding applies).
    ds: Option<&'a mut DirectState>,
}

#[derive(Debug, Clone, Copy)]
enum SourceGeom {
    Local(usize),
    Distant(usize),
    /// The image of distant source `base` (index into the sources) in the planar
    /// mirror `mirror` (a shape): reached only by shadow rays that meet that mirror
    /// and, reflected there, reach the source (Radiance's virtual sources, one relay).
    Virtual {
        base: usize,
        mirror: usize,
        dir: DVec3,
    },
}

#[derive(Debug, Clone)]
struct Source {
    geom: SourceGeom,
    /// Scene index of the emitting material.
    mat: usize,
    /// Scene index of the surface.
    prim: usize,
    /// A polygon or ring source's sampling geometry.
    flat: Option<FlatSource>,
    /// A cylinder source's sampling geometry.
    cyl: Option<CylSource>,
}

#[derive(Debug, Clone)]
struct Distant {
    prim: usize,
    mat: usize,
    dir: DVec3,
    /// Two unit vectors completing `dir` to an orthonormal frame (for `-dj`).
    frame: (DVec3, DVec3),
    cos_half: f64,
    omega: f64,
    glow: bool,
}

/// Rays traced, by kind (a tool's `-v` budget line).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// First rays of records (rtcontrib `-I` irradiance records start with their ambient
    /// samples instead, counted as indirect).
    pub primary: u64,
    /// Shadow rays toward light sources (with their continuations through glass).
    pub shadow: u64,
    /// Ambient samples and every ray descending from one.
    pub indirect: u64,
    /// Specular reflections and transmissions not below an ambient sample.
    pub specular: u64,
}

impl std::fmt::Display for RayCounts {
    /// `N primary, N shadow, N indirect (ambient samples and below), N specular/transmitted`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} primary, {} shadow, {} indirect (ambient samples and below), {} specular/transmitted",
            self.primary, self.shadow, self.indirect, self.specular
        )
    }
}

/// What the integrator switched on, and why (printed by `-v`).
#[derive(Debug, Clone, PartialEq)]
pub struct Effects {
    /// Shadow rays to light sources.
    pub direct: bool,
    /// Ambient (indirect diffuse) sampling.
    pub ambient: bool,
    /// Specular reflection/transmission rays.
    pub specular: bool,
    /// Shadow rays to distant sources stop at the first surface (no material passes them).
    pub occlusion_shadows: bool,
    /// One line per effect with its reason.
    pub notes: Vec<String>,
}

/// A scene prepared for tracing.
pub struct Tracer {
    accel: Accel,
    /// Scene index of each BVH shape's surface.
    surf_prim: Vec<usize>,
    /// Scene index of each BVH shape's material.
    surf_mat: Vec<usize>,
    mats: Dense<Material>,
    /// Patterns modifying each material (nearest first).
    patterns: Dense<Vec<crate::pattern::Pattern>>,
    /// Scene index of the direct modifier of every primitive.
    modifier_of: Vec<Option<usize>>,
    distant: Vec<Distant>,
    sources: Vec<Source>,
    opts: TraceOptions,
    effects: Effects,
    warnings: Vec<String>,
    rays: [std::sync::atomic::AtomicU64; 4],
    /// With source thresholding: every source's initial obstructor cache.
    obs: Option<Vec<Option<ObsCache>>>,
    /// Per BVH shape: a reliable shadow-ray blocker (opaque material, never clipped).
    blocker: Vec<bool>,
    /// Per scene primitive: a material `-i` passes straight through (Radiance's nominally
    /// transparent types and BSDF proxies), rather than taking the irradiance on it.
    irr_pass: Vec<bool>,
}

fn maxc(c: DVec3) -> f64 {
    c.max_element()
}

impl Tracer {
    /// Warnings found while preparing the scene (degenerate polygons …).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Where the scene's auxiliary files were found (the options' resolver).
    pub fn resolver(&self) -> &fenestra_io::raypath::Resolver {
        &self.opts.resolver
    }

    /// The effects switched on for this scene and options.
    pub fn effects(&self) -> &Effects {
        &self.effects
    }

    /// Number of light sources used for direct lighting.
    pub fn source_count(&self) -> usize {
        self.sources.len()
    }

    /// Whether anything in the scene emits light (a light source, or a glow such as a sky):
    /// without it every value is zero, the case worth a warning.
    pub fn emits(&self) -> bool {
        self.mats
            .values()
            .any(|m| matches!(m, Material::Light { .. }))
    }

    fn tmin(p: DVec3) -> f64 {
        1e-9 * (1.0 + p.abs().max_element())
    }

    /// Russian roulette and weight limits (Radiance's `rayorigin`); may scale `rcoef`.
    fn admit(&self, child: &mut Ray, rcoef: &mut DVec3, cx: &mut Ctx) -> bool {
        if child.weight <= 0.0 {
            return false;
        }
        let lr = self.opts.lr;
        let lw = self.opts.lw;
        if lr <= 0 {
            if lr < 0 && child.depth > -lr {
                return false;
            }
            if child.weight >= lw {
                return true;
            }
            if lw <= 0.0 {
                return true;
            }
            if cx.rng.next_f64() > child.weight / lw {
                return false;
            }
            let s = lw / child.weight;
            *rcoef *= s;
            child.coef *= s;
            child.weight = lw;
            true
        } else {
            child.depth <= lr && child.weight >= lw
        }
    }

    fn child(&self, r: &Ray, from: Origin, dir: DVec3, flag: u8, rcoef: DVec3) -> Ray {
        let Origin { p: org, skip, dist } = from;
        // A transmitted ray carries on what is left of a limited length (rcontrib -ld+:
        // Radiance limits the ray through glass, not the reflected one); shadow rays set
        // their own length.
        let tmax = if flag == TRANS && r.flags & SHADOW == 0 && r.tmax.is_finite() {
            r.tmax - dist
        } else {
            f64::INFINITY
        };
        Ray {
            org,
            dir,
            tmax,
            flags: r.flags | flag,
            weight: r.weight * maxc(rcoef),
            coef: r.coef * rcoef,
            // Radiance's reflection level: every ray but a straight transmission adds one
            depth: r.depth + i32::from(flag != TRANS),
            amb: r.amb,
            src: if flag == TRANS { r.src } else { None },
            skip,
            start: r.start + dist,
            clip: r.clip.clone(),
        }
    }

    fn report(&self, cx: &mut Ctx, r: &Ray, prim: usize, rcol: DVec3, met: Met, zeroed: bool) {
        let Met {
            point: hit,
            normal,
            dist,
        } = met;
        let Some(sink) = cx.sink.as_mut() else { return };
        let Some(m) = self.modifier_of[prim] else {
            return;
        };
        if !cx.tracked.get(m).copied().unwrap_or(false) || zeroed {
            return;
        }
        if let Some(s) = r.src {
            if self.sources[s].prim != prim {
                return;
            }
        }
        sink(Contribution {
            modifier: m,
            coef: r.coef.to_array(),
            value: (r.coef * rcol).to_array(),
            org: r.org,
            dir: r.dir,
            hit,
            normal,
            total_dist: r.start + dist,
            dist,
        });
    }

    /// Number of rays traced so far (all kinds).
    pub fn rays_traced(&self) -> u64 {
        let c = self.ray_counts();
        c.primary + c.shadow + c.indirect + c.specular
    }

    /// Rays traced so far, by kind.
    pub fn ray_counts(&self) -> RayCounts {
        let get = |k: usize| self.rays[k].load(std::sync::atomic::Ordering::Relaxed);
        RayCounts {
            primary: get(0),
            shadow: get(1),
            indirect: get(2),
            specular: get(3),
        }
    }

    fn trace(&self, r: &Ray, cx: &mut Ctx) -> DVec3 {
        // kind: a shadow ray (also where it passes through glass), the first ray of a
        // record, a ray descending from an ambient sample, or a specular/transmitted one
        let kind = if r.flags & SHADOW != 0 {
            1
        } else if r.depth == 0 && r.flags & !IRRAD == 0 {
            0
        } else if r.flags & AMBIENT != 0 {
            2
        } else {
            3
        };
        cx.rays[kind] += 1;
        let tmin = Self::tmin(r.org);
        if self.effects.occlusion_shadows && r.flags & SHADOW != 0 {
            if let Some(s) = r.src {
                if let SourceGeom::Distant(k) = self.sources[s].geom {
                    if self.accel.occluded(r.org, r.dir, tmin, r.tmax, r.skip) {
                        return DVec3::ZERO;
                    }
                    let d = &self.distant[k];
                    let (val, zeroed) = self.shade_light(r, d.mat, d.prim, None, cx);
                    self.report(cx, r, d.prim, val, Self::distant_met(r), zeroed);
                    return val;
                }
            }
        }
        match self.accel.closest(r.org, r.dir, tmin, r.tmax, r.skip) {
            None => {
                if r.tmax.is_finite() {
                    return DVec3::ZERO;
                }
                let k = match r.src {
                    Some(s) => match self.sources[s].geom {
                        SourceGeom::Distant(k) => Some(k),
                        SourceGeom::Local(_) | SourceGeom::Virtual { .. } => None,
                    },
                    None => self.find_distant(r.dir),
                };
                let Some(k) = k else { return DVec3::ZERO };
                let d = &self.distant[k];
                let (val, zeroed) = self.shade_light(r, d.mat, d.prim, None, cx);
                self.report(cx, r, d.prim, val, Self::distant_met(r), zeroed);
                val
            }
            Some(h) => {
                let p = r.org + r.dir * h.t;
                let n = self.accel.shapes[h.shape].normal(p);
                let m = self.surf_mat[h.shape];
                let met = Met {
                    point: p,
                    normal: n,
                    dist: h.t,
                };
                if r.clip.contains(m) {
                    // inside antimatter: this surface is not there (rcontrib still hears of
                    // it, with what came through, as from Radiance)
                    let mut c = r.clone();
                    c.clip.cross(m, r.dir.dot(n) < 0.0);
                    let val = self.pass(c, h.shape, p, h.t, cx);
                    self.report(cx, r, self.surf_prim[h.shape], val, met, false);
                    return val;
                }
                let s = Surf {
                    shape: h.shape,
                    p,
                    n,
                    rod: -r.dir.dot(n),
                    t: h.t,
                };
                let (val, zeroed) = self.shade(r, m, &s, cx);
                self.report(cx, r, self.surf_prim[h.shape], val, met, zeroed);
                val
            }
        }
    }

    /// What a distant source reports: the ray's origin, facing it, at 1e10 (Radiance's).
    fn distant_met(r: &Ray) -> Met {
        Met {
            point: r.org,
            normal: -r.dir,
            dist: 1e10,
        }
    }

    fn find_distant(&self, dir: DVec3) -> Option<usize> {
        let within = |d: &Distant| dir.dot(d.dir) >= d.cos_half - 1e-12;
        self.distant
            .iter()
            .position(|d| !d.glow && within(d))
            .or_else(|| self.distant.iter().position(within))
    }

    /// Continues a ray straight through the surface it hit.
    fn pass(&self, mut c: Ray, shape: usize, p: DVec3, t: f64, cx: &mut Ctx) -> DVec3 {
        let flat = self.accel.shapes[shape].is_flat();
        c.org = p;
        c.skip = flat.then_some(shape);
        c.start += t;
        if c.tmax.is_finite() {
            c.tmax -= t;
        }
        self.trace(&c, cx)
    }

    fn shade(&self, r: &Ray, m: usize, s: &Surf, cx: &mut Ctx) -> (DVec3, bool) {
        let Surf {
            shape,
            p,
            n,
            rod,
            t,
        } = *s;
        if r.flags & IRRAD != 0 && r.flags & !(IRRAD | TRANS) == 0 {
            // -i: emitters and antimatter act as usual (an illum passes the ray on to its
            // alternate material, antimatter shades with its first modifier where a ray
            // leaves it inside that modifier's volume, coming back here)
            if !matches!(
                self.mats[&m],
                Material::Light { .. } | Material::Antimatter { .. }
            ) {
                if self.irr_pass[m] {
                    return (self.pass(r.clone(), shape, p, t, cx), false);
                }
                let nf = if rod < 0.0 { -n } else { n };
                return (self.lambert(r, p, nf, Some(shape), cx), false);
            }
        }
        match &self.mats[&m] {
            Material::Light { .. } => self.shade_light(r, m, self.surf_prim[shape], Some(s), cx),
            Material::Glass { tn, n: idx } => (self.shade_glass(r, *tn, *idx, s, cx), false),
            Material::Dielectric { tn, n: idx } => {
                (self.shade_dielectric(r, *tn, *idx, s, cx), false)
            }
            Material::Bsdf(b) => (self.shade_bsdf(r, b, s, cx), false),
            // Reported to rcontrib with the value of the ray that met it, as by Radiance.
            Material::Antimatter { mods, first } => {
                (self.antimatter(r, mods, *first, s, cx), false)
            }
            Material::Mirror { color } => {
                if r.flags & SHADOW != 0 {
                    return (self.relay(r, s, *color, cx), false);
                }
                let nrm = if rod < 0.0 { -n } else { n };
                let pdot = rod.abs();
                let dir = (r.dir + nrm * (2.0 * pdot)).normalize();
                (self.spawn(r, s, dir, REFLECTED, *color, cx), false)
            }
            Material::Normal {
                color: c0,
                spec,
                rough,
                trans,
                tspec,
                metal,
            } => (
                self.shade_normal(
                    r,
                    *c0 * self.pattern(
                        m,
                        &PatternInput {
                            dir: r.dir,
                            point: p,
                            normal: n,
                            dist: t,
                        },
                    ),
                    &NormalLobes {
                        spec: *spec,
                        rough: *rough,
                        trans: *trans,
                        tspec: *tspec,
                        metal: *metal,
                    },
                    s,
                    cx,
                ),
                false,
            ),
        }
    }

    /// A ray reaching an antimatter surface: entering, it goes on blind to `mods`; leaving
    /// inside a volume of `first`, the surface is shaded with `first` facing the ray (the
    /// ray's clip set kept for what that spawns); otherwise it goes on seeing `mods` again.
    fn antimatter(
        &self,
        r: &Ray,
        mods: &[usize],
        first: Option<usize>,
        s: &Surf,
        cx: &mut Ctx,
    ) -> DVec3 {
        let entering = r.dir.dot(s.n) < 0.0;
        if !entering {
            if let Some(f) = first {
                if r.clip.inside(f) {
                    return self.shade(r, f, &s.flipped(), cx).0;
                }
            }
        }
        let mut c = r.clone();
        for &m in mods {
            if entering {
                // a ninth simultaneous modifier is not clipped (MAX_CLIP)
                c.clip.insert(m);
            } else {
                c.clip.remove(m);
            }
        }
        self.pass(c, s.shape, s.p, s.t, cx)
    }

    /// Where rays spawned at `s` start: its point, skipping it if flat.
    fn origin(&self, s: &Surf) -> Origin {
        Origin {
            p: s.p,
            skip: self.accel.shapes[s.shape].is_flat().then_some(s.shape),
            dist: s.t,
        }
    }

    /// Traces a ray spawned at `s` along `dir` with coefficient `rcoef` (Russian roulette
    /// and `-lw` applied) and returns its weighted value.
    fn spawn(&self, r: &Ray, s: &Surf, dir: DVec3, flag: u8, rcoef: DVec3, cx: &mut Ctx) -> DVec3 {
        let mut rc = rcoef;
        let mut c = self.child(r, self.origin(s), dir, flag, rc);
        if !self.admit(&mut c, &mut rc, cx) {
            return DVec3::ZERO;
        }
        rc * self.trace(&c, cx)
    }

    /// [`Self::spawn`] for one of several samples of a lobe: the child's weight is given
    /// (the lobe's share, as Radiance's) beside the coefficient, which carries the sample's
    /// own weighting.
    fn spawn_weighted(
        &self,
        r: &Ray,
        s: &Surf,
        dir: DVec3,
        flag: u8,
        (rcoef, weight): (DVec3, f64),
        cx: &mut Ctx,
    ) -> DVec3 {
        let mut rc = rcoef;
        let mut c = self.child(r, self.origin(s), dir, flag, rc);
        c.weight = weight;
        if !self.admit(&mut c, &mut rc, cx) {
            return DVec3::ZERO;
        }
        rc * self.trace(&c, cx)
    }
}
