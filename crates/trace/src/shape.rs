//! Analytic surfaces in f64: polygon, sphere/bubble, cone/cup, cylinder/tube, ring.
//!
//! Every routine works in f64 relative to a local origin of the surface (its first
//! vertex or centre), so a 1 mm slat 1 km from the world origin intersects correctly.

use glam::DVec3;

use crate::polygon::Polygon;

/// A surface the BVH holds.
#[derive(Debug, Clone)]
pub enum Shape {
    /// Planar polygon (convex or concave).
    Polygon(Polygon),
    /// Sphere; `inward` for a bubble.
    Sphere {
        /// Centre.
        c: DVec3,
        /// Radius.
        r: f64,
        /// Normal points inward (bubble).
        inward: bool,
    },
    /// Truncated cone or cylinder (open ends); `inward` for cup/tube.
    Cone {
        /// Base centre.
        p0: DVec3,
        /// Unit axis from `p0` to the other end.
        axis: DVec3,
        /// Axis length.
        len: f64,
        /// Radius at `p0`.
        r0: f64,
        /// Radius at the other end.
        r1: f64,
        /// Normal points inward (cup/tube).
        inward: bool,
    },
    /// Disk or annulus.
    Ring {
        /// Centre.
        c: DVec3,
        /// Unit normal.
        n: DVec3,
        /// Inner radius.
        r0: f64,
        /// Outer radius.
        r1: f64,
    },
}

/// Rays closer than this to parallel with a plane miss it (Radiance's FTINY).
pub const PARALLEL_EPS: f64 = 1e-9;

impl Shape {
    /// Nearest intersection distance in (tmin, tmax), if any (`dir` is a unit vector).
    pub fn intersect(&self, org: DVec3, dir: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        match self {
            Shape::Polygon(p) => p.intersect(org, dir, tmin, tmax),
            Shape::Sphere { c, r, .. } => {
                let oc = org - *c;
                let b = oc.dot(dir);
                let cc = oc.length_squared() - r * r;
                let disc = b * b - cc;
                if disc < 0.0 {
                    return None;
                }
                let s = disc.sqrt();
                // stable roots
                let q = if b > 0.0 { -b - s } else { -b + s };
                let (mut t0, mut t1) = (q, if q != 0.0 { cc / q } else { 0.0 });
                if t0 > t1 {
                    std::mem::swap(&mut t0, &mut t1);
                }
                [t0, t1].into_iter().find(|&t| t > tmin && t < tmax)
            }
            Shape::Cone {
                p0,
                axis,
                len,
                r0,
                r1,
                ..
            } => cone_hit((*p0, *axis, *len, *r0, *r1), org, dir, (tmin, tmax)),
            Shape::Ring { c, n, r0, r1 } => {
                let dn = dir.dot(*n);
                if dn.abs() < PARALLEL_EPS {
                    return None;
                }
                let t = (*c - org).dot(*n) / dn;
                if !(t > tmin && t < tmax) {
                    return None;
                }
                let p = org + dir * t - *c;
                let d2 = (p - *n * p.dot(*n)).length_squared();
                (d2 >= r0 * r0 && d2 <= r1 * r1).then_some(t)
            }
        }
    }

    /// Geometric (oriented) unit normal at a point on the surface.
    pub fn normal(&self, p: DVec3) -> DVec3 {
        match self {
            Shape::Polygon(poly) => poly.normal,
            Shape::Sphere { c, inward, .. } => {
                let n = (p - *c).normalize_or(DVec3::Z);
                if *inward {
                    -n
                } else {
                    n
                }
            }
            Shape::Cone {
                p0,
                axis,
                len,
                r0,
                r1,
                inward,
            } => {
                let v = p - *p0;
                let radial = (v - *axis * v.dot(*axis)).normalize_or(axis.any_orthonormal_vector());
                // slope: radius decreases by (r0-r1)/len along the axis
                let n = (radial * *len + *axis * (r0 - r1)).normalize();
                if *inward {
                    -n
                } else {
                    n
                }
            }
            Shape::Ring { n, .. } => *n,
        }
    }

    /// Whether the surface is flat (a ray leaving it cannot hit it again).
    pub fn is_flat(&self) -> bool {
        matches!(self, Shape::Polygon(_) | Shape::Ring { .. })
    }

    /// Axis-aligned bounds (min, max), exact in f64.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        match self {
            Shape::Polygon(p) => p.bounds(),
            Shape::Sphere { c, r, .. } => (*c - DVec3::splat(*r), *c + DVec3::splat(*r)),
            Shape::Cone {
                p0,
                axis,
                len,
                r0,
                r1,
                ..
            } => {
                let p1 = *p0 + *axis * *len;
                let (a, b) = (disk_bounds(*p0, *axis, *r0), disk_bounds(p1, *axis, *r1));
                (a.0.min(b.0), a.1.max(b.1))
            }
            Shape::Ring { c, n, r1, .. } => disk_bounds(*c, *n, *r1),
        }
    }

    /// Surface area (for sources and sampling).
    pub fn area(&self) -> f64 {
        match self {
            Shape::Polygon(p) => p.area,
            Shape::Sphere { r, .. } => 4.0 * std::f64::consts::PI * r * r,
            Shape::Cone { len, r0, r1, .. } => {
                std::f64::consts::PI * (r0 + r1) * (len * len + (r0 - r1) * (r0 - r1)).sqrt()
            }
            Shape::Ring { r0, r1, .. } => std::f64::consts::PI * (r1 * r1 - r0 * r0),
        }
    }
}

