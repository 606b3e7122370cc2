//! Shading of the `BSDF` material (Klems data): transmission and reflection lobes, their
//! specular and diffuse parts.

use super::*;

impl Tracer {
    pub(super) fn shade_bsdf(
        &self,
        r: &Ray,
        b: &crate::bsdf_mat::BsdfMat,
        s: &Surf,
        cx: &mut Ctx,
    ) -> DVec3 {
        let (shape, p, n) = (s.shape, s.p, s.n);
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
            self.direct(r, Lit::on(p, side, shape), DVec3::ZERO, cx, lobe)
        };
        for (comp, flag) in [(refl, REFLECTED), (trans, TRANS)] {
            let Some(c) = comp else { continue };
            let (u, u0, u1) = (cx.rng.next_f64(), cx.rng.next_f64(), cx.rng.next_f64());
            if let Some((d, h)) = c.sample(v, u, u0, u1) {
                let dir = (x * d.x + y * d.y + z * d.z).normalize();
                val += self.spawn(r, s, dir, SPECULAR | flag, DVec3::splat(h), cx);
            }
        }
        if maxc(rd) > FTINY {
            val += self.ambient(r, p, side, rd, Some(shape), cx);
        }
        if maxc(td) > FTINY {
            val += self.ambient(r, p, -side, td, Some(shape), cx);
        }
        if last {
            val += self.direct(r, Lit::on(p, side, shape), val, cx, lobe);
        }
        val
    }
}
