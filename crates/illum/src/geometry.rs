//! The surfaces mkillum converts: polygons (with mkillum's choice of axes and a point-in-
//! polygon test), rings and spheres.

use anyhow::{bail, Result};
use glam::DVec3;

/// Radiance's FTINY.
const FTINY: f64 = 1e-6;

/// A unit vector perpendicular to `n`.
pub fn perpendicular(n: DVec3) -> DVec3 {
    let a = if n.x.abs() < 0.6 {
        DVec3::X
    } else if n.y.abs() < 0.6 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let u = a - n * a.dot(n);
    u.normalize()
}

/// A polygon prepared for sampling.
#[derive(Debug, Clone)]
pub struct Face {
    /// Vertices (a repeated closing vertex dropped).
    pub verts: Vec<DVec3>,
    /// Unit normal (right-hand rule over the vertex order).
    pub norm: DVec3,
    /// Area.
    pub area: f64,
    /// Mean distance of the vertices from the origin along the normal.
    pub offset: f64,
    /// In-plane axes: `u` along the first edge at least √area long, `v = norm × u`.
    pub u: DVec3,
    /// Second in-plane axis.
    pub v: DVec3,
    /// Extent along `u`.
    pub ur: [f64; 2],
    /// Extent along `v`.
    pub vr: [f64; 2],
    pts: Vec<(f64, f64)>,
}

impl Face {
    /// The face of a polygon's real arguments; `Ok(None)` for a zero-area one.
    pub fn new(args: &[f64]) -> Result<Option<Face>> {
        if args.len() < 9 || args.len() % 3 != 0 {
            bail!(
                "bad # arguments (a polygon needs 3 coordinates per vertex, at least 3 vertices)"
            );
        }
        let mut verts: Vec<DVec3> = args
            .chunks(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect();
        if verts.len() > 3 && verts[0].distance_squared(verts[verts.len() - 1]) <= FTINY * FTINY {
            verts.pop();
        }
        let mut sum = DVec3::ZERO;
        let mut e1 = verts[1] - verts[0];
        for w in &verts[2..] {
            let e2 = *w - verts[0];
            sum += e1.cross(e2);
            e1 = e2;
        }
        let len = sum.length();
        if len == 0.0 || !len.is_finite() {
            return Ok(None);
        }
        let norm = sum / len;
        let area = 0.5 * len;
        let offset = verts.iter().map(|p| norm.dot(*p)).sum::<f64>() / verts.len() as f64;
        let n = verts.len();
        let mut u = None;
        for i in 0..n {
            let j = (i + n - 1) % n;
            let e = verts[i] - verts[j];
            let r = e.length_squared();
            if r >= area - FTINY {
                u = Some(e / r.sqrt());
                break;
            }
        }
        let u = u.unwrap_or_else(|| perpendicular(norm));
        let v = norm.cross(u);
        let pts: Vec<(f64, f64)> = verts.iter().map(|p| (p.dot(u), p.dot(v))).collect();
        let mut ur = [f64::INFINITY, f64::NEG_INFINITY];
        let mut vr = [f64::INFINITY, f64::NEG_INFINITY];
        for &(a, b) in &pts {
            ur = [ur[0].min(a), ur[1].max(a)];
            vr = [vr[0].min(b), vr[1].max(b)];
        }
        Ok(Some(Face {
            verts,
            norm,
            area,
            offset,
            u,
            v,
            ur,
            vr,
            pts,
        }))
    }

    /// The point at in-plane coordinates (a, b) (on the polygon's plane).
    pub fn point(&self, a: f64, b: f64) -> DVec3 {
        a * self.u + b * self.v + self.offset * self.norm
    }

    /// A point uniform over the polygon: the first candidate from (`x`, `y`) in [0,1)² over
    /// its (u, v) box, the later ones (rejection) from `rng`, at most `tries` in all; each
    /// accepted point is uniform over the polygon whichever try it came from. Also the
    /// number of candidates rejected (`tries` when none was kept).
    pub fn uniform_point(
        &self,
        (x, y): (f64, f64),
        rng: &mut fenestra_trace::rng::Rng,
        tries: usize,
    ) -> (Option<DVec3>, usize) {
        let (mut x, mut y) = (x, y);
        for t in 0..tries {
            if t > 0 {
                (x, y) = (rng.next_f64(), rng.next_f64());
            }
            let a = self.ur[0] + (self.ur[1] - self.ur[0]) * x;
            let b = self.vr[0] + (self.vr[1] - self.vr[0]) * y;
            if self.contains(a, b) {
                return (Some(self.point(a, b)), t);
            }
        }
        (None, tries)
    }

    /// Whether in-plane coordinates (a, b) fall inside the polygon (crossing count).
    pub fn contains(&self, a: f64, b: f64) -> bool {
        let n = self.pts.len();
        let mut inside = false;
        let mut j = n - 1;
        for i in 0..n {
            let (xi, yi) = self.pts[i];
            let (xj, yj) = self.pts[j];
            if (yi > b) != (yj > b) {
                let x = xj + (b - yj) * (xi - xj) / (yi - yj);
                if a < x {
                    inside = !inside;
                }
            }
            j = i;
        }
        inside
    }
}

/// A ring (disk with a hole).
#[derive(Debug, Clone)]
pub struct Ring {
    /// Centre.
    pub centre: DVec3,
    /// Unit axis (normal).
    pub axis: DVec3,
    /// Inner radius.
    pub r0: f64,
    /// Outer radius.
    pub r1: f64,
    /// In-plane axes.
    pub u: DVec3,
    /// Second in-plane axis (`axis × u`).
    pub v: DVec3,
}

impl Ring {
    /// A ring from its real arguments (centre, normal, inner and outer radius).
    pub fn new(args: &[f64]) -> Result<Ring> {
        if args.len() != 8 {
            bail!("bad # arguments (a ring needs 8 real arguments)");
        }
        let axis = DVec3::new(args[3], args[4], args[5]);
        if axis.length() == 0.0 || !axis.is_finite() {
            bail!("zero normal (cannot create illum)");
        }
        let (r0, r1) = (args[6], args[7]);
        if r0 < 0.0 || r1 <= r0 {
            bail!("illegal radii ({r0} {r1}: need 0 <= inner < outer)");
        }
        let axis = axis.normalize();
        let u = perpendicular(axis);
        Ok(Ring {
            centre: DVec3::new(args[0], args[1], args[2]),
            axis,
            r0,
            r1,
            u,
            v: axis.cross(u),
        })
    }

