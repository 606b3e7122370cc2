//! Shading of Radiance's "normal" materials (plastic, metal, trans) and the Lambertian
//! surface used by `-I`/`-i` irradiance.

use super::*;

/// Draws of a rough specular sample before it is given up (Radiance's MAXITER).
const MAXITER: usize = 10;

/// Radiance's FTINY: how far above (below) the surface a rough sample must leave.
const FTINY_SPEC: f64 = 1e-6;

/// The lobes of a plastic, metal or trans material (its colour comes patterned).
#[derive(Debug, Clone, Copy)]
pub(super) struct NormalLobes {
    pub(super) spec: f64,
    pub(super) rough: f64,
    pub(super) trans: f64,
    pub(super) tspec: f64,
    pub(super) metal: bool,
}

impl Tracer {
    /// Irradiance at `p` on a surface facing unit `n` (Radiance's irradiance hack: a
    /// Lambertian of reflectance pi there, patterns ignored), reached by ray `r` (its clip
    /// set and weight carry over to the shadow and ambient rays); `shape` is the surface
    /// hit, if any.
    pub(super) fn lambert(
        &self,
        r: &Ray,
        p: DVec3,
        n: DVec3,
        shape: Option<usize>,
        cx: &mut Ctx,
    ) -> DVec3 {
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
            return amb + self.direct(r, Lit { p, n, shape }, amb, cx, lamb);
        }
        let mut val = self.direct(r, Lit { p, n, shape }, DVec3::ZERO, cx, lamb);
        val += self.ambient(r, p, n, rho, shape, cx);
        val
    }

    pub(super) fn shade_normal(
        &self,
        r: &Ray,
        color: DVec3,
        lobes: &NormalLobes,
        s: &Surf,
        cx: &mut Ctx,
    ) -> DVec3 {
        let NormalLobes {
            spec,
            rough,
            trans,
            tspec: tspec_frac,
            metal,
        } = *lobes;
        let (shape, p, n, rod) = (s.shape, s.p, s.n, s.rod);
        let nrm = if rod < 0.0 { -n } else { n };
        let pdot = rod.abs().max(1e-3);
        let alpha2 = rough * rough;
        let pure = alpha2 <= FTINY;
        // Radiance 6's estimate of the Fresnel factor (its normal.c: the constant was
        // 0.00287989916, exp(−5.85), in Radiance 5)
        let fres = |c: f64| (-5.85 * c).exp() - 0.00202943064;
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
                return self.spawn(r, s, r.dir, TRANS, color * tspec, cx);
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
            self.direct(r, Lit::on(p, nrm, shape), DVec3::ZERO, cx, lobe)
        };
        if self.effects.specular {
            if rspec > FTINY && pure {
                let dir = (d + nrm * (2.0 * pdot)).normalize();
                val += self.spawn(r, s, dir, REFLECTED, scolor, cx);
            } else if rspec > FTINY && rspec > self.opts.st {
                val += self.rough_reflection(r, s, nrm, alpha2, scolor, cx);
            }
            if tspec > FTINY && pure {
                val += self.spawn(r, s, d, TRANS, color * tspec, cx);
            } else if tspec > FTINY && tspec > self.opts.st {
                val += self.rough_transmission(r, s, nrm, alpha2, color * tspec, cx);
            }
        }
        // A rough lobe too weak to sample (not above -st) joins the ambient coefficient of
        // its side, as Radiance's "below threshold" rule does: its energy is not lost.
        let mut ramb = color * rdiff;
        if rspec > FTINY && !pure && rspec <= self.opts.st {
            ramb += scolor;
        }
        let mut tamb = color * tdiff;
        if tspec > FTINY && !pure && tspec <= self.opts.st {
            tamb += color * tspec;
        }
        if ramb.max_element() > FTINY {
            val += self.ambient(r, p, nrm, ramb, Some(shape), cx);
        }
        if tamb.max_element() > FTINY {
            val += self.ambient(r, p, -nrm, tamb, Some(shape), cx);
        }
        if last {
            val += self.direct(r, Lit::on(p, nrm, shape), val, cx, lobe);
        }
        val
    }

    /// How many samples a rough lobe of coefficient `coef` takes (Radiance's rule): one, or at
    /// `-ss` above 1.5 that many times the ray's weight, rounded, while each keeps a weight
    /// of at least `-lw`.
    fn lobe_samples(&self, r: &Ray, coef: DVec3) -> usize {
        let ss = self.opts.ss;
        if ss <= 1.5 {
            return 1;
        }
        let mut n = (ss * r.weight + 0.5) as usize;
        let w = r.weight * maxc(coef).min(1.0);
        if w <= self.opts.lw * n as f64 {
            n = (w / self.opts.lw) as usize;
        }
        n.max(1)
    }

    /// One draw of a Gaussian lobe's offset: its tangent (the angle's tangent from the
    /// lobe's axis) and azimuth. Below `-ss` 1 the tangent's variate is pulled toward the
    /// axis by that factor, `-ss 0` giving the axis itself (Radiance's rule).
    fn lobe_offset(&self, alpha2: f64, cx: &mut Ctx) -> (f64, f64) {
        let (u, v) = (cx.rng.next_f64(), cx.rng.next_f64());
        let ss = self.opts.ss;
        // 1 − u is in (0, 1], the variate whose logarithm gives the tangent
        let q = if (0.0..1.0).contains(&ss) {
            1.0 - ss * u
        } else {
            1.0 - u
        };
        let tan = if q <= FTINY_SPEC {
            1.0
        } else {
            (-alpha2 * q.ln()).sqrt()
        };
        (tan, 2.0 * PI * v)
    }

    /// The rough (Ward) reflection of a plastic or metal: directions drawn about the
    /// half-vector and drawn again, up to 10 times a sample, while they point below the
    /// surface (so the lobe keeps its energy at grazing angles, as Radiance's). Several
    /// samples (`-ss` > 1.5) are weighted as Radiance's W-G-M-D rule and by the number of
    /// draws made; each traced ray carries its share in its coefficient.
    fn rough_reflection(
        &self,
        r: &Ray,
        s: &Surf,
        nrm: DVec3,
        alpha2: f64,
        scolor: DVec3,
        cx: &mut Ctx,
    ) -> DVec3 {
        let d = r.dir;
        let (a, b) = frame(nrm);
        let n = self.lobe_samples(r, scolor);
        let rod = s.rod.abs();
        // one draw: the reflected direction and its W-G-M-D weight, or None below the surface
        let draw = |cx: &mut Ctx| {
            let (tan, phi) = self.lobe_offset(alpha2, cx);
            let h = nrm + (a * phi.cos() + b * phi.sin()) * tan;
            let dir = d + h * (-2.0 * h.dot(d) / (1.0 + tan * tan));
            let dot = dir.dot(nrm);
            (dot > FTINY_SPEC).then(|| (dir.normalize(), 2.0 / (1.0 + rod / dot)))
        };
        if n == 1 {
            // the usual case: the first direction above the surface, no list
            for _ in 0..MAXITER {
                if let Some((dir, _)) = draw(cx) {
                    return self.spawn(r, s, dir, SPECULAR | REFLECTED, scolor, cx);
                }
            }
            return DVec3::ZERO;
        }
        let mut taken: Vec<(DVec3, f64)> = Vec::with_capacity(n);
        let mut trials = 0usize;
        while taken.len() < n && trials < MAXITER * n {
            trials += 1;
            if let Some(t) = draw(cx) {
                taken.push(t);
            }
        }
        let weight = r.weight * maxc(scolor).min(1.0) / n as f64;
        let mut val = DVec3::ZERO;
        for (dir, w) in taken {
            let coef = scolor * (w / trials as f64);
            val += self.spawn_weighted(r, s, dir, SPECULAR | REFLECTED, (coef, weight), cx);
        }
        val
    }

    /// The rough transmission of a trans material: directions spread about the ray's own
    /// across the surface's plane (Radiance's rule), drawn again up to 10 times a sample
    /// while they do not leave through the far side; several samples (`-ss` > 1.5) share
    /// the coefficient.
    fn rough_transmission(
        &self,
        r: &Ray,
        s: &Surf,
        nrm: DVec3,
        alpha2: f64,
        coef: DVec3,
        cx: &mut Ctx,
    ) -> DVec3 {
        let d = r.dir;
        let (a, b) = frame(nrm);
        let n = self.lobe_samples(r, coef);
        let (mut taken, mut trials) = (0usize, 0usize);
        let weight = r.weight * maxc(coef).min(1.0) / n as f64;
        let share = coef / n as f64;
        let mut val = DVec3::ZERO;
        while taken < n && trials < MAXITER * n {
            trials += 1;
            let (tan, phi) = self.lobe_offset(alpha2, cx);
            let dir = d + (a * phi.cos() + b * phi.sin()) * tan;
            if dir.dot(nrm) >= -FTINY_SPEC {
                continue;
            }
            taken += 1;
            val += if n == 1 {
                self.spawn(r, s, dir.normalize(), SPECULAR | TRANS, coef, cx)
            } else {
                self.spawn_weighted(r, s, dir.normalize(), SPECULAR | TRANS, (share, weight), cx)
            };
        }
        val
    }
}
