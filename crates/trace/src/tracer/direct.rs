//! Direct lighting: sampling light sources (distant, sphere, flat, cylinder), shadow rays
//! and their relay through transmitting surfaces.

use super::*;

/// A surface point lit by sources: the point, the normal of the side lit, and the
/// surface, if any (the `-I` point is on none).
#[derive(Debug, Clone, Copy)]
pub(super) struct Lit {
    pub(super) p: DVec3,
    pub(super) n: DVec3,
    pub(super) shape: Option<usize>,
}

impl Lit {
    /// A point on surface `shape`.
    pub(super) fn on(p: DVec3, n: DVec3, shape: usize) -> Lit {
        Lit {
            p,
            n,
            shape: Some(shape),
        }
    }
}

/// Where a shadow ray goes: its unit direction, its length and the source it is aimed at.
#[derive(Debug, Clone, Copy)]
pub(super) struct Aim {
    pub(super) l: DVec3,
    pub(super) tmax: f64,
    pub(super) si: usize,
}

impl Tracer {
    /// Direct lighting at `p` (normal `nrm`): `bsdf(l, omega, ldot)` gives the coefficient
    /// of a source sample; a shadow ray fetches the source's radiance. With source
    /// thresholding (`-dt > 0`, a [`DirectState`] in `cx`), only the brightest samples are
    /// shadow-tested ([`Self::direct_threshold`]); `prior` is what the surface already
    /// returns from its other components (Radiance computes direct light last).
    pub(super) fn direct(
        &self,
        r: &Ray,
        lit: Lit,
        prior: DVec3,
        cx: &mut Ctx,
        bsdf: impl Fn(DVec3, f64, f64) -> DVec3,
    ) -> DVec3 {
        let mut val = DVec3::ZERO;
        if !self.effects.direct {
            return val;
        }
        if cx.ds.is_some() {
            return self.direct_threshold(r, lit, prior, cx, bsdf);
        }
        let Lit { p, n: nrm, shape } = lit;
        let skip = shape.filter(|&s| self.accel.shapes[s].is_flat());
        for si in 0..self.sources.len() {
            self.each_sample(si, p, shape, r.weight, cx, |cx, s| {
                let ldot = s.l.dot(nrm);
                let aim = Aim {
                    l: s.l,
                    tmax: s.tmax,
                    si,
                };
                self.shadow(
                    r,
                    Origin::at(p, skip),
                    aim,
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
    pub(super) fn each_sample(
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
                let l = self.jitter_cone(d.dir, d.frame, d.cos_half, cx);
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
                let l = if self.opts.dj > 0.0 {
                    self.jitter_cone(dir, frame(dir), d.cos_half, cx)
                } else {
                    dir
                };
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
                // a cylinder's or flat source's samples, all drawn before the first is used
                let (samples, count, beyond): (Vec<(DVec3, f64)>, usize, f64) =
                    if let Some(cyl) = &s.cyl {
                        let parts = cyl.partitions(p, self.opts.ds, weight);
                        let count = parts.len();
                        let samples = parts
                            .into_iter()
                            .filter_map(|(cent, size)| {
                                cyl.sample(p, cent, size, self.sample_jitter(cx))
                            })
                            .collect();
                        (samples, count, cyl.beyond())
                    } else if let Some(flat) = &s.flat {
                        let parts = flat.partitions(p, self.opts.ds, weight);
                        let count = parts.len();
                        let samples = parts
                            .into_iter()
                            .filter_map(|part| flat.sample(p, part, count, self.sample_jitter(cx)))
                            .collect();
                        (samples, count, 0.0)
                    } else {
                        if let Shape::Sphere { c, r, .. } = &self.accel.shapes[sh] {
                            if let Some(omega) = Self::sphere_omega(*c, *r, p) {
                                emit(cx, *c, omega, 1, 0.0);
                            }
                        }
                        return;
                    };
                for (q, omega) in samples {
                    emit(cx, q, omega, count, beyond);
                }
            }
        }
    }

    /// With `-dj`, it and `N` uniform numbers to jitter a source sample by; else None.
    #[inline]
    fn sample_jitter<const N: usize>(&self, cx: &mut Ctx) -> Option<(f64, [f64; N])> {
        if self.opts.dj > 0.0 {
            let mut u = [0.0; N];
            for x in &mut u {
                *x = cx.rng.next_f64();
            }
            Some((self.opts.dj, u))
        } else {
            None
        }
    }

    /// A direction toward a distant source: its centre, or with `-dj` a point drawn
    /// uniformly (by solid angle) within the fraction `-dj` of the source's cone
    /// ([`cone_direction`]); `frame` completes `dir` to an orthonormal basis.
    pub(super) fn jitter_cone(
        &self,
        dir: DVec3,
        frame: (DVec3, DVec3),
        cos_half: f64,
        cx: &mut Ctx,
    ) -> DVec3 {
        if self.opts.dj <= 0.0 {
            return dir;
        }
        let (u, v) = (cx.rng.next_f64(), cx.rng.next_f64());
        cone_direction(dir, frame, self.opts.dj * (1.0 - cos_half), u, v)
    }

    /// A shadow ray meeting a mirror: if it is aimed at that mirror's image of a distant
    /// source, it continues, reflected, toward the real source (weighted by the mirror's
    /// colour); any other shadow ray is stopped.
    pub(super) fn relay(&self, r: &Ray, s: &Surf, color: DVec3, cx: &mut Ctx) -> DVec3 {
        let Surf {
            shape,
            p,
            n,
            rod,
            t,
        } = *s;
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
        let from = Origin {
            p,
            skip: Some(shape),
            dist: t,
        };
        let mut c = self.child(r, from, dir, 0, color);
        c.weight = r.weight;
        c.src = Some(base);
        color * self.trace(&c, cx)
    }

    pub(super) fn shadow(
        &self,
        r: &Ray,
        from: Origin,
        aim: Aim,
        coef: DVec3,
        val: &mut DVec3,
        cx: &mut Ctx,
    ) {
        // as Radiance's direct(): any sample with a positive coefficient is tested (a
        // grazing part of a subdivided source can have a coefficient below 1e-6)
        if maxc(coef) <= 0.0 {
            return;
        }
        let c = self.shadow_ray(r, from, aim, coef);
        *val += coef * self.trace(&c, cx);
    }

    /// The shadow ray from `from` along `aim` toward its source, with coefficient `coef`.
    /// Radiance starts shadow rays without a coefficient: they keep the parent's weight
    /// and are never subject to Russian roulette.
    pub(super) fn shadow_ray(&self, r: &Ray, from: Origin, aim: Aim, coef: DVec3) -> Ray {
        let mut c = self.child(r, from, aim.l, SHADOW, coef);
        c.weight = r.weight;
        c.src = Some(aim.si);
        c.tmax = aim.tmax;
        c
    }

    /// Solid angle of a sphere (centre `c`, radius `r`) seen from `p` outside it.
    pub(super) fn sphere_omega(c: DVec3, r: f64, p: DVec3) -> Option<f64> {
        let d2 = (c - p).length_squared();
        if d2 <= r * r {
            return None;
        }
        Some(2.0 * PI * (1.0 - (1.0 - r * r / d2).max(0.0).sqrt()))
    }
}

/// The direction of a cap about unit `dir` (frame `a`, `b`) of solid angle 2π·`k` for the
/// unit-square point (`u`, `v`), uniform by solid angle. The point (x, y) of the unit disk
/// (concentric map) gives the angle from the axis, 1 − cos θ = w = k·r² (r² = x² + y² is
/// uniform), and the azimuth; sin θ / r = √(k·(2 − w)), so no trigonometric call is needed
/// (the disk map's one division aside), and the result is unit to within rounding. `k` is
/// held to 2 (the whole sphere), so a `-dj` above 1 cannot give a longer vector.
pub(super) fn cone_direction(dir: DVec3, (a, b): (DVec3, DVec3), k: f64, u: f64, v: f64) -> DVec3 {
    let k = k.min(2.0);
    let (x, y) = square_to_disk(u, v);
    let w = k * (x * x + y * y);
    let s = (k * (2.0 - w)).max(0.0).sqrt();
    (a * x + b * y) * s + dir * (1.0 - w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_directions_are_unit_and_uniform_by_solid_angle() {
        let dir = DVec3::new(0.3, -0.5, 0.8).normalize();
        let f = frame(dir);
        // the sun's cone (0.5° across) and a wide one
        for k in [1.0 - (0.25f64).to_radians().cos(), 0.3] {
            let n = 256;
            let (mut sum_w, mut sum_a, mut sum_b) = (0.0, 0.0, 0.0);
            for i in 0..n {
                for j in 0..n {
                    let (u, v) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                    let d = cone_direction(dir, f, k, u, v);
                    assert!((d.length() - 1.0).abs() < 1e-15, "{}", d.length());
                    let w = 1.0 - d.dot(dir);
                    assert!(w >= -1e-15 && w <= k * (1.0 + 1e-12), "{w} beyond {k}");
                    sum_w += w;
                    sum_a += d.dot(f.0);
                    sum_b += d.dot(f.1);
                }
            }
            let m = (n * n) as f64;
            // uniform by solid angle: 1 − cos θ uniform on [0, k], mean k/2 (the grid's
            // midpoints give it to ~1/n²); azimuth symmetric: the frame components cancel
            assert!(
                (sum_w / m - k / 2.0).abs() < 1e-4 * k,
                "{} vs {}",
                sum_w / m,
                k / 2.0
            );
            let sin_max = (k * (2.0 - k)).sqrt();
            assert!((sum_a / m).abs() < 1e-3 * sin_max && (sum_b / m).abs() < 1e-3 * sin_max);
        }
    }
}