    /// A point on the annulus from two numbers in [0,1) (uniform in area).
    pub fn point(&self, s0: f64, s1: f64) -> DVec3 {
        let r = (self.r0 * self.r0 + s0 * (self.r1 * self.r1 - self.r0 * self.r0)).sqrt();
        let t = std::f64::consts::TAU * s1;
        self.centre + r * t.cos() * self.u + r * t.sin() * self.v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_axes_follow_mkillum() {
        // the reference window: first edge (from the last vertex) is 2 long, area 3
        let f = Face::new(&[1., 0.01, 0.9, 1., 0.01, 2.4, 3., 0.01, 2.4, 3., 0.01, 0.9])
            .unwrap()
            .unwrap();
        assert!((f.area - 3.0).abs() < 1e-12);
        assert_eq!(f.norm, DVec3::new(0.0, 1.0, 0.0));
        assert_eq!(f.u, DVec3::new(-1.0, 0.0, 0.0));
        assert_eq!(f.v, DVec3::new(0.0, -0.0, 1.0));
        assert!(f.contains(-2.0, 1.5));
        assert!(!f.contains(-0.5, 1.5));
        assert!((f.offset - 0.01).abs() < 1e-15);
    }

    #[test]
    fn degenerate_faces_and_rings() {
        assert!(Face::new(&[0., 0., 0., 1., 0., 0., 2., 0., 0.])
            .unwrap()
            .is_none());
        assert!(Face::new(&[0., 0., 0., 1., 0.]).is_err());
        assert!(Ring::new(&[0., 0., 0., 0., 0., 1., 1., 0.5]).is_err());
        assert!(Ring::new(&[0., 0., 0., 0., 0., 0., 0., 1.]).is_err());
        let r = Ring::new(&[0., 0., 0., 0., 0., 2., 0., 1.]).unwrap();
        assert!((r.point(0.999, 0.3).length() - 0.9995).abs() < 1e-3);
    }
}
