//! Planar polygons: convex or concave, intersected in f64 relative to their first vertex.
//!
//! The inside test is a crossing-number test in the plane's dominant projection, with
//! points within a tiny relative distance of an edge counted inside, so a ray through a
//! shared edge or vertex never leaks between neighbouring polygons.

use glam::{DVec2, DVec3};

use crate::shape::PARALLEL_EPS;

/// A planar polygon.
#[derive(Debug, Clone)]
pub struct Polygon {
    /// Local origin (first vertex).
    pub origin: DVec3,
    /// Vertices in world coordinates.
    pub verts: Vec<DVec3>,
    /// Unit normal by the right-hand rule.
    pub normal: DVec3,
    /// Area.
    pub area: f64,
    /// Projection axes (indices of the two coordinates kept).
    axes: (usize, usize),
    /// Projected vertices relative to `origin`.
    pts: Vec<DVec2>,
    /// Edge tolerance in projected units.
    tol: f64,
    /// Projected bounding box (relative to `origin`), grown by `tol`.
    lo: DVec2,
    hi: DVec2,
    /// For a convex polygon: each non-degenerate edge's inward unit normal and offset in
    /// the projection (`n·q - c` is the signed distance of `q` inside that edge); empty
    /// for a concave one (which uses the crossing-number test).
    edges: Vec<(DVec2, f64)>,
}

/// Inward edge lines of a convex projected polygon, or an empty list if it is not convex
/// (or winds more than once).
fn convex_edges(pts: &[DVec2]) -> Vec<(DVec2, f64)> {
    let n = pts.len();
    let mut sign = 0.0;
    let mut turn = 0.0;
    let mut prev: Option<DVec2> = None;
    let mut dirs = Vec::with_capacity(n);
    for i in 0..n {
        let e = pts[(i + 1) % n] - pts[i];
        if e.length_squared() > 0.0 {
            dirs.push((i, e));
        }
    }
    if dirs.len() < 3 {
        return Vec::new();
    }
    for k in 0..=dirs.len() {
        let e = dirs[k % dirs.len()].1;
        if let Some(p) = prev {
            let c = p.perp_dot(e);
            if c != 0.0 {
                if sign == 0.0 {
                    sign = c.signum();
                } else if c.signum() != sign {
                    return Vec::new();
                }
            }
            turn += c.atan2(p.dot(e));
        }
        prev = Some(e);
    }
    if sign == 0.0 || (turn.abs() - 2.0 * std::f64::consts::PI).abs() > 1e-6 {
        return Vec::new();
    }
    dirs.iter()
        .map(|&(i, e)| {
            // inward normal: left of the edge for counter-clockwise order
            let nrm = DVec2::new(-e.y, e.x) * sign / e.length();
            (nrm, nrm.dot(pts[i]))
        })
        .collect()
}

/// Why a polygon cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub enum PolygonError {
    /// Fewer than 3 vertices.
    TooFewVertices(usize),
    /// Zero area (collinear or repeated vertices).
    Degenerate,
    /// Vertices not in one plane.
    NonPlanar(f64),
}

impl std::fmt::Display for PolygonError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PolygonError::TooFewVertices(n) => {
                write!(f, "polygon has {n} vertices (needs 3 or more)")
            }
            PolygonError::Degenerate => {
                write!(
                    f,
                    "degenerate polygon (zero area: collinear or repeated vertices)"
                )
            }
            PolygonError::NonPlanar(d) => {
                write!(f, "non-planar polygon (a vertex is {d:.3e} off the plane)")
            }
        }
    }
}

