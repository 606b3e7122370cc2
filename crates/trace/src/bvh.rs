//! The acceleration structure, with every primitive test done in f64: for a scene of at
//! most [`FLAT_MAX`] shapes, all shape boxes (f64) are tested against each ray in one
//! branch-free loop and only the shapes whose boxes the ray enters are intersected; a
//! larger scene uses an obvhs compressed-wide BVH over f32 boxes rounded outward.
//!
//! Boxes are padded by a margin that covers the rounding of the f32 ray (origin and
//! direction) used for traversal, so a surface the f64 test would hit is never culled.
//! Neither path has a minimum distance: a surface a few µm from a ray's origin (a room's
//! corner) is found.

use glam::{DVec3, Vec3A};
use obvhs::{aabb::Aabb, cwbvh::CwBvh, ray::Ray, Boundable, BvhBuildParams};

use crate::shape::Shape;

/// A closest-hit result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Index of the shape in the accelerator's list.
    pub shape: usize,
    /// Distance along the (unit) ray.
    pub t: f64,
}

struct BoxPrim(Aabb);

impl Boundable for BoxPrim {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// Shapes with their BVH.
pub struct Accel {
    /// The shapes, indexed as the caller gave them.
    pub shapes: Vec<Shape>,
    index: Index,
    /// Largest absolute coordinate of the scene (for relative epsilons).
    pub scale: f64,
}

/// How rays find candidate shapes.
enum Index {
    /// A small scene: every shape's box, tested all at once.
    Flat(Flat),
    /// obvhs's BVH.
    Bvh(CwBvh),
}

/// How far behind its origin a ray enters the BVH (more than obvhs's 1e-4 minimum box
/// distance).
const BACK: f64 = 1e-3;

/// Up to this many shapes, every shape's box is tested for each ray (a loop without
/// branches the compiler vectorises) instead of traversing the BVH.
const FLAT_MAX: usize = 32;

/// Shape boxes (f64, padded) by coordinate, for scenes of at most [`FLAT_MAX`] shapes.
struct Flat {
    lo: [Vec<f64>; 3],
    hi: [Vec<f64>; 3],
}

impl Flat {
    /// The distance at which the ray `o + t d` (`inv` = 1/d, every component finite)
    /// enters each box within [0, tmax], or ∞ where it does not.
    #[inline(always)]
    fn entries(&self, o: DVec3, inv: DVec3, tmax: f64, ent: &mut [f64]) {
        let n = ent.len();
        let (lx, ly, lz) = (&self.lo[0][..n], &self.lo[1][..n], &self.lo[2][..n]);
        let (hx, hy, hz) = (&self.hi[0][..n], &self.hi[1][..n], &self.hi[2][..n]);
        // plain comparisons (no NaN can arise: finite boxes, origin and inverse)
        let mn = |a: f64, b: f64| if a < b { a } else { b };
        let mx = |a: f64, b: f64| if a > b { a } else { b };
        for i in 0..n {
            let (ax, bx) = ((lx[i] - o.x) * inv.x, (hx[i] - o.x) * inv.x);
            let (ay, by) = ((ly[i] - o.y) * inv.y, (hy[i] - o.y) * inv.y);
            let (az, bz) = ((lz[i] - o.z) * inv.z, (hz[i] - o.z) * inv.z);
            let t0 = mx(mx(mx(mn(ax, bx), mn(ay, by)), mn(az, bz)), 0.0);
            let t1 = mn(mn(mn(mx(ax, bx), mx(ay, by)), mx(az, bz)), tmax);
            ent[i] = if t0 <= t1 { t0 } else { f64::INFINITY };
        }
    }
}

/// 1/x with |x| raised to at least 1e-300, so the inverse is finite and a box test never
/// meets 0 × ∞ (a ray parallel to an axis gets a slope of 1e-300 instead of 0).
fn safe_inv(x: f64) -> f64 {
    if x.abs() < 1e-300 {
        1e300
    } else {
        1.0 / x
    }
}

/// The next f32 towards +inf (f32::next_up needs Rust 1.86; MSRV is 1.85).
fn f32_next_up(f: f32) -> f32 {
    if f.is_nan() || f == f32::INFINITY {
        return f;
    }
    if f == 0.0 {
        return f32::from_bits(1);
    }
    let b = f.to_bits();
    f32::from_bits(if f > 0.0 { b + 1 } else { b - 1 })
}

/// The next f32 towards -inf.
fn f32_next_down(f: f32) -> f32 {
    -f32_next_up(-f)
}

fn down(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) > x {
        f32_next_down(f)
    } else {
        f
    }
}

