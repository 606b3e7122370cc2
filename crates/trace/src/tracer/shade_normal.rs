//! Shading of Radiance's "normal" materials (plastic, metal, trans) and the Lambertian
//! surface used by `-I`/`-i` irradiance.

use super::*;

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
                // one Ward-lobe sample (isotropic); below -ss 1 the variates are pulled
                // toward the lobe's median, -ss 0 giving one fixed direction (Radiance's rule)
                let (u, v) = self.spec_variates(cx);
                let tan2 = -alpha2 * (1.0 - u).max(1e-300).ln();
                let ct = 1.0 / (1.0 + tan2).sqrt();
                let st = (1.0 - ct * ct).max(0.0).sqrt();
                let (a, b) = frame(nrm);
                let phi = 2.0 * PI * v;
                let h = a * (st * phi.cos()) + b * (st * phi.sin()) + nrm * ct;
                let dir = d - h * (2.0 * d.dot(h));
                if dir.dot(nrm) > 0.0 {
                    val += self.spawn(r, s, dir.normalize(), SPECULAR | REFLECTED, scolor, cx);
                }
            }
            if tspec > FTINY && pure {
                val += self.spawn(r, s, d, TRANS, color * tspec, cx);
            } else if tspec > FTINY && tspec > self.opts.st {
                // the rough transmitted lobe: one Gaussian-spread sample about the ray's
                // direction, kept when it still leaves through the far side
                let (u, v) = self.spec_variates(cx);
                let spread = (-alpha2 * (1.0 - u).max(1e-300).ln()).sqrt();
                let (a, b) = frame(d);
                let phi = 2.0 * PI * v;
                let dir = (d + (a * phi.cos() + b * phi.sin()) * spread).normalize();
                if dir.dot(nrm) < 0.0 {
                    val += self.spawn(r, s, dir, SPECULAR | TRANS, color * tspec, cx);
                }
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

    /// Two variates for a specular lobe sample: uniform at `-ss` ≥ 1, pulled toward ½ by
    /// the factor `-ss` below it (so `-ss 0` samples the lobe's median direction).
    fn spec_variates(&self, cx: &mut Ctx) -> (f64, f64) {
        let (u, v) = (cx.rng.next_f64(), cx.rng.next_f64());
        let j = self.opts.ss;
        if j >= 1.0 {
            (u, v)
        } else {
            let j = j.max(0.0);
            (0.5 + j * (u - 0.5), 0.5 + j * (v - 0.5))
        }
    }
}