fn disk_bounds(c: DVec3, n: DVec3, r: f64) -> (DVec3, DVec3) {
    // extent of a disk of radius r with normal n along axis i is r*sqrt(1-n_i^2)
    let e = DVec3::new(
        (1.0 - n.x * n.x).max(0.0).sqrt(),
        (1.0 - n.y * n.y).max(0.0).sqrt(),
        (1.0 - n.z * n.z).max(0.0).sqrt(),
    ) * r;
    (c - e, c + e)
}

/// The nearest hit within (tmin, tmax) of the cone (base `p0`, unit `axis`, length,
/// radii at both ends).
fn cone_hit(
    (p0, axis, len, r0, r1): (DVec3, DVec3, f64, f64, f64),
    org: DVec3,
    dir: DVec3,
    (tmin, tmax): (f64, f64),
) -> Option<f64> {
    // radius along axis: r(h) = r0 + k h, k = (r1-r0)/len; surface |v_perp|^2 = r(h)^2
    let k = (r1 - r0) / len;
    let o = org - p0;
    let (oh, dh) = (o.dot(axis), dir.dot(axis));
    let (op, dp) = (o - axis * oh, dir - axis * dh);
    let ro = r0 + k * oh;
    let a = dp.length_squared() - k * k * dh * dh;
    let b = 2.0 * (op.dot(dp) - k * dh * ro);
    let c = op.length_squared() - ro * ro;
    let mut roots = [f64::NAN; 2];
    if a.abs() < 1e-14 {
        if b.abs() < 1e-300 {
            return None;
        }
        roots[0] = -c / b;
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        let q = -0.5 * (b + if b >= 0.0 { s } else { -s });
        roots = [q / a, if q != 0.0 { c / q } else { f64::NAN }];
        if roots[0] > roots[1] {
            roots.swap(0, 1);
        }
    }
    roots.into_iter().find(|&t| {
        if !(t > tmin && t < tmax) {
            return false;
        }
        let h = oh + dh * t;
        (0.0..=len).contains(&h) && r0 + k * h >= 0.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_from_outside_and_inside() {
        let s = Shape::Sphere {
            c: DVec3::new(0.0, 0.0, 5.0),
            r: 1.0,
            inward: false,
        };
        let t = s
            .intersect(DVec3::ZERO, DVec3::Z, 0.0, f64::INFINITY)
            .unwrap();
        assert!((t - 4.0).abs() < 1e-12);
        let t = s
            .intersect(DVec3::new(0.0, 0.0, 5.0), DVec3::Z, 1e-9, f64::INFINITY)
            .unwrap();
        assert!((t - 1.0).abs() < 1e-12);
        assert!((s.normal(DVec3::new(0.0, 0.0, 4.0)) + DVec3::Z).length() < 1e-12);
    }

    /// An outward cone (or cylinder) on the z axis from the origin.
    fn z_cone(len: f64, r0: f64, r1: f64) -> Shape {
        Shape::Cone {
            p0: DVec3::ZERO,
            axis: DVec3::Z,
            len,
            r0,
            r1,
            inward: false,
        }
    }

    /// Intersection of a ray along +x from (-5, 0, z).
    fn hit_along_x(s: &Shape, z: f64) -> Option<f64> {
        s.intersect(DVec3::new(-5.0, 0.0, z), DVec3::X, 0.0, f64::INFINITY)
    }

    #[test]
    fn cylinder_and_cone() {
        let cyl = z_cone(2.0, 1.0, 1.0);
        let t = hit_along_x(&cyl, 1.0).unwrap();
        assert!((t - 4.0).abs() < 1e-12);
        assert!(hit_along_x(&cyl, 3.0).is_none());
        let n = cyl.normal(DVec3::new(-1.0, 0.0, 1.0));
        assert!((n + DVec3::X).length() < 1e-12);
        let cone = z_cone(1.0, 1.0, 0.0);
        let t = hit_along_x(&cone, 0.5).unwrap();
        assert!((t - 4.5).abs() < 1e-12);
        let n = cone.normal(DVec3::new(-0.5, 0.0, 0.5));
        let want = DVec3::new(-1.0, 0.0, 1.0).normalize();
        assert!((n - want).length() < 1e-12, "{n}");
    }

    #[test]
    fn ring_annulus() {
        let r = Shape::Ring {
            c: DVec3::ZERO,
            n: DVec3::Z,
            r0: 0.5,
            r1: 1.0,
        };
        assert!(r
            .intersect(DVec3::new(0.0, 0.0, 1.0), -DVec3::Z, 0.0, 9.0)
            .is_none());
        assert!(r
            .intersect(DVec3::new(0.75, 0.0, 1.0), -DVec3::Z, 0.0, 9.0)
            .is_some());
    }
}