fn up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f32_next_up(f)
    } else {
        f
    }
}

impl Accel {
    /// Builds the BVH over `shapes`.
    pub fn new(shapes: Vec<Shape>) -> Accel {
        let bounds: Vec<(DVec3, DVec3)> = shapes.iter().map(Shape::bounds).collect();
        let mut scale: f64 = 1.0;
        for (lo, hi) in &bounds {
            scale = scale
                .max(lo.abs().max_element())
                .max(hi.abs().max_element());
        }
        let pad = 2e-6 * scale;
        let index = if shapes.len() <= FLAT_MAX {
            Index::Flat(Flat {
                lo: [0, 1, 2].map(|a| bounds.iter().map(|(lo, _)| lo[a] - pad).collect()),
                hi: [0, 1, 2].map(|a| bounds.iter().map(|(_, hi)| hi[a] + pad).collect()),
            })
        } else {
            let prims: Vec<BoxPrim> = bounds
                .iter()
                .map(|(lo, hi)| {
                    let lo = *lo - DVec3::splat(pad);
                    let hi = *hi + DVec3::splat(pad);
                    BoxPrim(Aabb::new(
                        Vec3A::new(down(lo.x), down(lo.y), down(lo.z)),
                        Vec3A::new(up(hi.x), up(hi.y), up(hi.z)),
                    ))
                })
                .collect();
            Index::Bvh(obvhs::cwbvh::builder::build_cwbvh(
                &prims,
                BvhBuildParams::medium_build(),
                &mut std::time::Duration::default(),
            ))
        };
        Accel {
            shapes,
            index,
            scale,
        }
    }

    /// How far past distance `t` a shape's (padded) box may still be entered.
    fn reach(&self, t: f64) -> f64 {
        t * (1.0 + 1e-6) + 4e-6 * self.scale
    }

    /// Entry distances of every shape's box along a ray (the flat index), up to `tmax`;
    /// returns the box limit used.
    fn flat_entries(&self, flat: &Flat, org: DVec3, dir: DVec3, tmax: f64, ent: &mut [f64]) -> f64 {
        let inv = DVec3::new(safe_inv(dir.x), safe_inv(dir.y), safe_inv(dir.z));
        let box_max = if tmax.is_finite() {
            self.reach(tmax)
        } else {
            f64::INFINITY
        };
        flat.entries(org, inv, box_max, ent);
        box_max
    }

    /// The f32 ray the BVH is traversed with: started `BACK` behind `org`, since obvhs's
    /// traversal skips boxes the ray leaves within its first 1e-4 (a surface a few µm from
    /// the origin, as in a room's corner, would be missed); its limit covers `tmax`.
    fn box_ray(&self, org: DVec3, dir: DVec3, tmax: f64) -> Ray {
        let o = org - dir * BACK;
        Ray::new(
            Vec3A::new(o.x as f32, o.y as f32, o.z as f32),
            // +0.0 turns -0.0 into 0.0: obvhs inverts the sign of a zero
            // component but tests `< 0`, so -0.0 would miss every box.
            Vec3A::new(dir.x as f32 + 0.0, dir.y as f32 + 0.0, dir.z as f32 + 0.0),
            0.0,
            if tmax.is_finite() {
                up(self.reach(tmax) + BACK)
            } else {
                f32::INFINITY
            },
        )
    }

    /// Closest hit in (tmin, tmax) for a unit direction, skipping shape `skip`.
    /// Ties at equal distance go to the lower shape index (Radiance's scene order).
    pub fn closest(
        &self,
        org: DVec3,
        dir: DVec3,
        tmin: f64,
        tmax: f64,
        skip: Option<usize>,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let test = |i: usize, best: &mut Option<Hit>| {
            if Some(i) == skip {
                return;
            }
            let lim = best.map_or(tmax, |b| b.t);
            // allow an exact tie through so the lower index can win
            let lim_incl = if lim.is_finite() {
                lim * (1.0 + 1e-15) + 1e-300
            } else {
                lim
            };
            if let Some(t) = self.shapes[i].intersect(org, dir, tmin, lim_incl) {
                match best {
                    Some(b) if t > b.t || (t == b.t && i > b.shape) => {}
                    _ => *best = Some(Hit { shape: i, t }),
                }
            }
        };
        match &self.index {
            Index::Flat(flat) => {
                let mut ent = [0.0f64; FLAT_MAX];
                let ent = &mut ent[..self.shapes.len()];
                let mut lim = self.flat_entries(flat, org, dir, tmax, ent);
                for (i, &e) in ent.iter().enumerate() {
                    if e <= lim && e < f64::INFINITY {
                        test(i, &mut best);
                        if let Some(b) = best {
                            lim = self.reach(b.t);
                        }
                    }
                }
            }
            Index::Bvh(bvh) => {
                let ray = self.box_ray(org, dir, tmax);
                let mut rh = obvhs::ray::RayHit::none();
                bvh.ray_traverse(ray, &mut rh, |_r, id| {
                    let i = bvh.primitive_indices[id] as usize;
                    test(i, &mut best);
                    match best {
                        Some(b) => up(self.reach(b.t) + BACK),
                        None => f32::INFINITY,
                    }
                });
            }
        }
        best
    }

