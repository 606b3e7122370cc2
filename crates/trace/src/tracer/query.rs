//! The tracer's entry points: radiance along a ray, irradiance at a point, rcontrib's
//! contributions, and first-hit queries (rtrace `-o l p n`, `-i`).

use super::*;

impl Tracer {
    pub(super) fn primary(org: DVec3, dir: DVec3) -> Ray {
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

    /// Radiance along a ray traced as Radiance's mkillum traces its sample rays (primary and
    /// specular): light sources are not seen directly (they are sampled explicitly, mkillum's
    /// `l+`), glows and everything they light are.
    pub fn radiance_specular(&self, ray_index: u64, org: DVec3, dir: DVec3) -> [f64; 3] {
        let cx = self.ctx(ray_index, &[], None, None);
        let d = dir.normalize_or_zero();
        if d == DVec3::ZERO {
            return [0.0; 3];
        }
        let mut r = Self::primary(org, d);
        r.flags = SPECULAR;
        self.run(&r, cx)
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
        self.contributions_flagged(ray_index, (org, dir, len), 0, tracked, sink)
    }

    /// The primary ray (origin, direction, length) of rcontrib's normal (`flags` 0) and
    /// `-i` (`IRRAD`) modes, traced with `sink` receiving the tracked contributions.
    pub(super) fn contributions_flagged(
        &self,
        ray_index: u64,
        (org, dir, len): (DVec3, DVec3, f64),
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
    pub(super) fn ctx<'a>(
        &self,
        ray_index: u64,
        tracked: &'a [bool],
        sink: Option<&'a mut dyn FnMut(Contribution)>,
        ds: Option<&'a mut DirectState>,
    ) -> Ctx<'a> {
        Ctx {
            rng: Rng::for_ray(self.opts.seed, ray_index),
            rays: [0; 4],
            tracked,
            sink,
            ds,
        }
    }

    /// Traces the primary ray `r` in `cx` and adds its rays to the tracer's count.
    pub(super) fn run(&self, r: &Ray, mut cx: Ctx) -> [f64; 3] {
        let v = self.trace(r, &mut cx);
        self.count(&cx);
        v.to_array()
    }

    /// Irradiance at `p` facing unit `n` in `cx`, counting its rays.
    pub(super) fn run_irradiance(&self, p: DVec3, n: DVec3, mut cx: Ctx) -> [f64; 3] {
        let v = self.irradiance_in(p, n, &mut cx);
        self.count(&cx);
        v.to_array()
    }

    pub(super) fn count(&self, cx: &Ctx) {
        for (total, n) in self.rays.iter().zip(cx.rays) {
            total.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
        }
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
    pub(super) fn irradiance_in(&self, p: DVec3, n: DVec3, cx: &mut Ctx) -> DVec3 {
        // Radiance's -I: a Lambertian of reflectance pi at the point, seen along -n.
        let r = Ray {
            org: p + n * 1e-5,
            dir: -n,
            ..Self::primary(p, -n)
        };
        self.lambert(&r, p, n, None, cx)
    }
}

/// What a ray hits first (rtrace `-ol -op -on`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FirstHit {
    /// Distance (1e10 for a distant source or nothing).
    pub t: f64,
    /// Hit point (the origin when nothing was hit).
    pub point: DVec3,
    /// Surface normal as stored on the ray: geometric normal, flipped for materials that
    /// face the ray (plastic, metal, trans, glass, mirror), as Radiance reports it (`-on`);
    /// the reversed ray direction on a distant source, zero when nothing is hit.
    pub normal: DVec3,
    /// The surface's own normal, not flipped toward the ray (`-oN`: outward for a sphere,
    /// cylinder or cone, inward for a bubble, tube or cup, a polygon's by its winding);
    /// the reversed ray direction on a distant source, zero when nothing is hit.
    pub geometric: DVec3,
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
                let g = self.accel.shapes[h.shape].normal(p);
                let mut n = g;
                if !self.mats[&self.surf_mat[h.shape]].is_light() && n.dot(d) > 0.0 {
                    n = -n;
                }
                FirstHit {
                    t: h.t,
                    point: p,
                    normal: n,
                    geometric: g,
                    prim: Some(self.surf_prim[h.shape]),
                }
            }
            None => {
                // a distant source faces the ray (Radiance's); nothing at all has no normal
                let n = if d != DVec3::ZERO && self.find_distant(d).is_some() {
                    -d
                } else {
                    DVec3::ZERO
                };
                FirstHit {
                    t: 1e10,
                    point: org,
                    normal: n,
                    geometric: n,
                    prim: None,
                }
            }
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
        self.contributions_flagged(ray_index, (org, dir, len), IRRAD, tracked, sink)
    }
}

/// One light-source sample seen from a point: what reaches the point from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SourceLight {
    /// Unit direction from the point toward the sample.
    pub dir: DVec3,
    /// Solid angle the sample stands for.
    pub omega: f64,
    /// Radiance arriving along the shadow ray (the source's, through whatever transmits).
    pub value: [f64; 3],
}

impl Tracer {
    /// Every light-source sample from `p` (as Radiance's `srcray` loop): its direction, solid
    /// angle and the radiance its shadow ray brings back (zero when blocked). mkillum's
    /// `l+` adds these to its distribution. Random numbers (source jitter) come from the
    /// stream of `ray_index`.
    pub fn source_light(&self, ray_index: u64, p: DVec3) -> Vec<SourceLight> {
        let mut cx = self.ctx(ray_index, &[], None, None);
        let r = Self::primary(p, DVec3::Z);
        let mut out = Vec::new();
        for si in 0..self.sources.len() {
            self.each_sample(si, p, None, 1.0, &mut cx, |cx, s| {
                let aim = Aim {
                    l: s.l,
                    tmax: s.tmax,
                    si,
                };
                let c = self.shadow_ray(&r, Origin::at(p, None), aim, DVec3::ONE);
                let v = self.trace(&c, cx);
                out.push(SourceLight {
                    dir: s.l,
                    omega: s.omega,
                    value: v.to_array(),
                });
            });
        }
        self.count(&cx);
        out
    }
}
