//! Shading of the `BSDF` material (Klems data, thickness 0), after Radiance 6.0's
//! `m_bsdf.c` rules (facts from its source; our own code):
//!
//! - Shadow rays stop: light reaches the far side through direct and ambient sampling at
//!   the window itself.
//! - Each lobe (reflection, transmission) is sampled with rays only when its non-diffuse
//!   hemispherical total for the view, jittered within its Klems patch, exceeds `-st`;
//!   otherwise that total joins the side's diffuse coefficient for the ambient calculation
//!   (grey, as Radiance). With `-ss` > 1.5 a lobe gets ⌊ss·weight + ½⌋ rays, stratified,
//!   each from its own jittered view.
//! - Direct light: the diffuse parts (arguments and the Lambertian parts split off on
//!   loading) as a Lambertian term, plus the non-diffuse remainder averaged over
//!   ⌊4·ss·weight + ½⌋ (at least 1) views jittered by the square root of the smaller
//!   projected solid angle of the view's and the source's patches (`-ss` below 1 shrinks
//!   the jitter; 0 turns it off), so a sun's beam is spread over a patch as in Radiance.
//! - Ambient: the diffuse reflectance (plus unsampled reflection) on the view side, the
//!   diffuse transmittance (plus unsampled transmission) on the other.

use super::*;
use crate::bsdf_mat::Component;

/// A view `v` (local, unit) moved by up to `radius`/2 in local x and y (`u`, `w` uniform
/// in [0, 1)), renormalised; the side (sign of z) is kept.
fn jitter(v: DVec3, radius: f64, u: f64, w: f64) -> DVec3 {
    if radius <= 0.0 {
        return v;
    }
    let j = DVec3::new(v.x + radius * (0.5 - u), v.y + radius * (0.5 - w), v.z);
    j.try_normalize().unwrap_or(v)
}

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
        let (refl, trans, rd, td) = if front {
            (b.rf.as_deref(), b.tf.as_deref(), b.rd_front, b.td_front)
        } else {
            (b.rb.as_deref(), b.tb.as_deref(), b.rd_back, b.td_back)
        };
        let side = if front { z } else { -z };
        let (ss, st) = (self.opts.ss.max(0.0), self.opts.st);
        let shrink = if ss < 1.0 { ss } else { 1.0 };
        // direct light: jittered views drawn from a generator of this hit's own (the
        // coefficient function is called once per source sample)
        let jit = std::cell::RefCell::new(Rng::for_ray(cx.rng.next_u64(), 0));
        let nview = if ss > 0.0 {
            ((4.0 * ss * r.weight + 0.5) as usize).max(1)
        } else {
            1
        };
        let remainder = |c: &Component, ll: DVec3| {
            let Some(tomega) = c.view_patch_size(v).zip(c.light_patch_size(ll)) else {
                return 0.0;
            };
            let radius = tomega.0.min(tomega.1).sqrt() * shrink;
            let mut g = jit.borrow_mut();
            let mut sum = 0.0;
            for _ in 0..nview {
                let (u, w) = (g.next_f64(), g.next_f64());
                sum += c.eval(jitter(v, radius, u, w), ll);
            }
            sum / nview as f64
        };
        let lobe = |l: DVec3, omega: f64, ldot: f64| {
            let ll = to_local(l);
            let same = (ll.z > 0.0) == front;
            let (comp, diffuse) = if same { (refl, rd) } else { (trans, td) };
            let f = DVec3::splat(comp.map_or(0.0, |c| remainder(c, ll))) + diffuse / PI;
            f * (ldot.abs() * omega)
        };
        // with thresholding direct light comes last (as in Radiance), otherwise first
        let last = cx.ds.is_some();
        let lit = Lit::on(p, side, shape);
        let mut val = if last {
            DVec3::ZERO
        } else {
            self.direct(r, lit, DVec3::ZERO, cx, lobe)
        };
        // the lobes: sampled with rays above -st, else folded into the diffuse parts
        let (mut rdiff, mut tdiff) = (rd, td);
        for (comp, flag) in [(refl, REFLECTED), (trans, TRANS)] {
            let Some(c) = comp else { continue };
            if c.max_hemi <= FTINY {
                continue;
            }
            let big = c.view_patch_size(v).unwrap_or(0.0).sqrt() * shrink;
            let (u, w) = (cx.rng.next_f64(), cx.rng.next_f64());
            let total = c.hemi(jitter(v, big, u, w));
            if total <= st + FTINY {
                if flag == REFLECTED {
                    rdiff += DVec3::splat(total);
                } else {
                    tdiff += DVec3::splat(total);
                }
                continue;
            }
            let nsamp = if ss > 1.5 {
                ((ss * r.weight + 0.5) as usize).max(1)
            } else {
                1
            };
            let small = big; // one patch size per view in a Klems basis
            for k in 0..nsamp {
                let (u, u0, u1) = (cx.rng.next_f64(), cx.rng.next_f64(), cx.rng.next_f64());
                let xr = if nsamp == 1 {
                    0.5 + shrink * (u - 0.5)
                } else {
                    (k as f64 + u) / nsamp as f64
                };
                let (ju, jw) = (cx.rng.next_f64(), cx.rng.next_f64());
                let vs = jitter(v, small, ju, jw);
                if let Some((d, h)) = c.sample(vs, xr, u0, u1) {
                    let dir = (x * d.x + y * d.y + z * d.z).normalize();
                    let coef = DVec3::splat(h / nsamp as f64);
                    val += self.spawn(r, s, dir, SPECULAR | flag, coef, cx);
                }
            }
        }
        if maxc(rdiff) > FTINY {
            val += self.ambient(r, p, side, rdiff, Some(shape), cx);
        }
        if maxc(tdiff) > FTINY {
            val += self.ambient(r, p, -side, tdiff, Some(shape), cx);
        }
        if last {
            val += self.direct(r, lit, val, cx, lobe);
        }
        val
    }
}