    /// Whether anything lies in (tmin, tmax) along a unit direction, skipping `skip`
    /// (stops at the first surface found).
    pub fn occluded(
        &self,
        org: DVec3,
        dir: DVec3,
        tmin: f64,
        tmax: f64,
        skip: Option<usize>,
    ) -> bool {
        let test =
            |i: usize| Some(i) != skip && self.shapes[i].intersect(org, dir, tmin, tmax).is_some();
        match &self.index {
            Index::Flat(flat) => {
                let mut ent = [0.0f64; FLAT_MAX];
                let ent = &mut ent[..self.shapes.len()];
                self.flat_entries(flat, org, dir, tmax, ent);
                ent.iter()
                    .enumerate()
                    .any(|(i, &e)| e < f64::INFINITY && test(i))
            }
            Index::Bvh(bvh) => {
                let ray = self.box_ray(org, dir, tmax);
                !bvh.ray_traverse_miss(ray, |_r, id| {
                    if test(bvh.primitive_indices[id] as usize) {
                        0.0
                    } else {
                        f32::INFINITY
                    }
                })
            }
        }
    }

    /// Number of shapes.
    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    /// Whether there are no shapes.
    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polygon::Polygon;

    pub fn quad(c: DVec3, hx: f64, hy: f64) -> Shape {
        Shape::Polygon(
            Polygon::new(vec![
                c + DVec3::new(-hx, -hy, 0.0),
                c + DVec3::new(hx, -hy, 0.0),
                c + DVec3::new(hx, hy, 0.0),
                c + DVec3::new(-hx, hy, 0.0),
            ])
            .unwrap()
            .0,
        )
    }

    #[test]
    fn bvh_matches_linear_scan() {
        let mut shapes = Vec::new();
        for i in 0..200 {
            let f = i as f64;
            shapes.push(quad(
                DVec3::new((f * 0.37).sin() * 5.0, (f * 0.71).cos() * 5.0, f * 0.05),
                0.3,
                0.2,
            ));
        }
        let acc = Accel::new(shapes.clone());
        let mut nhit = 0;
        for k in 0..500 {
            let f = k as f64;
            let org = DVec3::new((f * 0.13).sin() * 6.0, (f * 0.29).cos() * 6.0, 20.0);
            let dir = DVec3::new((f * 0.07).sin() * 0.2, (f * 0.11).cos() * 0.2, -1.0).normalize();
            let want = shapes
                .iter()
                .enumerate()
                .filter_map(|(i, s)| s.intersect(org, dir, 0.0, f64::INFINITY).map(|t| (t, i)))
                .min_by(|a, b| a.partial_cmp(b).unwrap());
            let got = acc
                .closest(org, dir, 0.0, f64::INFINITY, None)
                .map(|h| (h.t, h.shape));
            assert_eq!(got, want, "ray {k}");
            nhit += usize::from(got.is_some());
        }
        assert!(nhit > 50, "{nhit}");
    }

