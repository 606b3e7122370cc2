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

mod cylinder;
mod flat;
mod threshold;

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
    /// Rays traced in this context (added to the tracer's total once, at the end).
    rays: u64,
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
    cos_half: f64,
    omega: f64,
    glow: bool,
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
    rays: std::sync::atomic::AtomicU64,
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
    /// Prepares `scene` for tracing with `opts`.
    pub fn new(scene: &Scene, opts: &TraceOptions) -> Result<Tracer> {
        let mut shapes = Vec::new();
        let mut surf_prim = Vec::new();
        let mut surf_mat = Vec::new();
        let mut mats: Dense<Material> = Dense::default();
        let mut distant = Vec::new();
        let mut warnings = Vec::new();
        let mut patterns: Dense<Vec<crate::pattern::Pattern>> = Dense::default();
        let mut need_mat = |m: usize, mats: &mut Dense<Material>| -> Result<()> {
            if mats.contains_key(&m) {
                return Ok(());
            }
            let p = &scene.prims[m];
            if is_pattern(&p.ptype) {
                bail!(
                    "{}: '{}' is a {} (pattern), used where a material is expected",
                    p.loc,
                    p.name,
                    p.ptype
                );
            }
            let mut pats = Vec::new();
            for k in scene.modifier_chain(m) {
                pats.push(crate::pattern::compile(scene, k, &p.name, &opts.cal)?);
            }
            if !pats.is_empty() {
                patterns.insert(m, pats);
            }
            let mat = compile(scene, m)?;
            if let Material::Light {
                kind: LightKind::Illum(Some(a)),
                ..
            } = &mat
            {
                let a = *a;
                mats.insert(m, mat);
                let alt = compile(scene, a)?;
                mats.insert(a, alt);
                return Ok(());
            }
            mats.insert(m, mat);
            Ok(())
        };
        for (i, p) in scene.prims.iter().enumerate() {
            if !p.is_surface() {
                continue;
            }
            let Some(m) = p.modifier else { continue };
            let r = &p.rargs;
            let bad = |what: &str| anyhow::anyhow!("{}: {} '{}': {what}", p.loc, p.ptype, p.name);
            let shape = match p.ptype.as_str() {
                t if crate::surface::is_geometry(t) => match crate::surface::shape_of(p)? {
                    crate::surface::Built::Shape(shape, warn) => {
                        warnings.extend(warn);
                        shape
                    }
                    crate::surface::Built::Ignored(warn) => {
                        warnings.push(warn);
                        continue;
                    }
                },
                "source" => {
                    if r.len() != 4 {
                        return Err(bad("needs 4 real arguments"));
                    }
                    need_mat(m, &mut mats)?;
                    let dir = DVec3::new(r[0], r[1], r[2]).normalize_or_zero();
                    if dir == DVec3::ZERO {
                        return Err(bad("zero direction"));
                    }
                    let cos_half = (r[3].to_radians() * 0.5).cos();
                    let glow = matches!(
                        mats[&m],
                        Material::Light {
                            kind: LightKind::Glow(_),
                            ..
                        }
                    );
                    if !mats[&m].is_light() {
                        return Err(bad(
                            "a distant source needs a light, glow, illum or spotlight material",
                        ));
                    }
                    distant.push(Distant {
                        prim: i,
                        mat: m,
                        dir,
                        cos_half,
                        omega: 2.0 * PI * (1.0 - cos_half),
                        glow,
                    });
                    continue;
                }
                other => bail!(
                    "{}: surface type '{other}' of '{}' is not supported by fenestra's ray tracer",
                    p.loc,
                    p.name
                ),
            };
            need_mat(m, &mut mats)?;
            shapes.push(shape);
            surf_prim.push(i);
            surf_mat.push(m);
        }
        // Antimatter: the material of its first modifier shades where rays leave it.
        let firsts: Vec<(usize, usize)> = surf_mat
            .iter()
            .filter_map(|&m| match &mats[&m] {
                Material::Antimatter { first: Some(f), .. } => Some((m, *f)),
                _ => None,
            })
            .collect();
        for (am, f) in firsts {
            need_mat(f, &mut mats)?;
            if matches!(mats[&f], Material::Antimatter { .. }) {
                let p = &scene.prims[am];
                bail!(
                    "{}: antimatter '{}': its first modifier '{}' is itself antimatter",
                    p.loc,
                    p.name,
                    scene.prims[f].name
                );
            }
        }
        for (i, p) in scene.prims.iter().enumerate() {
            if p.ptype == "antimatter" && mats.contains_key(&i) {
                for name in p.sargs.iter().filter(|n| *n != "void") {
                    if scene.find_modifier(name, i).is_none() {
                        warnings.push(format!(
                            "{}: antimatter '{}': unknown modifier '{name}' ignored",
                            p.loc, p.name
                        ));
                    }
                }
            }
        }
        // light sources
        let mut sources = Vec::new();
        for (s, &m) in surf_mat.iter().enumerate() {
            if let Material::Light { color, kind } = &mats[&m] {
                let active = maxc(*color) > FTINY
                    && match kind {
                        LightKind::Glow(r) => *r > FTINY,
                        _ => true,
                    };
                if active {
                    if let Shape::Cone { len, r0, .. } = shapes[s] {
                        let p = &scene.prims[surf_prim[s]];
                        if p.ptype != "cylinder" {
                            // Radiance: "illegal material for cone" (also cup, tube)
                            bail!(
                                "{}: {} '{}' has the light-emitting material '{}': a light, illum, glow \
                                 or spotlight source must be a sphere, polygon, ring, cylinder or \
                                 source (Radiance stops with \"illegal material\" here too)",
                                p.loc,
                                p.ptype,
                                p.name,
                                scene.prims[m].name
                            );
                        }
                        if r0 > 0.2 * len {
                            warnings.push(format!(
                                "{}: cylinder source '{}': aspect too small (radius above 0.2 x length)",
                                p.loc, p.name
                            ));
                        }
                    }
                    // Radiance: "cannot hit source center" (a polygon whose vertex mean
                    // lies outside it, a ring with an inner radius)
                    let p = &scene.prims[surf_prim[s]];
                    let flat = match &shapes[s] {
                        Shape::Polygon(poly) => match FlatSource::polygon(poly) {
                            Ok((f, poor)) => {
                                if poor {
                                    warnings.push(format!(
                                        "{}: polygon source '{}': triangular source with poor aspect",
                                        p.loc, p.name
                                    ));
                                }
                                Some(f)
                            }
                            Err(why) => bail!(
                                "{}: polygon '{}' with the light-emitting material '{}': {why} \
                                 (Radiance stops here too)",
                                p.loc,
                                p.name,
                                scene.prims[m].name
                            ),
                        },
                        Shape::Ring { c, r0, r1, .. } => {
                            if *r0 > 0.0 {
                                bail!(
                                    "{}: ring '{}' with the light-emitting material '{}': cannot hit \
                                     source center (a ring source must have inner radius 0; Radiance \
                                     stops here too)",
                                    p.loc,
                                    p.name,
                                    scene.prims[m].name
                                );
                            }
                            // the normal as written (Radiance normalises it its own way)
                            let a = &p.rargs;
                            // (the shape's n is this vector normalised: same direction)
                            Some(FlatSource::disk(*c, DVec3::new(a[3], a[4], a[5]), *r1))
                        }
                        _ => None,
                    };
                    let cyl = match shapes[s] {
                        Shape::Cone {
                            p0, axis, len, r0, ..
                        } => Some(CylSource::new(p0, axis, len, r0)),
                        _ => None,
                    };
                    sources.push(Source {
                        geom: SourceGeom::Local(s),
                        mat: m,
                        prim: surf_prim[s],
                        flat,
                        cyl,
                    });
                }
            }
        }
        for (k, d) in distant.iter().enumerate() {
            if let Material::Light { color, .. } = &mats[&d.mat] {
                if !d.glow && maxc(*color) > FTINY {
                    sources.push(Source {
                        geom: SourceGeom::Distant(k),
                        mat: d.mat,
                        prim: d.prim,
                        flat: None,
                        cyl: None,
                    });
                }
            }
        }
        // Virtual sources: each distant source seen in each planar mirror (-dr > 0).
        if opts.dr > 0 {
            let real = sources.len();
            for (s, &m) in surf_mat.iter().enumerate() {
                if !matches!(mats[&m], Material::Mirror { .. }) || !shapes[s].is_flat() {
                    continue;
                }
                let n = shapes[s].normal(shapes[s].bounds().0);
                for b in 0..real {
                    if let SourceGeom::Distant(k) = sources[b].geom {
                        let d = distant[k].dir;
                        let dir = d - n * (2.0 * d.dot(n));
                        sources.push(Source {
                            geom: SourceGeom::Virtual {
                                base: b,
                                mirror: s,
                                dir,
                            },
                            mat: sources[b].mat,
                            prim: sources[b].prim,
                            flat: None,
                            cyl: None,
                        });
                    }
                }
            }
        }
        let modifier_of = scene.prims.iter().map(|p| p.modifier).collect();
        let specular = mats.values().any(|m| match m {
            Material::Mirror { .. }
            | Material::Glass { .. }
            | Material::Dielectric { .. }
            | Material::Bsdf(_) => true,
            Material::Normal {
                spec, trans, tspec, ..
            } => *spec > FTINY || (*trans > FTINY && *tspec > FTINY),
            Material::Light { .. } | Material::Antimatter { .. } => false,
        });
        let mut notes = Vec::new();
        let direct = !sources.is_empty() || opts.full;
        notes.push(if sources.is_empty() {
            "direct: off (no light sources in the scene)".to_string()
        } else {
            format!("direct: on ({} light source(s))", sources.len())
        });
        let ambient = opts.ab > 0 || opts.full;
        notes.push(if opts.ab > 0 {
            format!("ambient: on (-ab {})", opts.ab)
        } else {
            "ambient: off (-ab 0)".into()
        });
        notes.push(if specular {
            "specular: on (specular materials present)".into()
        } else {
            "specular: off (no specular materials)".into()
        });
        if opts.full {
            notes.push("effect selection disabled: full integrator".into());
        }
        let passes_shadows = mats.values().any(|m| match m {
            Material::Glass { .. } | Material::Dielectric { .. } => true,
            Material::Normal {
                trans,
                tspec,
                rough,
                ..
            } => *trans > FTINY && *tspec > FTINY && rough * rough <= FTINY,
            Material::Light {
                kind: LightKind::Illum(_),
                ..
            } => true,
            // clipped surfaces let shadow rays through
            Material::Antimatter { .. } => true,
            _ => false,
        });
        let occlusion_shadows = !passes_shadows && !opts.full;
        notes.push(if passes_shadows {
            "shadow rays: traced through surfaces (glass, illum, antimatter or transmitting materials present)"
                .into()
        } else {
            "shadow rays to distant sources: occlusion test only (no material lets them through)"
                .into()
        });
        let specular = specular || opts.full;
        let most = Self::most_samples(opts, &sources, &shapes);
        let threshold = direct && Self::wants_threshold(opts, most);
        notes.push(if threshold {
            format!(
                "source thresholding: on (-dt {} -dc {}, {} source(s)): only the brightest source samples are shadow-tested",
                opts.dt,
                opts.dc,
                sources.len()
            )
        } else if opts.dt > 0.0 && direct {
            format!(
                "source thresholding: off (-dt {}, but at most {most} source sample(s) per point and the first {} are always tested)",
                opts.dt,
                threshold::MIN_TESTS
            )
        } else {
            format!("source thresholding: off (-dt {}): every source sample is shadow-tested", opts.dt)
        });
        let clipped: Vec<usize> = mats
            .values()
            .filter_map(|m| match m {
                Material::Antimatter { mods, .. } => Some(mods.iter().copied()),
                _ => None,
            })
            .flatten()
            .collect();
        // Radiance's opaque material types (a shadow ray meeting one stops there; a
        // light or spotlight stops shadow rays aimed at other sources)
        let irr_pass = scene
            .prims
            .iter()
            .map(|p| match p.ptype.as_str() {
                // (trans2, interface, mist and aBSDF would pass too, but the material
                // compiler rejects them before this point)
                "trans" | "dielectric" | "glass" => true,
                "BSDF" => p.sargs.first().is_some_and(|t| t != "0"),
                _ => false,
            })
            .collect();
        let blocker = surf_mat
            .iter()
            .map(|m| {
                matches!(
                    scene.prims[*m].ptype.as_str(),
                    "plastic" | "metal" | "light" | "spotlight"
                ) && !clipped.contains(m)
            })
            .collect();
        let mut tracer = Tracer {
            accel: Accel::new(shapes),
            surf_prim,
            surf_mat,
            mats,
            modifier_of,
            patterns,
            distant,
            sources,
            opts: opts.clone(),
            effects: Effects {
                direct,
                ambient,
                specular,
                occlusion_shadows,
                notes,
            },
            warnings,
            rays: std::sync::atomic::AtomicU64::new(0),
            obs: None,
            blocker,
            irr_pass,
        };
        if threshold {
            tracer.obs = Some(tracer.build_caches());
        }
        Ok(tracer)
    }

    /// Warnings found while preparing the scene (degenerate polygons …).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The effects switched on for this scene and options.
    pub fn effects(&self) -> &Effects {
        &self.effects
    }

    /// Number of light sources used for direct lighting.
    pub fn source_count(&self) -> usize {
        self.sources.len()
    }

    fn primary(org: DVec3, dir: DVec3) -> Ray {
        Ray {
            org,
            dir,
            tmax: f64::INFINITY,
            flags: 0,
            weight: 1.0,
            coef: DVec3::ONE,
            depth: 0,
            amb: 0,
            src: None,
            skip: None,
            start: 0.0,
            clip: ClipSet::default(),
        }
    }

    /// Radiance along a ray (`dir` need not be unit; a zero direction gives zero).
    /// With source thresholding the hit statistics start afresh for this ray; see
    /// [`radiance_with`](Self::radiance_with) to carry them over rays.
    pub fn radiance(&self, ray_index: u64, org: DVec3, dir: DVec3) -> [f64; 3] {
        self.radiance_with(&mut self.direct_state(), ray_index, org, dir)
    }

    /// As [`radiance`](Self::radiance), using and updating the source-thresholding
    /// state `st` (hit statistics and obstructor caches carried from ray to ray).
    pub fn radiance_with(
        &self,
        st: &mut DirectState,
        ray_index: u64,
        org: DVec3,
        dir: DVec3,
    ) -> [f64; 3] {
        let cx = self.ctx(ray_index, &[], None, self.state_for(st));
        let d = dir.normalize_or_zero();
        if d == DVec3::ZERO {
            return [0.0; 3];
        }
        self.run(&Self::primary(org, d), cx)
    }

    /// Irradiance at `point` itself on a surface facing `normal` (rtrace `-I` evaluates
    /// it at [`Self::rtrace_irradiance_point`] of the input point).
    pub fn irradiance(&self, ray_index: u64, point: DVec3, normal: DVec3) -> [f64; 3] {
        self.irradiance_with(&mut self.direct_state(), ray_index, point, normal)
    }

    /// As [`irradiance`](Self::irradiance) with a source-thresholding state (see
    /// [`radiance_with`](Self::radiance_with)).
    pub fn irradiance_with(
        &self,
        st: &mut DirectState,
        ray_index: u64,
        point: DVec3,
        normal: DVec3,
    ) -> [f64; 3] {
        let cx = self.ctx(ray_index, &[], None, self.state_for(st));
        let n = normal.normalize_or_zero();
        if n == DVec3::ZERO {
            return [0.0; 3];
        }
        self.run_irradiance(point, n, cx)
    }

    /// Traces a ray and reports every ray that reaches a surface whose direct modifier
    /// is tracked (`tracked[scene prim index]`), as rcontrib does; returns the radiance.
    pub fn contributions(
        &self,
        ray_index: u64,
        org: DVec3,
        dir: DVec3,
        tracked: &[bool],
        sink: &mut impl FnMut(Contribution),
    ) -> [f64; 3] {
        self.contributions_limited(ray_index, org, dir, f64::INFINITY, tracked, sink)
    }

    /// As [`contributions`](Self::contributions) for a ray that ends after `len` (rcontrib
    /// `-ld+`): nothing beyond, not even a distant source; rays transmitted on the way keep
    /// what is left of the length.
    pub fn contributions_limited(
        &self,
        ray_index: u64,
        org: DVec3,
        dir: DVec3,
        len: f64,
        tracked: &[bool],
        sink: &mut impl FnMut(Contribution),
    ) -> [f64; 3] {
        self.contributions_flagged(ray_index, org, dir, len, 0, tracked, sink)
    }

    /// The primary ray of rcontrib's normal (`flags` 0) and `-i` (`IRRAD`) modes, ending
    /// after `len`, traced with `sink` receiving the tracked contributions.
    #[allow(clippy::too_many_arguments)]
    fn contributions_flagged(
        &self,
        ray_index: u64,
        org: DVec3,
        dir: DVec3,
        len: f64,
        flags: u8,
        tracked: &[bool],
        sink: &mut impl FnMut(Contribution),
    ) -> [f64; 3] {
        let d = dir.normalize_or_zero();
        if d == DVec3::ZERO || len.is_nan() || len <= 0.0 {
            return [0.0; 3];
        }
        let r = Ray {
            tmax: len,
            flags,
            ..Self::primary(org, d)
        };
        self.run(&r, self.ctx(ray_index, tracked, Some(sink), None))
    }

    /// As [`contributions`](Self::contributions) for an irradiance request (`-I+`):
    /// `point` and `normal` as in [`irradiance`](Self::irradiance).
    pub fn contributions_irradiance(
        &self,
        ray_index: u64,
        point: DVec3,
        normal: DVec3,
        tracked: &[bool],
        sink: &mut impl FnMut(Contribution),
    ) -> [f64; 3] {
        let n = normal.normalize_or_zero();
        if n == DVec3::ZERO {
            return [0.0; 3];
        }
        let cx = self.ctx(ray_index, tracked, Some(sink), None);
        self.run_irradiance(point, n, cx)
    }

    /// The tracing context of input ray `ray_index` (its random numbers fixed by the seed
    /// and the index).
    fn ctx<'a>(
        &self,
        ray_index: u64,
        tracked: &'a [bool],
        sink: Option<&'a mut dyn FnMut(Contribution)>,
        ds: Option<&'a mut DirectState>,
    ) -> Ctx<'a> {
        Ctx {
            rng: Rng::for_ray(self.opts.seed, ray_index),
            rays: 0,
            tracked,
            sink,
            ds,
        }
    }

    /// Traces the primary ray `r` in `cx` and adds its rays to the tracer's count.
    fn run(&self, r: &Ray, mut cx: Ctx) -> [f64; 3] {
        let v = self.trace(r, &mut cx);
        self.count(&cx);
        v.to_array()
    }

    /// Irradiance at `p` facing unit `n` in `cx`, counting its rays.
    fn run_irradiance(&self, p: DVec3, n: DVec3, mut cx: Ctx) -> [f64; 3] {
        let v = self.irradiance_in(p, n, &mut cx);
        self.count(&cx);
        v.to_array()
    }

    fn count(&self, cx: &Ctx) {
        self.rays
            .fetch_add(cx.rays, std::sync::atomic::Ordering::Relaxed);
    }

    /// Where Radiance's rtrace `-I` evaluates the irradiance for an input `point` and
    /// unit `normal`: its fake ray starts 1.1e-4 along the normal and "hits" 1e-5 back
    /// toward the point, i.e. 1e-4 along the normal (computed in those two steps, as
    /// rtrace does, so that the rounding is the same).
    pub fn rtrace_irradiance_point(point: DVec3, normal: DVec3) -> DVec3 {
        (point + normal * 1.1e-4) + (-normal) * 1e-5
    }

    /// Where Radiance's rcontrib `-I` evaluates the irradiance: 1e-4 along the unit
    /// `normal` from `point`, in one step.
    pub fn rcontrib_irradiance_point(point: DVec3, normal: DVec3) -> DVec3 {
        point + normal * 1e-4
    }

    /// `-I` at `p` itself (the tools move it off the surface first, see
    /// [`Self::rtrace_irradiance_point`]).
    fn irradiance_in(&self, p: DVec3, n: DVec3, cx: &mut Ctx) -> DVec3 {
        // Radiance's -I: a Lambertian of reflectance pi at the point, seen along -n.
        let r = Ray {
            org: p + n * 1e-5,
            dir: -n,
            ..Self::primary(p, -n)
        };
        self.lambert(&r, p, n, None, cx)
    }

    /// Irradiance at `p` on a surface facing unit `n` (Radiance's irradiance hack: a
    /// Lambertian of reflectance pi there, patterns ignored), reached by ray `r` (its clip
    /// set and weight carry over to the shadow and ambient rays); `shape` is the surface
    /// hit, if any.
    fn lambert(&self, r: &Ray, p: DVec3, n: DVec3, shape: Option<usize>, cx: &mut Ctx) -> DVec3 {
        let rho = DVec3::splat(PI);
        let lamb = |_l: DVec3, omega: f64, ldot: f64| {
            if ldot > 0.0 {
                rho * (ldot * omega / PI)
            } else {
                DVec3::ZERO
            }
        };
        if cx.ds.is_some() {
            // thresholding: direct light last, as Radiance (its threshold is relative
            // to what the surface already returns)
            let amb = self.ambient(r, p, n, rho, shape, cx);
            return amb + self.direct(r, p, n, shape, amb, cx, lamb);
        }
        let mut val = self.direct(r, p, n, shape, DVec3::ZERO, cx, lamb);
        val += self.ambient(r, p, n, rho, shape, cx);
        val
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

    #[allow(clippy::too_many_arguments)]
    fn child(
        &self,
        r: &Ray,
        org: DVec3,
        dir: DVec3,
        flag: u8,
        rcoef: DVec3,
        skip: Option<usize>,
        dist: f64,
    ) -> Ray {
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
            depth: r.depth + 1,
            amb: r.amb,
            src: if flag == TRANS { r.src } else { None },
            skip,
            start: r.start + dist,
            clip: r.clip.clone(),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn report(
        &self,
        cx: &mut Ctx,
        r: &Ray,
        prim: usize,
        rcol: DVec3,
        hit: DVec3,
        normal: DVec3,
        dist: f64,
        zeroed: bool,
    ) {
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
        if maxc(r.coef) <= 1e-6 {
            return;
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
        self.rays.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn trace(&self, r: &Ray, cx: &mut Ctx) -> DVec3 {
        cx.rays += 1;
        let tmin = Self::tmin(r.org);
        if self.effects.occlusion_shadows && r.flags & SHADOW != 0 {
            if let Some(s) = r.src {
                if let SourceGeom::Distant(k) = self.sources[s].geom {
                    if self.accel.occluded(r.org, r.dir, tmin, r.tmax, r.skip) {
                        return DVec3::ZERO;
                    }
                    let d = &self.distant[k];
                    let (val, zeroed) = self.shade_light(
                        r,
                        d.mat,
                        d.prim,
                        1.0,
                        f64::INFINITY,
                        DVec3::ZERO,
                        None,
                        cx,
                    );
                    self.report(cx, r, d.prim, val, r.org, -r.dir, 1e10, zeroed);
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
                let (val, zeroed) =
                    self.shade_light(r, d.mat, d.prim, 1.0, f64::INFINITY, DVec3::ZERO, None, cx);
                self.report(cx, r, d.prim, val, r.org, -r.dir, 1e10, zeroed);
                val
            }
            Some(h) => {
                let p = r.org + r.dir * h.t;
                let n = self.accel.shapes[h.shape].normal(p);
                let m = self.surf_mat[h.shape];
                if r.clip.contains(m) {
                    // inside antimatter: this surface is not there (rcontrib still hears of
                    // it, with what came through, as from Radiance)
                    let mut c = r.clone();
                    c.clip.cross(m, r.dir.dot(n) < 0.0);
                    let val = self.pass(c, h.shape, p, h.t, cx);
                    self.report(cx, r, self.surf_prim[h.shape], val, p, n, h.t, false);
                    return val;
                }
                let (val, zeroed) = self.shade(r, m, h.shape, p, n, h.t, cx);
                self.report(cx, r, self.surf_prim[h.shape], val, p, n, h.t, zeroed);
                val
            }
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

    #[allow(clippy::too_many_arguments)]
    fn shade(
        &self,
        r: &Ray,
        m: usize,
        shape: usize,
        p: DVec3,
        n: DVec3,
        t: f64,
        cx: &mut Ctx,
    ) -> (DVec3, bool) {
        let rod = -r.dir.dot(n);
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
            Material::Light { .. } => {
                self.shade_light(r, m, self.surf_prim[shape], rod, t, p, Some(shape), cx)
            }
            Material::Glass { tn, n: idx } => (
                self.shade_glass(r, *tn, *idx, shape, p, n, rod, t, cx),
                false,
            ),
            Material::Dielectric { tn, n: idx } => (
                self.shade_dielectric(r, *tn, *idx, shape, p, n, rod, t, cx),
                false,
            ),
            Material::Bsdf(b) => (self.shade_bsdf(r, b, shape, p, n, t, cx), false),
            // Reported to rcontrib with the value of the ray that met it, as by Radiance.
            Material::Antimatter { mods, first } => {
                (self.antimatter(r, mods, *first, shape, p, n, t, cx), false)
            }
            Material::Mirror { color } => {
                if r.flags & SHADOW != 0 {
                    return (self.relay(r, shape, p, n, rod, t, *color, cx), false);
                }
                let nrm = if rod < 0.0 { -n } else { n };
                let pdot = rod.abs();
                let dir = (r.dir + nrm * (2.0 * pdot)).normalize();
                (
                    self.spawn(r, p, dir, REFLECTED, *color, shape, t, cx),
                    false,
                )
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
                    *spec,
                    *rough,
                    *trans,
                    *tspec,
                    *metal,
                    shape,
                    p,
                    n,
                    rod,
                    t,
                    cx,
                ),
                false,
            ),
        }
    }

    /// A ray reaching an antimatter surface: entering, it goes on blind to `mods`; leaving
    /// inside a volume of `first`, the surface is shaded with `first` facing the ray (the
    /// ray's clip set kept for what that spawns); otherwise it goes on seeing `mods` again.
    #[allow(clippy::too_many_arguments)]
    fn antimatter(
        &self,
        r: &Ray,
        mods: &[usize],
        first: Option<usize>,
        shape: usize,
        p: DVec3,
        n: DVec3,
        t: f64,
        cx: &mut Ctx,
    ) -> DVec3 {
        let entering = r.dir.dot(n) < 0.0;
        if !entering {
            if let Some(f) = first {
                if r.clip.inside(f) {
                    return self.shade(r, f, shape, p, -n, t, cx).0;
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
        self.pass(c, shape, p, t, cx)
    }

    #[allow(clippy::too_many_arguments)]
    fn spawn(
        &self,
        r: &Ray,
        p: DVec3,
        dir: DVec3,
        flag: u8,
        rcoef: DVec3,
        shape: usize,
        t: f64,
        cx: &mut Ctx,
    ) -> DVec3 {
        let mut rc = rcoef;
        let skip = self.accel.shapes[shape].is_flat().then_some(shape);
        let mut c = self.child(r, p, dir, flag, rc, skip, t);
        if !self.admit(&mut c, &mut rc, cx) {
            return DVec3::ZERO;
        }
        rc * self.trace(&c, cx)
    }

    #[allow(clippy::too_many_arguments)]
    fn shade_light(
        &self,
        r: &Ray,
        m: usize,
        prim: usize,
        rod: f64,
        t: f64,
        p: DVec3,
        shape: Option<usize>,
        cx: &mut Ctx,
    ) -> (DVec3, bool) {
        let Material::Light { color, kind } = &self.mats[&m] else {
            return (DVec3::ZERO, false);
        };
        let distglow = matches!(kind, LightKind::Glow(rad) if *rad >= -FTINY && t > *rad);
        if r.flags & (AMBIENT | SPECULAR) != 0 && !(r.flags & SHADOW != 0 || rod < 0.0 || distglow)
        {
            return (DVec3::ZERO, true);
        }
        // A shadow ray is aimed at one source object: meeting another emitter, even one
        // of the same material, it is stopped (as Radiance compares the object hit with
        // the source's object), unless that emitter is an illum it may pass. An illum
        // does not pass a ray aimed at another illum or glow when met from its front
        // (that would count the light twice), except a ray relayed toward a virtual source.
        let own_source = r.src.is_none_or(|s| self.sources[s].prim == prim);
        if !own_source {
            let blocked = match kind {
                LightKind::Illum(_) => {
                    let s = &self.sources[r.src.expect("aimed ray")];
                    !matches!(s.geom, SourceGeom::Virtual { .. })
                        && rod > 0.0
                        && matches!(
                            self.mats[&s.mat],
                            Material::Light {
                                kind: LightKind::Illum(_) | LightKind::Glow(_),
                                ..
                            }
                        )
                }
                _ => true,
            };
            if blocked {
                return (DVec3::ZERO, true);
            }
        }
        if let LightKind::Illum(alt) = kind {
            // An illum is a source only for its own shadow rays; any other ray (a view
            // ray, or a shadow ray toward another source such as the sun through the
            // window it stands in) meets its alternate material.
            if r.src.is_none() || !own_source {
                if let Some(shape) = shape {
                    return match alt {
                        Some(a) => {
                            let n = self.accel.shapes[shape].normal(p);
                            self.shade(r, *a, shape, p, n, t, cx)
                        }
                        None => (self.pass(r.clone(), shape, p, t, cx), false),
                    };
                }
            }
        }
        if rod < 0.0 {
            return (DVec3::ZERO, false);
        }
        if let LightKind::Spot(cosang, aim, _) = kind {
            if (-r.dir).dot(*aim) < *cosang {
                return (DVec3::ZERO, false);
            }
        }
        let normal = match shape {
            Some(s) => self.accel.shapes[s].normal(p),
            None => -r.dir,
        };
        let q = PatternInput {
            dir: r.dir,
            point: p,
            normal,
            dist: t,
        };
        (*color * self.pattern(m, &q), false)
    }

    /// Product of the patterns on material `m` for a ray going along `dir`.
    fn pattern(&self, m: usize, q: &PatternInput) -> DVec3 {
        match self.patterns.get(&m) {
            None => DVec3::ONE,
            Some(ps) => ps.iter().fold(DVec3::ONE, |acc, p| acc * p.eval(q)),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn shade_bsdf(
        &self,
        r: &Ray,
        b: &crate::bsdf_mat::BsdfMat,
        shape: usize,
        p: DVec3,
        n: DVec3,
        t: f64,
        cx: &mut Ctx,
    ) -> DVec3 {
        if r.flags & SHADOW != 0 {
            return DVec3::ZERO;
        }
        let z = n;
        let x =
            b.up.cross(z)
                .try_normalize()
                .unwrap_or_else(|| z.any_orthonormal_vector());
        let y = z.cross(x);
        let to_local = |w: DVec3| DVec3::new(w.dot(x), w.dot(y), w.dot(z));
        let v = to_local(-r.dir);
        let front = v.z > 0.0;
        let (refl, trans, rd) = if front {
            (b.rf.as_deref(), b.tf.as_deref(), b.rd_front)
        } else {
            (b.rb.as_deref(), b.tb.as_deref(), b.rd_back)
        };
        let td = b.td;
        let side = if front { z } else { -z };
        let lobe = |l: DVec3, omega: f64, ldot: f64| {
            let ll = to_local(l);
            let same = (ll.z > 0.0) == front;
            let f = if same {
                DVec3::splat(refl.map_or(0.0, |c| c.eval(v, ll))) + rd / PI
            } else {
                DVec3::splat(trans.map_or(0.0, |c| c.eval(v, ll))) + td / PI
            };
            f * (ldot.abs() * omega)
        };
        // with thresholding direct light comes last (as in Radiance), otherwise first
        let last = cx.ds.is_some();
        let mut val = if last {
            DVec3::ZERO
        } else {
            self.direct(r, p, side, Some(shape), DVec3::ZERO, cx, lobe)
        };
        for (comp, flag) in [(refl, REFLECTED), (trans, TRANS)] {
            let Some(c) = comp else { continue };
            let (u, u0, u1) = (cx.rng.next_f64(), cx.rng.next_f64(), cx.rng.next_f64());
            if let Some((d, h)) = c.sample(v, u, u0, u1) {
                let dir = (x * d.x + y * d.y + z * d.z).normalize();
                val += self.spawn(r, p, dir, SPECULAR | flag, DVec3::splat(h), shape, t, cx);
            }
        }
        if maxc(rd) > FTINY {
            val += self.ambient(r, p, side, rd, Some(shape), cx);
        }
        if maxc(td) > FTINY {
            val += self.ambient(r, p, -side, td, Some(shape), cx);
        }
        if last {
            val += self.direct(r, p, side, Some(shape), val, cx, lobe);
        }
        val
    }

    #[allow(clippy::too_many_arguments)]
    fn shade_dielectric(
        &self,
        r: &Ray,
        tn: DVec3,
        idx: f64,
        shape: usize,
        p: DVec3,
        n: DVec3,
        rod: f64,
        t: f64,
        cx: &mut Ctx,
    ) -> DVec3 {
        // entering from the front (outside) or leaving from inside
        let entering = rod > 0.0;
        let nrm = if entering { n } else { -n };
        let eta = if entering { 1.0 / idx } else { idx };
        let cos_i = rod.abs();
        // absorption along the segment travelled inside the medium
        let atten = if entering {
            DVec3::ONE
        } else {
            DVec3::new(
                tn.x.max(1e-300).powf(t),
                tn.y.max(1e-300).powf(t),
                tn.z.max(1e-300).powf(t),
            )
        };
        let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
        let refl_dir = (r.dir + nrm * (2.0 * cos_i)).normalize();
        if sin2_t >= 1.0 {
            if r.flags & SHADOW != 0 {
                return DVec3::ZERO;
            }
            return atten * self.spawn(r, p, refl_dir, REFLECTED, DVec3::ONE, shape, t, cx);
        }
        let cos_t = (1.0 - sin2_t).sqrt();
        let rs = ((eta * cos_i - cos_t) / (eta * cos_i + cos_t)).powi(2);
        let rp = ((eta * cos_t - cos_i) / (eta * cos_t + cos_i)).powi(2);
        let fr = 0.5 * (rs + rp);
        let tdir = (r.dir * eta + nrm * (eta * cos_i - cos_t)).normalize();
        let mut val = DVec3::ZERO;
        if r.flags & SHADOW != 0 {
            // a bent shadow ray no longer points at its source, except at index 1
            if (idx - 1.0).abs() < 1e-6 {
                val += self.spawn(r, p, r.dir, TRANS, DVec3::splat(1.0 - fr), shape, t, cx);
            }
            return atten * val;
        }
        val += self.spawn(r, p, tdir, TRANS, DVec3::splat(1.0 - fr), shape, t, cx);
        val += self.spawn(r, p, refl_dir, REFLECTED, DVec3::splat(fr), shape, t, cx);
        atten * val
    }

    #[allow(clippy::too_many_arguments)]
    fn shade_glass(
        &self,
        r: &Ray,
        tn: DVec3,
        idx: f64,
        shape: usize,
        p: DVec3,
        n: DVec3,
        rod: f64,
        t: f64,
        cx: &mut Ctx,
    ) -> DVec3 {
        let pdot = rod.abs().max(1e-3);
        let nrm = if rod < 0.0 { -n } else { n };
        let cos2 = ((1.0 - 1.0 / (idx * idx)) + pdot * pdot / (idx * idx)).sqrt();
        let r1e = ((pdot - idx * cos2) / (pdot + idx * cos2)).powi(2);
        let r1m = ((1.0 / pdot - idx / cos2) / (1.0 / pdot + idx / cos2)).powi(2);
        let mut trans = DVec3::ZERO;
        let mut refl = DVec3::ZERO;
        for c in 0..3 {
            let tau = tn[c].max(1e-15).powf(1.0 / cos2);
            let t2 = tau * tau;
            trans[c] = 0.5 * (1.0 - r1e).powi(2) * tau / (1.0 - r1e * r1e * t2)
                + 0.5 * (1.0 - r1m).powi(2) * tau / (1.0 - r1m * r1m * t2);
            refl[c] = 0.5 * r1e * (1.0 + (1.0 - 2.0 * r1e) * t2) / (1.0 - r1e * r1e * t2)
                + 0.5 * r1m * (1.0 + (1.0 - 2.0 * r1m) * t2) / (1.0 - r1m * r1m * t2);
        }
        let mut val = DVec3::ZERO;
        if maxc(trans) > FTINY {
            val += self.spawn(r, p, r.dir, TRANS, trans, shape, t, cx);
        }
        if r.flags & SHADOW == 0 && maxc(refl) > FTINY {
            let dir = (r.dir + nrm * (2.0 * pdot)).normalize();
            val += self.spawn(r, p, dir, REFLECTED, refl, shape, t, cx);
        }
        val
    }

    #[allow(clippy::too_many_arguments)]
    fn shade_normal(
        &self,
        r: &Ray,
        color: DVec3,
        spec: f64,
        rough: f64,
        trans: f64,
        tspec_frac: f64,
        metal: bool,
        shape: usize,
        p: DVec3,
        n: DVec3,
        rod: f64,
        t: f64,
        cx: &mut Ctx,
    ) -> DVec3 {
        let nrm = if rod < 0.0 { -n } else { n };
        let pdot = rod.abs().max(1e-3);
        let alpha2 = rough * rough;
        let pure = alpha2 <= FTINY;
        let fres = |c: f64| (-5.85 * c).exp() - 0.00287989916;
        let mut rspec = spec;
        let use_fres = pure && spec >= 0.017999;
        if use_fres {
            rspec = spec + fres(pdot) * (1.0 - spec);
        }
        let tt = trans * (1.0 - rspec);
        let tspec = tt * tspec_frac;
        let tdiff = tt - tspec;
        let rdiff = 1.0 - tt - rspec;
        let scolor = if metal {
            if use_fres {
                let f = fres(pdot);
                DVec3::splat(f) + color * spec * (1.0 - f)
            } else {
                color * rspec
            }
        } else {
            DVec3::splat(rspec)
        };
        if r.flags & SHADOW != 0 {
            if tspec > FTINY && pure {
                return self.spawn(r, p, r.dir, TRANS, color * tspec, shape, t, cx);
            }
            return DVec3::ZERO;
        }
        let flat = self.accel.shapes[shape].is_flat();
        let d = r.dir;
        let lobe = |l: DVec3, omega: f64, ldot: f64| {
            let mut c = DVec3::ZERO;
            if ldot > 0.0 {
                let mut dr = rdiff;
                if use_fres {
                    dr *= 1.0 - fres(ldot.abs());
                }
                c += color * (dr * ldot * omega / PI);
                if rspec > FTINY && !pure {
                    let h = l - d;
                    let mut a2 = alpha2;
                    if flat {
                        a2 += omega / (4.0 * PI);
                    }
                    let hn = h.dot(nrm);
                    if hn > 0.0 {
                        let hh = h.dot(h);
                        let tt = (hh - hn * hn) / (hn * hn);
                        let f = (-tt / a2).exp() * hh / (PI * hn.powi(4) * a2);
                        c += scolor * (f * ldot * omega);
                    }
                }
            } else if ldot < 0.0 && tdiff > FTINY {
                c += color * (tdiff * -ldot * omega / PI);
            }
            c
        };
        // With thresholding, direct light comes last, as in Radiance (its threshold is
        // relative to what the surface already returns); otherwise first.
        let last = cx.ds.is_some();
        let mut val = if last {
            DVec3::ZERO
        } else {
            self.direct(r, p, nrm, Some(shape), DVec3::ZERO, cx, lobe)
        };
        if self.effects.specular {
            if rspec > FTINY && pure {
                let dir = (d + nrm * (2.0 * pdot)).normalize();
                val += self.spawn(r, p, dir, REFLECTED, scolor, shape, t, cx);
            } else if rspec > FTINY && self.opts.ss > 0.0 && rspec > self.opts.st {
                // one Ward-lobe sample (isotropic)
                let (u, v) = (cx.rng.next_f64(), cx.rng.next_f64());
                let tan2 = -alpha2 * (1.0 - u).max(1e-300).ln();
                let ct = 1.0 / (1.0 + tan2).sqrt();
                let st = (1.0 - ct * ct).max(0.0).sqrt();
                let (a, b) = frame(nrm);
                let phi = 2.0 * PI * v;
                let h = a * (st * phi.cos()) + b * (st * phi.sin()) + nrm * ct;
                let dir = d - h * (2.0 * d.dot(h));
                if dir.dot(nrm) > 0.0 {
                    val += self.spawn(
                        r,
                        p,
                        dir.normalize(),
                        SPECULAR | REFLECTED,
                        scolor,
                        shape,
                        t,
                        cx,
                    );
                }
            }
            if tspec > FTINY && pure {
                val += self.spawn(r, p, d, TRANS, color * tspec, shape, t, cx);
            }
        }
        if rdiff > FTINY {
            val += self.ambient(r, p, nrm, color * rdiff, Some(shape), cx);
        }
        if tdiff > FTINY {
            val += self.ambient(r, p, -nrm, color * tdiff, Some(shape), cx);
        }
        if last {
            val += self.direct(r, p, nrm, Some(shape), val, cx, lobe);
        }
        val
    }

    /// Direct lighting at `p` (normal `nrm`): `bsdf(l, omega, ldot)` gives the coefficient
    /// of a source sample; a shadow ray fetches the source's radiance. With source
    /// thresholding (`-dt > 0`, a [`DirectState`] in `cx`), only the brightest samples are
    /// shadow-tested ([`Self::direct_threshold`]); `prior` is what the surface already
    /// returns from its other components (Radiance computes direct light last).
    #[allow(clippy::too_many_arguments)]
    fn direct(
        &self,
        r: &Ray,
        p: DVec3,
        nrm: DVec3,
        shape: Option<usize>,
        prior: DVec3,
        cx: &mut Ctx,
        bsdf: impl Fn(DVec3, f64, f64) -> DVec3,
    ) -> DVec3 {
        let mut val = DVec3::ZERO;
        if !self.effects.direct {
            return val;
        }
        if cx.ds.is_some() {
            return self.direct_threshold(r, p, nrm, shape, prior, cx, bsdf);
        }
        let skip = shape.filter(|&s| self.accel.shapes[s].is_flat());
        for si in 0..self.sources.len() {
            self.each_sample(si, p, shape, r.weight, cx, |cx, s| {
                let ldot = s.l.dot(nrm);
                self.shadow(
                    r,
                    p,
                    s.l,
                    s.tmax,
                    si,
                    skip,
                    bsdf(s.l, s.omega, ldot),
                    &mut val,
                    cx,
                );
            });
        }
        val
    }

    /// Calls `f` for every sample of source `si` seen from `p` (on surface `shape`): its
    /// unit direction, solid angle, shadow-ray length and the number of samples drawn
    /// for the source. Samples are drawn (random numbers used) before the first call.
    /// `weight` is the weight of the ray that reached `p` (a cylinder's `-ds` subdivision
    /// depends on it, as in Radiance).
    fn each_sample(
        &self,
        si: usize,
        p: DVec3,
        shape: Option<usize>,
        weight: f64,
        cx: &mut Ctx,
        mut f: impl FnMut(&mut Ctx, SourceSample),
    ) {
        let s = &self.sources[si];
        match s.geom {
            SourceGeom::Distant(k) => {
                let d = &self.distant[k];
                let l = self.jitter_cone(d.dir, d.cos_half, cx);
                f(
                    cx,
                    SourceSample {
                        l,
                        omega: d.omega,
                        tmax: f64::INFINITY,
                        count: 1,
                    },
                );
            }
            SourceGeom::Virtual { base, mirror, dir } => {
                if Some(mirror) == shape {
                    return;
                }
                let SourceGeom::Distant(k) = self.sources[base].geom else {
                    return;
                };
                let d = &self.distant[k];
                let l = self.jitter_cone(dir, d.cos_half, cx);
                f(
                    cx,
                    SourceSample {
                        l,
                        omega: d.omega,
                        tmax: f64::INFINITY,
                        count: 1,
                    },
                );
            }
            SourceGeom::Local(sh) => {
                if Some(sh) == shape {
                    return;
                }
                let (maxrad, focus, spot) = match &self.mats[&s.mat] {
                    Material::Light {
                        kind: LightKind::Glow(rad),
                        ..
                    } => (*rad, 0.0, None),
                    Material::Light {
                        kind: LightKind::Spot(cosang, aim, flen),
                        ..
                    } => (f64::INFINITY, *flen, Some((*cosang, *aim))),
                    _ => (f64::INFINITY, 0.0, None),
                };
                // `beyond`: how far past the sample point its shadow ray may still meet the
                // source (a cylinder's sample can lie off its surface)
                let mut emit = |cx: &mut Ctx, q: DVec3, omega: f64, count: usize, beyond: f64| {
                    let v = q - p;
                    let dist = v.length();
                    if dist <= 0.0 || dist > maxrad || omega <= 0.0 {
                        return;
                    }
                    // a sample outside a spotlight's cone is dropped before any shadow ray
                    // (as Radiance's srcray; rcontrib would otherwise record the ray)
                    if let Some((cosang, aim)) = spot {
                        if -(v / dist).dot(aim) < cosang {
                            return;
                        }
                    }
                    // a spotlight's light comes from its focus, `focus` behind the source
                    // (Radiance scales the sample's solid angle so)
                    let omega = if focus > 0.0 {
                        omega * (dist / (dist + focus)).powi(2)
                    } else {
                        omega
                    };
                    f(
                        cx,
                        SourceSample {
                            l: v / dist,
                            omega,
                            tmax: dist * (1.0 + 1e-7) + beyond + Self::tmin(q),
                            count,
                        },
                    );
                };
                if let Some(cyl) = &s.cyl {
                    let parts = cyl.partitions(p, self.opts.ds, weight);
                    let count = parts.len();
                    let samples: Vec<(DVec3, f64)> = parts
                        .into_iter()
                        .filter_map(|(cent, size)| {
                            let jit = if self.opts.dj > 0.0 {
                                let u = [cx.rng.next_f64(), cx.rng.next_f64(), cx.rng.next_f64()];
                                Some((self.opts.dj, u))
                            } else {
                                None
                            };
                            cyl.sample(p, cent, size, jit)
                        })
                        .collect();
                    for (q, omega) in samples {
                        emit(cx, q, omega, count, cyl.beyond());
                    }
                    return;
                }
                if let Some(flat) = &s.flat {
                    let parts = flat.partitions(p, self.opts.ds, weight);
                    let count = parts.len();
                    let samples: Vec<(DVec3, f64)> = parts
                        .into_iter()
                        .filter_map(|part| {
                            let jit = if self.opts.dj > 0.0 {
                                let u = [cx.rng.next_f64(), cx.rng.next_f64()];
                                Some((self.opts.dj, u))
                            } else {
                                None
                            };
                            flat.sample(p, part, count, jit)
                        })
                        .collect();
                    for (q, omega) in samples {
                        emit(cx, q, omega, count, 0.0);
                    }
                    return;
                }
                if let Shape::Sphere { c, r, .. } = &self.accel.shapes[sh] {
                    if let Some(omega) = Self::sphere_omega(*c, *r, p) {
                        emit(cx, *c, omega, 1, 0.0);
                    }
                }
            }
        }
    }

    /// A direction toward a distant source: its centre, or with `-dj` a point jittered
    /// within the source's cone.
    fn jitter_cone(&self, dir: DVec3, cos_half: f64, cx: &mut Ctx) -> DVec3 {
        if self.opts.dj <= 0.0 {
            return dir;
        }
        let (u, v) = (cx.rng.next_f64(), cx.rng.next_f64());
        let ct = 1.0 - self.opts.dj * u * (1.0 - cos_half);
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let (a, b) = frame(dir);
        let ph = 2.0 * PI * v;
        (a * (st * ph.cos()) + b * (st * ph.sin()) + dir * ct).normalize()
    }

    /// A shadow ray meeting a mirror: if it is aimed at that mirror's image of a distant
    /// source, it continues, reflected, toward the real source (weighted by the mirror's
    /// colour); any other shadow ray is stopped.
    #[allow(clippy::too_many_arguments)]
    fn relay(
        &self,
        r: &Ray,
        shape: usize,
        p: DVec3,
        n: DVec3,
        rod: f64,
        t: f64,
        color: DVec3,
        cx: &mut Ctx,
    ) -> DVec3 {
        let Some(SourceGeom::Virtual { base, mirror, .. }) = r.src.map(|s| self.sources[s].geom)
        else {
            return DVec3::ZERO;
        };
        if mirror != shape {
            return DVec3::ZERO;
        }
        let nrm = if rod < 0.0 { -n } else { n };
        let dir = (r.dir + nrm * (2.0 * rod.abs())).normalize();
        let SourceGeom::Distant(k) = self.sources[base].geom else {
            return DVec3::ZERO;
        };
        if self.distant[k].dir.dot(nrm) <= 0.0 {
            return DVec3::ZERO;
        }
        let mut c = self.child(r, p, dir, 0, color, Some(shape), t);
        c.weight = r.weight;
        c.src = Some(base);
        color * self.trace(&c, cx)
    }

    #[allow(clippy::too_many_arguments)]
    fn shadow(
        &self,
        r: &Ray,
        p: DVec3,
        l: DVec3,
        tmax: f64,
        si: usize,
        skip: Option<usize>,
        coef: DVec3,
        val: &mut DVec3,
        cx: &mut Ctx,
    ) {
        // as Radiance's direct(): any sample with a positive coefficient is tested (a
        // grazing part of a subdivided source can have a coefficient below 1e-6)
        if maxc(coef) <= 0.0 {
            return;
        }
        let c = self.shadow_ray(r, p, l, tmax, si, skip, coef);
        *val += coef * self.trace(&c, cx);
    }

    /// The shadow ray from `p` (on surface `skip`, if flat) along `l` toward source `si`,
    /// `tmax` long, with coefficient `coef`. Radiance starts shadow rays without a
    /// coefficient: they keep the parent's weight and are never subject to Russian
    /// roulette.
    #[allow(clippy::too_many_arguments)]
    fn shadow_ray(
        &self,
        r: &Ray,
        p: DVec3,
        l: DVec3,
        tmax: f64,
        si: usize,
        skip: Option<usize>,
        coef: DVec3,
    ) -> Ray {
        let mut c = self.child(r, p, l, SHADOW, coef, skip, 0.0);
        c.weight = r.weight;
        c.src = Some(si);
        c.tmax = tmax;
        c
    }

    /// Solid angle of a sphere (centre `c`, radius `r`) seen from `p` outside it.
    fn sphere_omega(c: DVec3, r: f64, p: DVec3) -> Option<f64> {
        let d2 = (c - p).length_squared();
        if d2 <= r * r {
            return None;
        }
        Some(2.0 * PI * (1.0 - (1.0 - r * r / d2).max(0.0).sqrt()))
    }

    /// Indirect diffuse light by stratified cosine-weighted hemisphere sampling (`-aa 0`),
    /// multiplied by `rcol` (the surface's diffuse colour × reflectance).
    fn ambient(
        &self,
        r: &Ray,
        p: DVec3,
        nrm: DVec3,
        rcol: DVec3,
        shape: Option<usize>,
        cx: &mut Ctx,
    ) -> DVec3 {
        if !self.effects.ambient || r.amb >= self.opts.ab {
            return rcol * DVec3::from_array(self.opts.av);
        }
        let ad = self.opts.ad as f64;
        // n = round(sqrt(ad · min(weight, d))) ≥ 1; below ad · weight = 2.25 it is 1 whatever
        // d is (the usual case past the first bounce), without the division and the root
        let (n, wt) = if ad * r.weight < 2.25 {
            (1, r.weight)
        } else {
            let mut wt = r.weight;
            let d = 0.8 * maxc(rcol) * r.weight / (ad * self.opts.lw);
            if wt > d {
                wt = d;
            }
            ((((ad * wt).sqrt() + 0.5) as usize).max(1), wt)
        };
        let (a, b) = frame(nrm);
        let skip = shape.filter(|&s| self.accel.shapes[s].is_flat());
        let shoot = |dir: DVec3, acoef: DVec3, cx: &mut Ctx| {
            let mut rc = acoef;
            let mut c = self.child(r, p, dir, AMBIENT, rc, skip, 0.0);
            c.amb = r.amb + 1;
            if !self.admit(&mut c, &mut rc, cx) {
                return DVec3::ZERO;
            }
            rc * self.trace(&c, cx)
        };
        let direction = |x: f64, y: f64| {
            let (u, v) = square_to_disk(x, y);
            let z = (1.0 - u * u - v * v).max(0.0).sqrt();
            // unit to within rounding (u² + v² + z² = 1 over an orthonormal frame)
            a * u + b * v + nrm * z
        };
        if n == 1 {
            // one stratum: the unit square itself (no division by 1, no batch)
            let (x, y) = (cx.rng.next_f64(), cx.rng.next_f64());
            return shoot(direction(x, y), rcol, cx);
        }
        let acoef = rcol / (n * n) as f64;
        let mut sum = DVec3::ZERO;
        // Directions are drawn a batch at a time (stratum by stratum, row-major), then
        // traced: the batch's arithmetic runs without waiting on each ray's tracing.
        let nf = n as f64;
        // a jittered direction in stratum (row i, column j)
        let stratum = |i: usize, j: usize, cx: &mut Ctx| {
            let x = (j as f64 + cx.rng.next_f64()) / nf;
            let y = (i as f64 + cx.rng.next_f64()) / nf;
            direction(x, y)
        };
        let total = n * n;
        // -as: extra samples where the neighbouring strata vary most (Radiance's rtrace does
        // it for hemispheres of more than 4×4 strata and more than 8 extra samples)
        let extra = (self.opts.asamp as f64 * wt + 0.5) as usize;
        let keep = n > 4 && extra > 8;
        let mut vals = Vec::with_capacity(if keep { total } else { 0 });
        let (mut i, mut j) = (0usize, 0usize);
        let mut dirs = [DVec3::ZERO; AMB_BATCH];
        let mut done = 0;
        while done < total {
            let m = (total - done).min(AMB_BATCH);
            for d in dirs.iter_mut().take(m) {
                *d = stratum(i, j, cx);
                j += 1;
                if j == n {
                    j = 0;
                    i += 1;
                }
            }
            for &dir in &dirs[..m] {
                let v = shoot(dir, acoef, cx);
                if keep {
                    vals.push(v);
                }
                sum += v;
            }
            done += m;
        }
        if keep {
            sum = super_sample(&mut vals, n, extra, cx, |i, j, cx| {
                shoot(stratum(i, j, cx), acoef, cx)
            });
        }
        sum
    }
}

/// Ambient super-sampling (`-as`): `vals` holds one sample per stratum of an n×n hemisphere
/// (row-major). A stratum's need is the variance of its (up to 4) neighbours' samples —
/// not its own, so that the decision to add samples to a stratum does not depend on the
/// sample it is averaged with (which would bias the stratum's mean). `extra` samples are
/// spread in proportion to need, stratum by stratum (⌊need·left/need_left + u⌋, u
/// uniform), drawn with `sample(i, j)` and averaged with the first. Returns the sum over
/// the strata.
fn super_sample(
    vals: &mut [DVec3],
    n: usize,
    extra: usize,
    cx: &mut Ctx,
    mut sample: impl FnMut(usize, usize, &mut Ctx) -> DVec3,
) -> DVec3 {
    let bright = |c: DVec3| (c.x + c.y + c.z) / 3.0;
    let mut need = vec![0.0f64; vals.len()];
    for i in 0..n {
        for j in 0..n {
            let k = i * n + j;
            let mut nb = [0.0f64; 4];
            let mut m = 0;
            for (ok, q) in [
                (j > 0, k.wrapping_sub(1)),
                (j + 1 < n, k + 1),
                (i > 0, k.wrapping_sub(n)),
                (i + 1 < n, k + n),
            ] {
                if ok {
                    nb[m] = bright(vals[q]);
                    m += 1;
                }
            }
            let mean = nb[..m].iter().sum::<f64>() / m as f64;
            need[k] = nb[..m].iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (m - 1) as f64;
        }
    }
    let mut need_left: f64 = need.iter().sum();
    let mut left = extra as f64;
    for k in 0..vals.len() {
        if need_left <= 1e-300 || left < 1.0 {
            break;
        }
        let nss = (need[k] * left / need_left + cx.rng.next_f64()) as usize;
        need_left -= need[k];
        if nss < 1 {
            continue;
        }
        left -= nss as f64;
        let mut acc = vals[k];
        for _ in 0..nss {
            acc += sample(k / n, k % n, cx);
        }
        vals[k] = acc / (nss + 1) as f64;
    }
    vals.iter().copied().sum()
}

/// Ambient directions drawn ahead of tracing (see [`Tracer::ambient`]).
const AMB_BATCH: usize = 16;

/// Shirley–Chiu concentric map of the unit square onto the unit disk.
fn square_to_disk(x: f64, y: f64) -> (f64, f64) {
    let (a, b) = (2.0 * x - 1.0, 2.0 * y - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    // one division and selects instead of branches (the branch is a coin toss); the angle
    // is q (|q| ≤ π/4) or π/2 − q, whose cosine and sine are q's sine and cosine
    let outer_a = a * a > b * b;
    let (r, num) = if outer_a { (a, b) } else { (b, a) };
    let q = (PI / 4.0) * (num / r);
    let (s, c) = sin_cos_quarter(q);
    if outer_a {
        (r * c, r * s)
    } else {
        (r * s, r * c)
    }
}

/// Sine and cosine of |x| ≤ π/4 by their Taylor series to x¹⁵ and x¹⁶ (truncation below
/// 7e-17 and 3e-18; within 2 ulp of the correctly rounded values, checked in the tests),
/// evaluated by Estrin's scheme (three dependent steps instead of eight): no call and no
/// branch, unlike the library's general-argument routine.
fn sin_cos_quarter(x: f64) -> (f64, f64) {
    let y = x * x;
    let y2 = y * y;
    let y4 = y2 * y2;
    // sin x = x + x·y·(s0 + s1 y + … + s6 y⁶), s_k = (−1)^(k+1) / (2k+3)!
    const S: [f64; 7] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
    ];
    // cos x = 1 − y·(c0 + c1 y + … + c7 y⁷), c_k = (−1)^k / (2k+2)!
    const C: [f64; 8] = [
        0.5,
        -1.0 / 24.0,
        1.0 / 720.0,
        -1.0 / 40_320.0,
        1.0 / 3_628_800.0,
        -1.0 / 479_001_600.0,
        1.0 / 87_178_291_200.0,
        -1.0 / 20_922_789_888_000.0,
    ];
    let ps = (S[0] + S[1] * y + (S[2] + S[3] * y) * y2) + (S[4] + S[5] * y + S[6] * y2) * y4;
    let pc = (C[0] + C[1] * y + (C[2] + C[3] * y) * y2)
        + (C[4] + C[5] * y + (C[6] + C[7] * y) * y2) * y4;
    (x + x * y * ps, 1.0 - y * pc)
}

/// Two unit vectors completing `n` to an orthonormal frame.
fn frame(n: DVec3) -> (DVec3, DVec3) {
    let a = n.any_orthonormal_vector();
    (a, n.cross(a))
}

/// What a ray hits first (rtrace `-ol -op -on`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FirstHit {
    /// Distance (1e10 for a distant source or nothing).
    pub t: f64,
    /// Hit point (the origin when nothing was hit).
    pub point: DVec3,
    /// Surface normal as stored on the ray: geometric normal, flipped for materials that
    /// face the ray (plastic, metal, trans, glass, mirror), as Radiance reports it.
    pub normal: DVec3,
    /// Scene index of the surface, if any.
    pub prim: Option<usize>,
}

impl Tracer {
    /// The first surface along a ray.
    pub fn first_hit(&self, org: DVec3, dir: DVec3) -> FirstHit {
        let d = dir.normalize_or_zero();
        match self
            .accel
            .closest(org, d, Self::tmin(org), f64::INFINITY, None)
        {
            Some(h) => {
                let p = org + d * h.t;
                let mut n = self.accel.shapes[h.shape].normal(p);
                if !self.mats[&self.surf_mat[h.shape]].is_light() && n.dot(d) > 0.0 {
                    n = -n;
                }
                FirstHit {
                    t: h.t,
                    point: p,
                    normal: n,
                    prim: Some(self.surf_prim[h.shape]),
                }
            }
            None => FirstHit {
                t: 1e10,
                point: org,
                normal: -d,
                prim: None,
            },
        }
    }

    /// Irradiance at the first surface along a ray that is not passed (rtrace `-i`), as
    /// Radiance's irradiance hack: the ray is traced as usual (antimatter clip sets
    /// included) and passes straight through trans, trans2, dielectric, interface, mist,
    /// glass and aBSDF surfaces and BSDF proxies; an emitter or the sky gives its radiance
    /// (an illum passes it on to its alternate material); any other surface gives the
    /// irradiance there, on its side facing the ray, with a Lambertian of reflectance π.
    pub fn irradiance_at_hit(&self, ray_index: u64, org: DVec3, dir: DVec3) -> [f64; 3] {
        self.irradiance_at_hit_with(&mut self.direct_state(), ray_index, org, dir)
    }

    /// As [`irradiance_at_hit`](Self::irradiance_at_hit) with a source-thresholding state
    /// (see [`radiance_with`](Self::radiance_with)).
    pub fn irradiance_at_hit_with(
        &self,
        st: &mut DirectState,
        ray_index: u64,
        org: DVec3,
        dir: DVec3,
    ) -> [f64; 3] {
        let d = dir.normalize_or_zero();
        if d == DVec3::ZERO {
            return [0.0; 3];
        }
        let r = Ray {
            flags: IRRAD,
            ..Self::primary(org, d)
        };
        self.run(&r, self.ctx(ray_index, &[], None, self.state_for(st)))
    }

    /// As [`contributions_limited`](Self::contributions_limited) for rcontrib `-i`: the
    /// ray as in [`irradiance_at_hit`](Self::irradiance_at_hit), ending after `len`
    /// (`f64::INFINITY` without `-ld+`).
    pub fn contributions_irradiance_at_hit(
        &self,
        ray_index: u64,
        org: DVec3,
        dir: DVec3,
        len: f64,
        tracked: &[bool],
        sink: &mut impl FnMut(Contribution),
    ) -> [f64; 3] {
        self.contributions_flagged(ray_index, org, dir, len, IRRAD, tracked, sink)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_sin_cos_within_two_ulp() {
        let ulp = |v: f64| f64::EPSILON * v.abs().max(f64::MIN_POSITIVE);
        let mut worst: f64 = 0.0;
        for k in -100_000..=100_000 {
            let x = (PI / 4.0) * k as f64 / 100_000.0;
            let (s, c) = sin_cos_quarter(x);
            let es = (s - x.sin()).abs() / ulp(x.sin());
            let ec = (c - x.cos()).abs() / ulp(x.cos());
            worst = worst.max(es).max(ec);
        }
        assert!(worst <= 2.0, "{worst} ulp");
    }

    #[test]
    fn super_sampling_keeps_the_mean_and_lowers_the_spread() {
        // 8×8 strata: a bright disc (value 10) on a dark background (1), each sample
        // uniform ±100% noise around its stratum's value: the true sum is known
        let n = 8;
        let truth = |i: usize, j: usize| {
            let (x, y) = (i as f64 - 2.0, j as f64 - 5.0);
            if x * x + y * y < 5.0 {
                10.0
            } else {
                1.0
            }
        };
        let exact: f64 = (0..n * n).map(|k| truth(k / n, k % n)).sum();
        let run = |seed: u64, extra: usize| {
            let mut cx = Ctx {
                rng: Rng::for_ray(seed, 0),
                rays: 0,
                tracked: &[],
                sink: None,
                ds: None,
            };
            let draw = |i: usize, j: usize, cx: &mut Ctx| {
                DVec3::splat(truth(i, j) * 2.0 * cx.rng.next_f64())
            };
            let mut vals: Vec<DVec3> = (0..n * n).map(|k| draw(k / n, k % n, &mut cx)).collect();
            if extra == 0 {
                return vals.iter().map(|v| v.x).sum::<f64>();
            }
            super_sample(&mut vals, n, extra, &mut cx, draw).x
        };
        let stats = |extra: usize| {
            let xs: Vec<f64> = (0..4000).map(|s| run(s, extra)).collect();
            let m = xs.iter().sum::<f64>() / xs.len() as f64;
            let var = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (xs.len() - 1) as f64;
            (m, var)
        };
        let (m0, v0) = stats(0);
        let (m1, v1) = stats(64);
        // means within 4 standard errors of the exact sum
        assert!(
            (m0 - exact).abs() < 4.0 * (v0 / 4000.0).sqrt(),
            "{m0} {exact}"
        );
        assert!(
            (m1 - exact).abs() < 4.0 * (v1 / 4000.0).sqrt(),
            "{m1} {exact}"
        );
        // the extra samples go where the disc's edge is: the spread drops well below the
        // 1/2 that 64 evenly spread extra samples would give at best
        assert!(v1 < 0.5 * v0, "{v1} {v0}");
    }

    #[test]
    fn concentric_map_equals_its_library_trig_form() {
        let mut rng = Rng::for_ray(1, 2);
        for _ in 0..100_000 {
            let (x, y) = (rng.next_f64(), rng.next_f64());
            let (u, v) = square_to_disk(x, y);
            let (a, b) = (2.0 * x - 1.0, 2.0 * y - 1.0);
            let (r, phi) = if a * a > b * b {
                (a, (PI / 4.0) * (b / a))
            } else {
                (b, PI / 2.0 - (PI / 4.0) * (a / b))
            };
            assert!((u - r * phi.cos()).abs() < 1e-15, "{x} {y}");
            assert!((v - r * phi.sin()).abs() < 1e-15, "{x} {y}");
        }
    }
}
