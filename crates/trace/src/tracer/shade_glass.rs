//! Shading of `dielectric` and `glass` (Fresnel reflection and transmission).

use super::*;

impl Tracer {
    pub(super) fn shade_dielectric(
        &self,
        r: &Ray,
        tn: DVec3,
        idx: f64,
        s: &Surf,
        cx: &mut Ctx,
    ) -> DVec3 {
        let (n, rod, t) = (s.n, s.rod, s.t);
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
            return atten * self.spawn(r, s, refl_dir, REFLECTED, DVec3::ONE, cx);
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
                val += self.spawn(r, s, r.dir, TRANS, DVec3::splat(1.0 - fr), cx);
            }
            return atten * val;
        }
        val += self.spawn(r, s, tdir, TRANS, DVec3::splat(1.0 - fr), cx);
        val += self.spawn(r, s, refl_dir, REFLECTED, DVec3::splat(fr), cx);
        atten * val
    }

    pub(super) fn shade_glass(
        &self,
        r: &Ray,
        tn: DVec3,
        idx: f64,
        s: &Surf,
        cx: &mut Ctx,
    ) -> DVec3 {
        let (n, rod) = (s.n, s.rod);
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
            val += self.spawn(r, s, r.dir, TRANS, trans, cx);
        }
        if r.flags & SHADOW == 0 && maxc(refl) > FTINY {
            let dir = (r.dir + nrm * (2.0 * pdot)).normalize();
            val += self.spawn(r, s, dir, REFLECTED, refl, cx);
        }
        val
    }
}