    /// Brute force: closest over all shapes (lowest index on a tie).
    fn brute(shapes: &[Shape], org: DVec3, dir: DVec3, tmin: f64) -> Option<(f64, usize)> {
        shapes
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.intersect(org, dir, tmin, f64::INFINITY).map(|t| (t, i)))
            .min_by(|a, b| a.partial_cmp(b).unwrap())
    }

    #[test]
    fn flat_box_test_matches_brute_force() {
        // a closed box room (12 triangles) plus a few quads: the flat path, including rays
        // along the axes (zero direction components) and rays starting on a face
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let tri =
            |a: DVec3, b: DVec3, d: DVec3| Shape::Polygon(Polygon::new(vec![a, b, d]).unwrap().0);
        let mut shapes = Vec::new();
        let (x1, y1, z1) = (4.0, 5.0, 3.0);
        let faces = [
            [c(0., 0., 0.), c(x1, 0., 0.), c(x1, y1, 0.), c(0., y1, 0.)],
            [c(0., 0., z1), c(0., y1, z1), c(x1, y1, z1), c(x1, 0., z1)],
            [c(0., 0., 0.), c(0., y1, 0.), c(0., y1, z1), c(0., 0., z1)],
            [c(x1, 0., 0.), c(x1, 0., z1), c(x1, y1, z1), c(x1, y1, 0.)],
            [c(0., 0., 0.), c(0., 0., z1), c(x1, 0., z1), c(x1, 0., 0.)],
            [c(0., y1, 0.), c(x1, y1, 0.), c(x1, y1, z1), c(0., y1, z1)],
        ];
        for f in faces {
            shapes.push(tri(f[0], f[1], f[2]));
            shapes.push(tri(f[0], f[2], f[3]));
        }
        for k in 0..5 {
            shapes.push(quad(
                c(0.5 + 0.6 * k as f64, 2.0, 0.5 + 0.4 * k as f64),
                0.3,
                0.2,
            ));
        }
        let acc = Accel::new(shapes.clone());
        assert!(matches!(acc.index, Index::Flat(_)));
        let mut rng = crate::rng::Rng::for_ray(11, 3);
        let mut hits = 0;
        for k in 0..4000 {
            let org = c(
                rng.next_f64() * x1,
                rng.next_f64() * y1,
                if k % 4 == 0 { 0.0 } else { rng.next_f64() * z1 },
            );
            let dir = match k % 5 {
                0 => [DVec3::X, -DVec3::Y, DVec3::Z, -DVec3::Z][k / 5 % 4],
                _ => c(
                    rng.next_f64() - 0.5,
                    rng.next_f64() - 0.5,
                    rng.next_f64() - 0.5,
                )
                .normalize(),
            };
            let tmin = 1e-9 * (1.0 + org.abs().max_element());
            let got = acc
                .closest(org, dir, tmin, f64::INFINITY, None)
                .map(|h| (h.t, h.shape));
            assert_eq!(got, brute(&shapes, org, dir, tmin), "ray {k}");
            if org.z > 0.0 {
                hits += usize::from(got.is_some());
            }
            let occ = acc.occluded(org, dir, tmin, 1.0, None);
            let want = brute(&shapes, org, dir, tmin).is_some_and(|(t, _)| t < 1.0);
            assert_eq!(occ, want, "occlusion of ray {k}");
        }
        // inside the closed room every ray starting off the floor hits something
        assert_eq!(hits, 3000);
    }

    #[test]
    fn surface_microns_from_the_origin_is_found() {
        // A ray leaving a ceiling 3.5 µm from the wall it heads into meets that wall after
        // 4 µm. (obvhs's traversal skips boxes left within 1e-4 of the ray's start; the
        // BVH path starts its ray behind the origin to make up for it.)
        for extra in [0, 60] {
            let wall = Shape::Polygon(
                Polygon::new(vec![
                    DVec3::ZERO,
                    DVec3::new(0.0, 5.0, 0.0),
                    DVec3::new(0.0, 5.0, 3.0),
                    DVec3::new(0.0, 0.0, 3.0),
                ])
                .unwrap()
                .0,
            );
            let mut shapes = vec![wall];
            // (small quads under the floor, keeping the scene's size and so the boxes' padding)
            for k in 0..extra {
                let (i, j) = ((k % 8) as f64, (k / 8) as f64);
                shapes.push(quad(
                    DVec3::new(1.0 + 0.4 * i, 1.0 + 0.4 * j, -1.0),
                    0.1,
                    0.1,
                ));
            }
            let acc = Accel::new(shapes);
            assert_eq!(matches!(acc.index, Index::Flat(_)), extra == 0);
            let org = DVec3::new(3.5e-6, 0.44, 3.0);
            let dir = DVec3::new(-0.875, 0.171, -0.4525).normalize();
            let h = acc.closest(org, dir, 4e-9, f64::INFINITY, None).unwrap();
            assert_eq!(h.shape, 0);
            assert!(
                (h.t - 3.5e-6 / 0.875 * dir.length()).abs() < 1e-7,
                "{}",
                h.t
            );
            assert!(acc.occluded(org, dir, 4e-9, 1.0, None));
        }
    }

    #[test]
    fn coplanar_overlap_goes_to_first_in_scene_order() {
        let shapes: Vec<Shape> = (0..6).map(|_| quad(DVec3::ZERO, 1.0, 1.0)).collect();
        let acc = Accel::new(shapes);
        let h = acc
            .closest(
                DVec3::new(0.2, 0.3, 1.0),
                -DVec3::Z,
                0.0,
                f64::INFINITY,
                None,
            )
            .unwrap();
        assert_eq!(h.shape, 0);
        let h = acc
            .closest(
                DVec3::new(0.2, 0.3, 1.0),
                -DVec3::Z,
                0.0,
                f64::INFINITY,
                Some(0),
            )
            .unwrap();
        assert_eq!(h.shape, 1);
    }

    #[test]
    fn grazing_rays_give_no_nan_and_consistent_answers() {
        let acc = Accel::new(vec![quad(DVec3::ZERO, 1.0, 1.0); 5]);
        for k in 0..50 {
            let ang = 1e-6 * k as f64 / 50.0;
            let dir = DVec3::new(ang.cos(), 0.0, -ang.sin());
            let h = acc.closest(DVec3::new(-0.5, 0.0, 1e-7), dir, 0.0, f64::INFINITY, None);
            if let Some(h) = h {
                assert!(h.t.is_finite() && h.t > 0.0);
                let p = DVec3::new(-0.5, 0.0, 1e-7) + dir * h.t;
                assert!(p.x <= 1.0 + 1e-9, "{p}");
            }
        }
        // exactly parallel in the plane: a miss, not a NaN
        assert!(acc
            .closest(
                DVec3::new(-2.0, 0.0, 0.0),
                DVec3::X,
                0.0,
                f64::INFINITY,
                None
            )
            .is_none());
    }

    #[test]
    fn ray_starting_on_a_surface() {
        let acc = Accel::new(vec![
            quad(DVec3::ZERO, 1.0, 1.0),
            quad(DVec3::new(0.0, 0.0, 1.0), 1.0, 1.0),
        ]);
        // leaving the lower polygon upward, skipping it: hits the upper one
        let h = acc
            .closest(
                DVec3::new(0.1, 0.1, 0.0),
                DVec3::Z,
                0.0,
                f64::INFINITY,
                Some(0),
            )
            .unwrap();
        assert_eq!(h.shape, 1);
        assert!((h.t - 1.0).abs() < 1e-12);
        // with a relative tmin instead of skipping, the start surface is not hit either
        let h = acc
            .closest(
                DVec3::new(0.1, 0.1, 0.0),
                DVec3::Z,
                1e-9,
                f64::INFINITY,
                None,
            )
            .unwrap();
        assert_eq!(h.shape, 1);
    }

    #[test]
    fn ray_through_shared_edge_and_vertex_does_not_leak() {
        // two triangles sharing the diagonal of a unit square, and four squares sharing a vertex
        let tri =
            |a: DVec3, b: DVec3, c: DVec3| Shape::Polygon(Polygon::new(vec![a, b, c]).unwrap().0);
        let shapes = vec![
            tri(DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0)),
            tri(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), DVec3::Y),
            quad(DVec3::new(5.5, 5.5, 0.0), 0.5, 0.5),
            quad(DVec3::new(4.5, 5.5, 0.0), 0.5, 0.5),
            quad(DVec3::new(5.5, 4.5, 0.0), 0.5, 0.5),
            quad(DVec3::new(4.5, 4.5, 0.0), 0.5, 0.5),
        ];
        let acc = Accel::new(shapes);
        for k in 0..=20 {
            let s = k as f64 / 20.0;
            assert!(
                acc.closest(DVec3::new(s, s, 1.0), -DVec3::Z, 0.0, 9.0, None)
                    .is_some(),
                "diag {s}"
            );
        }
        assert!(acc
            .closest(DVec3::new(5.0, 5.0, 1.0), -DVec3::Z, 0.0, 9.0, None)
            .is_some());
        assert!(acc
            .closest(DVec3::new(5.0, 4.7, 1.0), -DVec3::Z, 0.0, 9.0, None)
            .is_some());
    }

    #[test]
    fn millimetre_slat_one_km_away() {
        let mut shapes = vec![quad(DVec3::new(1000.0, 1000.0, 0.0), 0.5, 0.0005)];
        for i in 0..10 {
            shapes.push(quad(DVec3::new(i as f64 * 3.0, 0.0, -1.0), 1.0, 1.0));
        }
        let acc = Accel::new(shapes);
        let mut hits = 0;
        for k in 0..=100 {
            let y = 1000.0 - 0.0005 + 0.001 * k as f64 / 100.0;
            let h = acc.closest(
                DVec3::new(1000.0, y, 1.0),
                -DVec3::Z,
                1e-9,
                f64::INFINITY,
                None,
            );
            if h.is_some_and(|h| h.shape == 0) {
                hits += 1;
            }
        }
        assert_eq!(hits, 101);
        let miss = acc.closest(
            DVec3::new(1000.0, 1000.0011, 1.0),
            -DVec3::Z,
            1e-9,
            f64::INFINITY,
            None,
        );
        assert!(miss.is_none());
    }
}
