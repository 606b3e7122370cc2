//! Klems-direction ray samples over a planar aperture (the genklemsamp tool): for each of
//! the 145 patches of the LBNL/Klems Full basis, in patch order, `N` rays whose origins are
//! spread over the aperture (window polygons, or a rectangle) and whose directions fall in
//! the patch, sampled as Radiance's genklemsamp samples them: the polar angle uniform
//! within the patch's ring (the centre patch over θ in [−5°, 5°]), the azimuth uniform
//! within the patch.
//!
//! Frame: `vd` is the direction the rays travel (out of the aperture), `vh = unit(vd × vu)`,
//! `vv = unit(vh × vd)`; a direction is `−cosφ sinθ vh − sinφ sinθ vv + cosθ vd`. That is the
//! Klems frame of a surface with normal `−vd` and up vector `vu` (`kbin(−vd, vu)` bins it).

use anyhow::{bail, Result};
use fenestra_bsdf::klems::KlemsBasis;
use fenestra_scene::Scene;
use fenestra_trace::rng::Rng;
use glam::DVec3;

/// How close to perpendicular to `vd` a polygon must be to count as aperture:
/// `(vd·n)² > 0.999` (within about 1.8°), as Radiance's genklemsamp.
pub const MIN_COS2: f64 = 0.999;

/// The aperture rays start from.
#[derive(Debug, Clone)]
pub enum Aperture {
    /// A rectangle centred on `centre`, `width` along `vh` and `height` along `vv`.
    Rect {
        /// Centre point.
        centre: DVec3,
        /// Size along the horizontal image vector.
        width: f64,
        /// Size along the vertical image vector.
        height: f64,
    },
    /// Triangles covering the window polygons, with their cumulative areas.
    Triangles {
        /// Triangle corners.
        tris: Vec<[DVec3; 3]>,
        /// Running sum of triangle areas (last = total area).
        cum: Vec<f64>,
    },
}

impl Aperture {
    /// Total area.
    pub fn area(&self) -> f64 {
        match self {
            Aperture::Rect { width, height, .. } => width * height,
            Aperture::Triangles { cum, .. } => cum.last().copied().unwrap_or(0.0),
        }
    }
}

/// The sampler: frame, aperture and origin offset.
#[derive(Debug, Clone)]
pub struct KlemsSampler {
    vd: DVec3,
    vh: DVec3,
    vv: DVec3,
    offset: f64,
    aperture: Aperture,
    basis: &'static KlemsBasis,
}

/// The frame vectors `(vd, vh, vv)` for a ray direction and an up vector, as Radiance's
/// views compute them; an error when they are parallel or zero.
pub fn frame(vd: [f64; 3], vu: [f64; 3]) -> Result<(DVec3, DVec3, DVec3)> {
    let d = DVec3::from(vd);
    let u = DVec3::from(vu);
    if d.length() < 1e-12 {
        bail!("zero view direction (-vd)");
    }
    let d = d.normalize();
    let h = d.cross(u);
    if h.length() < 1e-9 * u.length().max(1e-300) || u.length() < 1e-12 {
        bail!("the up vector (-vu) is parallel to the direction (-vd)");
    }
    let h = h.normalize();
    let v = h.cross(d).normalize();
    Ok((d, h, v))
}