impl Polygon {
    /// Builds a polygon; a degenerate one is an error (the caller warns and skips it).
    /// A slightly non-planar polygon is accepted (as Radiance does) and reported only
    /// when the deviation exceeds 1e-3 of its size.
    pub fn new(verts: Vec<DVec3>) -> Result<(Polygon, Option<PolygonError>), PolygonError> {
        if verts.len() < 3 {
            return Err(PolygonError::TooFewVertices(verts.len()));
        }
        let origin = verts[0];
        // Newell's method on coordinates relative to the first vertex.
        let mut nrm = DVec3::ZERO;
        for i in 0..verts.len() {
            let a = verts[i] - origin;
            let b = verts[(i + 1) % verts.len()] - origin;
            nrm += a.cross(b);
        }
        let len = nrm.length();
        let mut size: f64 = 0.0;
        for v in &verts {
            size = size.max((*v - origin).length());
        }
        if !(len.is_finite()) || size == 0.0 || len <= 1e-12 * size * size {
            return Err(PolygonError::Degenerate);
        }
        let normal = nrm / len;
        let area = 0.5 * len;
        let mut dev: f64 = 0.0;
        for v in &verts {
            dev = dev.max((*v - origin).dot(normal).abs());
        }
        let warn = (dev > 1e-3 * size).then_some(PolygonError::NonPlanar(dev));
        let an = normal.abs();
        let axes = if an.x >= an.y && an.x >= an.z {
            (1, 2)
        } else if an.y >= an.z {
            (2, 0)
        } else {
            (0, 1)
        };
        let pts: Vec<DVec2> = verts
            .iter()
            .map(|v| {
                let d = *v - origin;
                DVec2::new(d[axes.0], d[axes.1])
            })
            .collect();
        let tol = 1e-10 * size;
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for q in &pts {
            lo = lo.min(*q);
            hi = hi.max(*q);
        }
        let edges = convex_edges(&pts);
        Ok((
            Polygon {
                origin,
                verts,
                normal,
                area,
                axes,
                pts,
                tol,
                lo: lo - DVec2::splat(tol),
                hi: hi + DVec2::splat(tol),
                edges,
            },
            warn,
        ))
    }

    /// Nearest intersection in (tmin, tmax).
    pub fn intersect(&self, org: DVec3, dir: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        let dn = dir.dot(self.normal);
        if dn.abs() < PARALLEL_EPS {
            return None;
        }
        let rel = org - self.origin;
        let t = -rel.dot(self.normal) / dn;
        if !(t > tmin && t < tmax) {
            return None;
        }
        let p = (rel + dir * t).to_array();
        let q = DVec2::new(p[self.axes.0], p[self.axes.1]);
        self.contains(q).then_some(t)
    }

    /// Whether `p` (taken onto the polygon's plane) lies inside it or on its edge.
    pub fn contains_point(&self, p: DVec3) -> bool {
        let d = (p - self.origin).to_array();
        self.contains(DVec2::new(d[self.axes.0], d[self.axes.1]))
    }

    fn contains(&self, q: DVec2) -> bool {
        if q.x < self.lo.x || q.y < self.lo.y || q.x > self.hi.x || q.y > self.hi.y {
            return false;
        }
        if !self.edges.is_empty() {
            let lim = -self.tol;
            return self.edges.iter().all(|(n, c)| n.dot(q) - c >= lim);
        }
        let n = self.pts.len();
        let mut inside = false;
        let mut j = n - 1;
        for i in 0..n {
            let (a, b) = (self.pts[j], self.pts[i]);
            if (b.y > q.y) != (a.y > q.y) {
                let x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if q.x < x {
                    inside = !inside;
                }
            }
            j = i;
        }
        inside || self.on_edge(q)
    }

