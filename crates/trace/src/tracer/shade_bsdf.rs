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
//! - A thickness makes the surface a proxy for geometry modelled in place: shadow rays,
//!   rays with no specular or ambient scattering in their history (view rays, mirror and
//!   glass chains) and rays meeting its hidden side pass straight through; the other rays
//!   are shaded, transmitted specular rays and transmitted direct light taken a thickness
//!   behind the surface (along −normal), the far side's ambient a thickness in front (as
//!   Radiance 6.0 does).

use super::*;
use crate::bsdf_mat::LobeData;

/// A view `v` (local, unit) moved by up to `radius`/2 in local x and y (`u`, `w` uniform
/// in [0, 1)), renormalised; the side (sign of z) is kept.
fn jitter(v: DVec3, radius: f64, u: f64, w: f64) -> DVec3 {
    if radius <= 0.0 {
        return v;
    }
    let j = DVec3::new(v.x + radius * (0.5 - u), v.y + radius * (0.5 - w), v.z);
    j.try_normalize().unwrap_or(v)
}

/// aBSDF's through component for view `v` (Radiance's `compute_through`): the
/// transmission evaluated along −v and 28 directions around it (up to 2.4 × √ of the
/// smallest cell), sorted; leading values in cells no larger than 1.5 × the smallest, and
/// not below an eighth of the mean of those before them, form the peak, the rest its
/// surround. Returns the peak's transmittance (Σ value × cell) and the surround's mean
/// BTDF, both without the Lambertian part `diff` (sr⁻¹); zeros where there is no peak
/// (the strongest direction not in a peak cell, a surround under 0.2 of the peak's solid
/// angle, a peak under 0.0005).
fn through(trans: Option<&LobeData>, v: DVec3, diff: f64) -> (f64, f64) {
    const OFFSETS: [(f64, f64); 29] = [
        (0.0, 0.0),
        (-0.6, 0.0),
        (0.0, 0.6),
        (0.0, -0.6),
        (0.6, 0.0),
        (-0.6, 0.6),
        (-0.6, -0.6),
        (0.6, 0.6),
        (0.6, -0.6),
        (-1.2, 0.0),
        (0.0, 1.2),
        (0.0, -1.2),
        (1.2, 0.0),
        (-1.2, 1.2),
        (-1.2, -1.2),
        (1.2, 1.2),
        (1.2, -1.2),
        (-1.8, 0.0),
        (0.0, 1.8),
        (0.0, -1.8),
        (1.8, 0.0),
        (-1.8, 1.8),
        (-1.8, -1.8),
        (1.8, 1.8),
        (1.8, -1.8),
        (-2.4, 0.0),
        (0.0, 2.4),
        (0.0, -2.4),
        (2.4, 0.0),
    ];
    let Some(t) = trans else { return (0.0, 0.0) };
    let min = t.min_size();
    let rad = min.sqrt();
    // (value, cell size) of each direction, from one evaluation
    let mut samples: Vec<(f64, f64)> = OFFSETS
        .iter()
        .map(|&(dx, dy)| {
            let d = DVec3::new(-v.x + dx * rad, -v.y + dy * rad, -v.z).normalize();
            let (f, size) = t.eval_sized(v, d);
            (f + diff, size)
        })
        .collect();
    samples.sort_by(|a, b| b.0.total_cmp(&a.0));
    if samples[0].0 <= FTINY {
        return (0.0, 0.0);
    }
    let (mut peak, mut surr, mut ypeak, mut tsum, mut tsurr) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut ns = 0.0;
    for (i, &(y, size)) in samples.iter().enumerate() {
        if i > 0 && y == samples[i - 1].0 {
            continue; // a duplicate cell
        }
        if size > 1.5 * min || ypeak > 8.0 * y * ns {
            if i == 0 {
                return (0.0, 0.0);
            }
            surr += y * size;
            tsurr += size;
            continue;
        }
        peak += y * size;
        tsum += size;
        ypeak += y;
        ns += 1.0;
    }
    if tsurr < 0.2 * tsum {
        return (0.0, 0.0);
    }
    let surr = (surr / tsurr - diff).max(0.0);
    let peak = (peak - tsum * diff).max(0.0);
    if peak < 0.0005 {
        return (0.0, 0.0);
    }
    (peak, surr)
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
        if b.thick != 0.0 {
            let hidden = (b.thick > 0.0) != (s.rod > 0.0);
            if r.flags & SHADOW != 0 || r.flags & (SPECULAR | AMBIENT) == 0 || hidden {
                return self.pass(r.clone(), shape, p, s.t, cx);
            }
        } else if r.flags & SHADOW != 0 && !b.through {
            return DVec3::ZERO;
        }
        // a proxy's far side: transmitted rays and light a thickness behind, the far
        // side's ambient a thickness in front
        let behind = p - n * b.thick;
        let before = p + n * b.thick;
        let z = n;
        let x =
            b.up.cross(z)
                .try_normalize()
                .unwrap_or_else(|| z.any_orthonormal_vector());
        let y = z.cross(x);
        let to_local = |w: DVec3| DVec3::new(w.dot(x), w.dot(y), w.dot(z));
        let v = to_local(-r.dir);
        let front = v.z > 0.0;
        let (refl, trans) = b.lobes(front);
        let (rd, td) = if front {
            (b.rd_front, b.td_front)
        } else {
            (b.rd_back, b.td_back)
        };
        let side = if front { z } else { -z };
        // aBSDF: the transmission peak along the view passes straight on, for shadow rays
        // and for rays with no specular or ambient scattering behind them
        let (cthru, csurr) = if b.through {
            through(trans.as_ref(), v, b.lamb[2 + usize::from(!front)] / PI)
        } else {
            (0.0, 0.0)
        };
        if r.flags & SHADOW != 0 {
            return if cthru > FTINY {
                self.spawn(r, s, r.dir, TRANS, DVec3::splat(cthru), cx)
            } else {
                DVec3::ZERO
            };
        }
        let hasthru = cthru > FTINY && r.flags & (SPECULAR | AMBIENT) == 0;
        let thru_min = trans.as_ref().map_or(0.0, |t| t.min_size());
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
        // the non-diffuse part for light from `ll`, as Radiance's direct_specular_OK: the
        // full BSDF (file's Lambertian part `diff_y` included) averaged over jittered
        // views; a view whose value is no more than the Lambertian part counts as zero, one
        // landing in a cell under 0.12 of the first's size (a finer tree leaf) is left
        // out; then the Lambertian part is taken off again
        // (a coloured file: each view's value carries its element's colour; the result is
        // the luminance so found in the mean colour of the views counted)
        let remainder = |c: &LobeData, ll: DVec3, diff_y: f64| -> DVec3 {
            let (f0, tomega, colour0) = c.eval_full(v, ll);
            let radius = tomega.max(0.0).sqrt() * shrink;
            if radius <= 0.0 {
                return f0 * colour0.unwrap_or_else(|| c.colour(v, ll));
            }
            let mut g = jit.borrow_mut();
            let (mut sum, mut count) = (0.0, 0usize);
            let (mut sum_c, mut sum_f) = (DVec3::ZERO, 0.0);
            for _ in 0..nview {
                let (u, w) = (g.next_f64(), g.next_f64());
                let vj = jitter(v, radius, u, w);
                let (f, size, colour) = c.eval_full(vj, ll);
                if f <= FTINY {
                    count += 1;
                    continue;
                }
                if size < 0.12 * tomega {
                    continue;
                }
                sum += f + diff_y;
                sum_c += f * colour.unwrap_or_else(|| c.colour(vj, ll));
                sum_f += f;
                count += 1;
            }
            if count == 0 {
                return DVec3::ZERO;
            }
            let y = (sum / count as f64 - diff_y).max(0.0);
            if sum_f > 0.0 {
                sum_c * (y / sum_f)
            } else {
                DVec3::splat(y)
            }
        };
        // with a thickness, reflected and transmitted light are gathered at two points
        let only = std::cell::Cell::new(None::<bool>);
        let lobe = |l: DVec3, omega: f64, ldot: f64| {
            let ll = to_local(l);
            let same = (ll.z > 0.0) == front;
            if only.get().is_some_and(|want| want != same) {
                return DVec3::ZERO;
            }
            // aBSDF: a source seen through the peak gets the surround's BTDF (the peak
            // itself reaches the source by the through ray, not counted twice)
            if cthru > FTINY && !same {
                let (dx, dy) = (ll.x + v.x, ll.y + v.y);
                let tw = omega * ll.z.abs();
                if dx * dx + dy * dy
                    <= (2.5 * 4.0 / PI) * (tw + thru_min + 2.0 * (tw * thru_min).sqrt())
                {
                    return (DVec3::splat(csurr) + td / PI) * (ldot.abs() * omega);
                }
            }
            let (comp, diffuse, own) = if same {
                (refl, rd, b.lamb[usize::from(!front)])
            } else {
                (trans, td, b.lamb[2 + usize::from(!front)])
            };
            let f = comp
                .as_ref()
                .map_or(DVec3::ZERO, |c| remainder(c, ll, own / PI))
                + diffuse / PI;
            f * (ldot.abs() * omega)
        };
        // with thresholding direct light comes last (as in Radiance), otherwise first
        let last = cx.ds.is_some();
        let lit = Lit::on(p, side, shape);
        let direct = |cx: &mut Ctx, prior: DVec3| -> DVec3 {
            if b.thick == 0.0 {
                return self.direct(r, lit, prior, cx, lobe);
            }
            only.set(Some(true));
            let mut v = self.direct(r, lit, prior, cx, lobe);
            only.set(Some(false));
            let far = Lit {
                p: behind,
                n: side,
                shape: None,
            };
            v += self.direct(r, far, prior + v, cx, lobe);
            only.set(None);
            v
        };
        let mut val = if last {
            DVec3::ZERO
        } else {
            direct(cx, DVec3::ZERO)
        };
        // the lobes: sampled with rays above -st, else folded into the diffuse parts
        let (mut rdiff, mut tdiff) = (rd, td);
        for (comp, flag) in [(refl, REFLECTED), (trans, TRANS)] {
            let Some(c) = comp else { continue };
            let thru = hasthru && flag == TRANS;
            let mut taken = 0.0;
            if thru {
                val += self.spawn(r, s, r.dir, TRANS, DVec3::splat(cthru), cx);
                taken = cthru;
            }
            if c.max_hemi() - taken <= FTINY {
                continue;
            }
            let big = c.view_size(v).sqrt() * shrink;
            let (u, w) = (cx.rng.next_f64(), cx.rng.next_f64());
            let vj = jitter(v, big, u, w);
            let hemi = c.hemi(vj);
            let total = (hemi - taken).max(0.0);
            if total <= st + FTINY {
                // folded into the diffuse part, in the lobe's own colour
                let folded = if hemi > 0.0 {
                    c.hemi_rgb(vj) * (total / hemi)
                } else {
                    DVec3::ZERO
                };
                if flag == REFLECTED {
                    rdiff += folded;
                } else {
                    tdiff += folded;
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
                if let Some((d, h, colour)) = c.sample(vs, xr, u0, u1) {
                    // the through ray already carries the view's own direction
                    if thru && (vs.x + d.x).powi(2) + (vs.y + d.y).powi(2) <= small * small {
                        continue;
                    }
                    let dir = (x * d.x + y * d.y + z * d.z).normalize();
                    let coef = colour * (h / nsamp as f64);
                    let from = if flag == TRANS && b.thick != 0.0 {
                        Surf { p: behind, ..*s }
                    } else {
                        *s
                    };
                    val += self.spawn(r, &from, dir, SPECULAR | flag, coef, cx);
                }
            }
        }
        if maxc(rdiff) > FTINY {
            val += self.ambient(r, p, side, rdiff, Some(shape), cx);
        }
        if maxc(tdiff) > FTINY {
            let q = if b.thick != 0.0 { before } else { p };
            val += self.ambient(r, q, -side, tdiff, Some(shape), cx);
        }
        if last {
            val += direct(cx, val);
        }
        val
    }
}