/// A polygon of the scene that forms part of the aperture, as triangles.
pub(crate) fn triangulate(pts: &[DVec3]) -> Vec<[DVec3; 3]> {
    // Project on the polygon's plane (Newell normal) and clip ears; fall back to a fan.
    let mut n = DVec3::ZERO;
    for i in 0..pts.len() {
        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
        n += a.cross(b);
    }
    let n = n.normalize_or_zero();
    let ax = if n.x.abs() > 0.9 { DVec3::Y } else { DVec3::X };
    let e1 = n.cross(ax).normalize();
    let e2 = n.cross(e1);
    let p2: Vec<(f64, f64)> = pts.iter().map(|p| (p.dot(e1), p.dot(e2))).collect();
    let cross2 = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    // orientation
    let mut area2 = 0.0;
    for i in 0..p2.len() {
        let (a, b) = (p2[i], p2[(i + 1) % p2.len()]);
        area2 += a.0 * b.1 - b.0 * a.1;
    }
    let sign = if area2 >= 0.0 { 1.0 } else { -1.0 };
    let mut idx: Vec<usize> = (0..pts.len()).collect();
    let mut out = Vec::new();
    let mut guard = 0;
    while idx.len() > 3 && guard < 10 * pts.len() * pts.len() {
        guard += 1;
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (a, b, c) = (p2[ia], p2[ib], p2[ic]);
            if sign * cross2(a, b, c) <= 0.0 {
                continue; // reflex or degenerate corner
            }
            let inside = idx.iter().any(|&j| {
                if j == ia || j == ib || j == ic {
                    return false;
                }
                let p = p2[j];
                if p == a || p == b || p == c {
                    return false;
                }
                // points on an edge of the ear block it too
                sign * cross2(a, b, p) >= 0.0
                    && sign * cross2(b, c, p) >= 0.0
                    && sign * cross2(c, a, p) >= 0.0
            });
            if inside {
                continue;
            }
            out.push([pts[ia], pts[ib], pts[ic]]);
            idx.remove(k);
            clipped = true;
            break;
        }
        if !clipped {
            break;
        }
    }
    if idx.len() == 3 {
        out.push([pts[idx[0]], pts[idx[1]], pts[idx[2]]]);
    } else if idx.len() > 3 {
        for k in 1..idx.len() - 1 {
            out.push([pts[idx[0]], pts[idx[k]], pts[idx[k + 1]]]);
        }
    }
    out
}

/// The aperture made of the scene's polygons that face along `vd` (either side), with
/// warnings for the surfaces left out.
pub fn aperture_from_scene(scene: &Scene, vd: DVec3) -> Result<(Aperture, Vec<String>)> {
    let mut tris = Vec::new();
    let mut warnings = Vec::new();
    let mut used = 0;
    // planes (offset along vd) and facings of the polygons kept, to catch a whole room
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut facing_vd, mut facing_back) = (0usize, 0usize);
    let mut diag = 0.0f64;
    for p in &scene.prims {
        if !p.is_surface() {
            continue;
        }
        if p.ptype != "polygon" {
            warnings.push(format!(
                "{}: {} '{}' ignored (only polygons form the aperture)",
                p.loc, p.ptype, p.name
            ));
            continue;
        }
        if p.rargs.len() < 9 || p.rargs.len() % 3 != 0 {
            bail!(
                "{}: polygon '{}' needs 3n real arguments (n >= 3)",
                p.loc,
                p.name
            );
        }
        let pts: Vec<DVec3> = p
            .rargs
            .chunks(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect();
        let mut n = DVec3::ZERO;
        for i in 0..pts.len() {
            n += pts[i].cross(pts[(i + 1) % pts.len()]);
        }
        if n.length() == 0.0 {
            warnings.push(format!(
                "{}: polygon '{}' has no area; ignored",
                p.loc, p.name
            ));
            continue;
        }
        let c = n.normalize().dot(vd);
        if c * c <= MIN_COS2 {
            warnings.push(format!(
                "{}: polygon '{}' is not perpendicular to the direction (-vd); ignored",
                p.loc, p.name
            ));
            continue;
        }
        used += 1;
        if c > 0.0 {
            facing_vd += 1;
        } else {
            facing_back += 1;
        }
        for q in &pts {
            let o = q.dot(vd);
            lo = lo.min(o);
            hi = hi.max(o);
            diag = diag.max((*q - pts[0]).length());
        }
        tris.extend(triangulate(&pts));
    }
    // a window is polygons in one plane facing one way; a room gives walls in two planes
    // facing each other (Radiance samples them all as the window, silently)
    if used > 1 && (hi - lo > 1e-3 * diag.max(1e-3) || (facing_vd > 0 && facing_back > 0)) {
        warnings.push(format!(
            "the {used} polygons perpendicular to -vd lie {:.3} apart along it{} (a whole room or wall instead of the window?); all are sampled as the aperture: give only the window polygons (e.g. window_out.rad)",
            hi - lo,
            if facing_vd > 0 && facing_back > 0 {
                " and face opposite ways"
            } else {
                ""
            }
        ));
    }
    if used == 0 {
        bail!(
            "View direction does not correspond to any surfaces (no polygon perpendicular to -vd)"
        );
    }
    let mut cum = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in &tris {
        total += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        cum.push(total);
    }
    if total <= 0.0 {
        bail!("the aperture polygons have no area");
    }
    Ok((Aperture::Triangles { tris, cum }, warnings))
}