    fn on_edge(&self, q: DVec2) -> bool {
        let n = self.pts.len();
        (0..n).any(|i| {
            let (a, b) = (self.pts[i], self.pts[(i + 1) % n]);
            let ab = b - a;
            let l2 = ab.length_squared();
            let s = if l2 > 0.0 {
                ((q - a).dot(ab) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (a + ab * s - q).length_squared() <= self.tol * self.tol
        })
    }

    /// Exact bounds.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in &self.verts {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        (lo, hi)
    }

    /// Centroid of the vertices (area-weighted for the fan; used for sources).
    pub fn centroid(&self) -> DVec3 {
        let mut acc = DVec3::ZERO;
        let mut w = 0.0;
        let o = self.origin;
        for i in 1..self.verts.len() - 1 {
            let (a, b) = (self.verts[i] - o, self.verts[i + 1] - o);
            let ar = a.cross(b).dot(self.normal) * 0.5;
            acc += (a + b) / 3.0 * ar;
            w += ar;
        }
        if w.abs() > 0.0 {
            o + acc / w
        } else {
            o
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sq(z: f64) -> Polygon {
        Polygon::new(vec![
            DVec3::new(0.0, 0.0, z),
            DVec3::new(1.0, 0.0, z),
            DVec3::new(1.0, 1.0, z),
            DVec3::new(0.0, 1.0, z),
        ])
        .unwrap()
        .0
    }

    #[test]
    fn square_hit_and_normal() {
        let p = sq(0.0);
        assert_eq!(p.normal, DVec3::Z);
        assert!((p.area - 1.0).abs() < 1e-15);
        let t = p
            .intersect(DVec3::new(0.5, 0.5, 2.0), -DVec3::Z, 0.0, f64::INFINITY)
            .unwrap();
        assert_eq!(t, 2.0);
        assert!(p
            .intersect(DVec3::new(1.5, 0.5, 2.0), -DVec3::Z, 0.0, f64::INFINITY)
            .is_none());
    }

    #[test]
    fn concave_l_shape() {
        // L: the square (1..2)x(1..2) is missing
        let p = Polygon::new(vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ])
        .unwrap()
        .0;
        let hit = |x: f64, y: f64| {
            p.intersect(DVec3::new(x, y, 1.0), -DVec3::Z, 0.0, 9.0)
                .is_some()
        };
        assert!(hit(0.5, 0.5) && hit(1.5, 0.5) && hit(0.5, 1.5));
        assert!(!hit(1.5, 1.5));
        assert!((p.area - 3.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_polygons_are_rejected() {
        let col = Polygon::new(vec![DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)]);
        assert_eq!(col.err(), Some(PolygonError::Degenerate));
        let rep = Polygon::new(vec![DVec3::ZERO, DVec3::ZERO, DVec3::ZERO]);
        assert_eq!(rep.err(), Some(PolygonError::Degenerate));
        let two = Polygon::new(vec![DVec3::ZERO, DVec3::X]);
        assert_eq!(two.err(), Some(PolygonError::TooFewVertices(2)));
    }

    #[test]
    fn convex_edge_test_agrees_with_crossing_test() {
        let hex: Vec<DVec3> = (0..6)
            .map(|k| {
                let a = k as f64 * std::f64::consts::PI / 3.0;
                DVec3::new(a.cos(), 0.3 * a.cos() + 0.2, a.sin())
            })
            .collect();
        let tri = vec![
            DVec3::ZERO,
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 1.0, 0.5),
        ];
        // clockwise quad with a repeated vertex
        let quad = vec![
            DVec3::ZERO,
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
        ];
        for verts in [hex, tri, quad] {
            let p = Polygon::new(verts).unwrap().0;
            assert!(!p.edges.is_empty());
            let mut q = p.clone();
            q.edges.clear();
            let mut rng = crate::rng::Rng::for_ray(5, 5);
            let mut inside = 0;
            for _ in 0..20000 {
                let pt = DVec2::new(rng.next_f64() * 5.0 - 2.5, rng.next_f64() * 5.0 - 2.5);
                assert_eq!(p.contains(pt), q.contains(pt), "{pt}");
                inside += usize::from(p.contains(pt));
            }
            assert!(inside > 300, "{inside}");
        }
        // a concave polygon and a pentagram keep the crossing test
        let l = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)];
        let star: Vec<(f64, f64)> = (0..5)
            .map(|k| {
                let a = k as f64 * 4.0 * std::f64::consts::PI / 5.0;
                (a.cos(), a.sin())
            })
            .collect();
        for pts in [l.to_vec(), star] {
            let verts = pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
            assert!(Polygon::new(verts).unwrap().0.edges.is_empty());
        }
    }

    #[test]
    fn vertex_and_edge_hits_are_inside() {
        let p = sq(0.0);
        for (x, y) in [(0.0, 0.0), (1.0, 1.0), (0.5, 0.0), (1.0, 0.5), (0.0, 1.0)] {
            assert!(
                p.intersect(DVec3::new(x, y, 1.0), -DVec3::Z, 0.0, 9.0)
                    .is_some(),
                "({x},{y})"
            );
        }
    }
}