impl KlemsSampler {
    /// A sampler for rays travelling along `vd` (up vector `vu`) from `aperture`, origins
    /// moved `offset` along `vd` off the surface.
    pub fn new(vd: [f64; 3], vu: [f64; 3], offset: f64, aperture: Aperture) -> Result<Self> {
        let (vd, vh, vv) = frame(vd, vu)?;
        Ok(KlemsSampler {
            vd,
            vh,
            vv,
            offset,
            aperture,
            basis: KlemsBasis::full(),
        })
    }

    /// Number of patches (145).
    pub fn patches(&self) -> usize {
        self.basis.len()
    }

    /// The direction for patch `k` (0-based) from two uniform variates, as genklemsamp
    /// computes it (θ uniform over the ring, the centre patch over [−5°, 5°]).
    pub fn direction(&self, k: usize, x1: f64, x2: f64) -> DVec3 {
        let (ring, col) = self.basis.ring_of(k).expect("patch index within the basis");
        let r = &self.basis.rings()[ring];
        let (lo, hi) = if ring == 0 {
            (-r.theta_hi, r.theta_hi)
        } else {
            (r.theta_lo, r.theta_hi)
        };
        let theta = (x1 * hi + (1.0 - x1) * lo).to_radians();
        let phi = 2.0 * std::f64::consts::PI * (col as f64 + 0.5 - x2) / r.nphi as f64;
        let (st, ct) = theta.sin_cos();
        -phi.cos() * st * self.vh - phi.sin() * st * self.vv + ct * self.vd
    }

    /// A point of the aperture from two uniform variates (area-uniform).
    pub fn point(&self, u1: f64, u2: f64, u3: f64) -> DVec3 {
        match &self.aperture {
            Aperture::Rect {
                centre,
                width,
                height,
            } => *centre + (u1 - 0.5) * width * self.vh + (u2 - 0.5) * height * self.vv,
            Aperture::Triangles { tris, cum } => {
                let total = *cum.last().unwrap_or(&0.0);
                let target = u3 * total;
                let i = cum.partition_point(|&c| c <= target).min(tris.len() - 1);
                let t = &tris[i];
                let (mut a, mut b) = (u1, u2);
                if a + b > 1.0 {
                    a = 1.0 - a;
                    b = 1.0 - b;
                }
                t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0])
            }
        }
    }

    /// Ray `j` of patch `k` (origin, direction), drawn from the stream `(seed, k·n + j)`.
    pub fn ray(&self, seed: u64, n: usize, k: usize, j: usize) -> (DVec3, DVec3) {
        let mut rng = Rng::for_ray(seed, (k * n + j) as u64);
        let (x1, x2) = (rng.next_f64(), rng.next_f64());
        let (u1, u2, u3) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
        let d = self.direction(k, x1, x2);
        let o = self.point(u1, u2, u3) + self.offset * self.vd;
        (o, d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fenestra_bsdf::klems::Frame;

    #[test]
    fn directions_fall_in_their_patch() {
        let ap = Aperture::Rect {
            centre: DVec3::ZERO,
            width: 2.0,
            height: 1.0,
        };
        let s = KlemsSampler::new([0.0, -1.0, 0.0], [0.0, 0.0, 1.0], 1e-5, ap).unwrap();
        let f = Frame::new([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        for k in 0..145 {
            for j in 0..50 {
                let (_, d) = s.ray(7, 50, k, j);
                assert!((d.length() - 1.0).abs() < 1e-12);
                let got = f.bin(KlemsBasis::full(), d.to_array());
                assert_eq!(got, Some(k), "patch {k} ray {j}: {d:?}");
            }
        }
    }

    #[test]
    fn concave_polygon_triangulates_to_its_area() {
        // an L shape of area 3
        let pts: Vec<DVec3> = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)]
            .iter()
            .map(|&(x, z)| DVec3::new(x, 0.0, z))
            .collect();
        let t = triangulate(&pts);
        let a: f64 = t
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
            .sum();
        assert!((a - 3.0).abs() < 1e-12, "{a}");
    }
}
