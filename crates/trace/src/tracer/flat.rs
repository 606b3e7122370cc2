//! A polygon or ring as a light source, sampled the way Radiance 6.0a's source describes
//! it (facts only; own code):
//!
//! - The source stands at its centre: the mean of a polygon's vertices (which must lie
//!   inside it, else Radiance stops: "cannot hit source center"), a ring's centre (a
//!   ring with an inner radius cannot be a source, for the same reason).
//! - Two half-extent vectors `su`, `sv` span it: for four vertices half of edges 0→1 and
//!   0→3; for three the edge nearest the centre gives the direction of `su`, the
//!   distance to that edge its length, `sv` = normal × `su`; otherwise (and for a ring)
//!   `su` is across the normal (the last coordinate axis where |normal| < 0.6, crossed
//!   with the normal) of length ½√area, `sv` = normal × `su`.
//! - With `-ds 0` one part, the whole square/parallelogram. With `-ds > 0`, from a point
//!   in front of the source: the square is halved, along `su` or `sv` (the one whose
//!   length times 2·weight/ds is larger), recursively, while the point is nearer the
//!   part's centre than that length (which halves with each split along it), into at
//!   most 64 parts. From behind: no parts.
//! - A part's sample is its centre, with `-dj` moved by ± dj × half its size along each
//!   vector. A ring's sample, when it has several parts or dj > 0.7, is mapped from the
//!   square onto the disk (x·√(1 − y²/2), y·√(1 − x²/2), scaled by 2/√π). Parts outside a
//!   polygon are still sampled: their shadow rays miss the source.
//! - Its solid angle: the cosine at the source (toward the point) times the part's share
//!   of the square times the source's area over the squared distance; samples with
//!   cosine × share at most 1e-4 are dropped.

use glam::DVec3;

use super::MAX_PARTS;
use crate::polygon::Polygon;

/// 2/√π to 9 digits, as Radiance writes it (3e-9 above the exact value, so a corner of
/// the square lands just past the rim): maps the square of a ring (side √π × radius)
/// onto its disk. With the exact value a disk lamp's worst point was 1.3e-6 off Radiance,
/// with this one 8.3e-7.
#[allow(clippy::approx_constant)]
const SQUARE_TO_DISK: f64 = 1.128_379_17;

/// One part of a flat source: centre and size along `su` and `sv`, in 1/64ths of the
/// half-extent (the whole source: centre 0, size 64).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Part {
    pub cu: i64,
    pub cv: i64,
    pub nu: i64,
    pub nv: i64,
}

impl Part {
    /// The part's centre and size across u (`along_u`) or across v.
    #[inline]
    fn axis_mut(&mut self, along_u: bool) -> (&mut i64, &mut i64) {
        if along_u {
            (&mut self.cu, &mut self.nu)
        } else {
            (&mut self.cv, &mut self.nv)
        }
    }
}

/// A flat light source's sampling geometry.
#[derive(Debug, Clone)]
pub(super) struct FlatSource {
    centre: DVec3,
    normal: DVec3,
    su: DVec3,
    sv: DVec3,
    area: f64,
    /// A ring: samples are mapped onto the disk.
    disk: bool,
}

/// A source's area as Radiance keeps it: in single precision (read from the reference
/// rtrace's source record in a debugger: a disk of radius .4 has extent vectors 2.6e-8
/// longer than with the f64 area). Which extent vector is halved first on a tie depends
/// on it.
fn f32_area(a: f64) -> f64 {
    a as f32 as f64
}

/// `v` made unit with the reference build's arithmetic (read from its machine code):
/// squared length x² + (z² + y²); within 1e-6 of 1 a first-order correction 2 − (1 + d)/2,
/// else 1/√d, times each component. A ring's normal made so differs from `normalize` in
/// the last bit, which decides which extent vector is halved first (their lengths tie).
pub(super) fn rad_normalize(v: DVec3) -> DVec3 {
    let d = v.x * v.x + (v.z * v.z + v.y * v.y);
    if d == 0.0 {
        return v;
    }
    let f = if (1.0 - 1e-6..=1.0 + 1e-6).contains(&d) {
        2.0 - (d + 1.0) * 0.5
    } else {
        1.0 / d.sqrt()
    };
    v * f
}

/// A unit vector across unit `n` (Radiance's unrandomised choice).
fn across(n: DVec3) -> DVec3 {
    rad_normalize(super::across_unnormalised(n))
}

/// Squared distance from `p` to the line through `a` and `b`.
fn dist2_line(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let ap = p - a;
    let t = ap.dot(ab);
    ap.length_squared() - t * t / l2
}

impl FlatSource {
    /// A polygon source; Err(reason) if it cannot be one. The flag: a triangle of poor
    /// aspect (Radiance warns).
    pub(super) fn polygon(poly: &Polygon) -> Result<(FlatSource, bool), String> {
        let v = &poly.verts;
        let n = v.len() as f64;
        let centre = v.iter().fold(DVec3::ZERO, |a, b| a + *b) / n;
        if !poly.contains_point(centre) {
            return Err(
                "cannot hit source center (the mean of its vertices lies outside it)".into(),
            );
        }
        let normal = poly.normal;
        let mut poor = false;
        let (su, sv) = match v.len() {
            4 => ((v[1] - v[0]) * 0.5, (v[3] - v[0]) * 0.5),
            3 => {
                // the edge nearest the centre: 2→0 unless 0→1 or 1→2 is strictly nearer
                let mut near = 2;
                let mut dmin = dist2_line(centre, v[2], v[0]);
                for i in 0..2 {
                    let d2 = dist2_line(centre, v[i], v[i + 1]);
                    if d2 < dmin {
                        near = i;
                        dmin = d2;
                    }
                }
                poor = dmin < 0.08 * f32_area(poly.area);
                let su = (v[(near + 1) % 3] - v[near]).normalize() * dmin.sqrt();
                (su, normal.cross(su))
            }
            _ => {
                let su = across(normal) * (0.5 * f32_area(poly.area).sqrt());
                (su, normal.cross(su))
            }
        };
        Ok((
            FlatSource {
                centre,
                normal,
                su,
                sv,
                area: f32_area(poly.area),
                disk: false,
            },
            poor,
        ))
    }

    /// A ring source (a disk: no inner radius) of centre `c`, normal `n` as given in the
    /// scene (any length), radius `r`.
    pub(super) fn disk(c: DVec3, n: DVec3, r: f64) -> FlatSource {
        let n = rad_normalize(n);
        let area = f32_area(std::f64::consts::PI * r * r);
        let su = across(n) * (0.5 * area.sqrt());
        FlatSource {
            centre: c,
            normal: n,
            su,
            sv: n.cross(su),
            area,
            disk: true,
        }
    }

    /// The parts that sample the source from `p` (in Radiance's order).
    pub(super) fn partitions(&self, p: DVec3, ds: f64, weight: f64) -> Vec<Part> {
        let whole = Part {
            cu: 0,
            cv: 0,
            nu: MAX_PARTS as i64,
            nv: MAX_PARTS as i64,
        };
        if ds <= crate::material::FTINY {
            return vec![whole];
        }
        if (p - self.centre).dot(self.normal) <= 0.0 {
            return Vec::new();
        }
        let k = 2.0 * weight / ds;
        let k2 = k * k;
        let mut out = Vec::new();
        self.split(
            p,
            whole,
            MAX_PARTS as i64,
            k2 * self.su.length_squared(),
            k2 * self.sv.length_squared(),
            &mut out,
        );
        out
    }

    fn split(&self, p: DVec3, part: Part, most: i64, du2: f64, dv2: f64, out: &mut Vec<Part>) {
        let m = MAX_PARTS as f64;
        let c = self.centre + self.su * (part.cu as f64 / m) + self.sv * (part.cv as f64 / m);
        let d2 = (p - c).length_squared();
        if most < 2 || (d2 >= du2 && d2 >= dv2) {
            out.push(part);
            return;
        }
        // halve the part along its longer side
        let along_u = du2 > dv2;
        let (mut lo, mut hi) = (part, part);
        for (half, side) in [(&mut lo, -1), (&mut hi, 1)] {
            let (centre, size) = half.axis_mut(along_u);
            *size /= 2;
            *centre += side * *size;
        }
        let (du2, dv2) = if along_u {
            (du2 * 0.25, dv2)
        } else {
            (du2, dv2 * 0.25)
        };
        self.split(p, lo, most / 2, du2, dv2, out);
        self.split(p, hi, most / 2, du2, dv2, out);
    }

    /// The sample of `part` (one of `count`) seen from `p`: its point and solid angle, or
    /// None if it is (nearly) edge-on or behind. `jitter`: `-dj` and two uniform numbers.
    pub(super) fn sample(
        &self,
        p: DVec3,
        part: Part,
        count: usize,
        jitter: Option<(f64, [f64; 2])>,
    ) -> Option<(DVec3, f64)> {
        let m = MAX_PARTS as f64;
        let (su_n, sv_n) = (part.nu as f64 / m, part.nv as f64 / m);
        let (mut x, mut y) = (part.cu as f64 / m, part.cv as f64 / m);
        let dj = jitter.map_or(0.0, |(dj, _)| dj);
        if let Some((dj, u)) = jitter {
            x += dj * (1.0 - 2.0 * u[0]) * su_n;
            y += dj * (1.0 - 2.0 * u[1]) * sv_n;
        }
        if self.disk && (count > 1 || dj > 0.7) {
            let tx = SQUARE_TO_DISK * (1.0 - 0.5 * y * y).sqrt();
            let ty = SQUARE_TO_DISK * (1.0 - 0.5 * x * x).sqrt();
            x *= tx;
            y *= ty;
        }
        let q = self.centre + self.su * x + self.sv * y;
        let l = q - p;
        let dist = l.length();
        if dist == 0.0 {
            return None;
        }
        let dom = -self.normal.dot(l / dist) * su_n * sv_n;
        if dom <= 1e-4 {
            return None;
        }
        Some((q, dom * self.area / (dist * dist)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> FlatSource {
        // 1 x 1 at z = 2, facing down
        let v = vec![
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
            DVec3::new(1.0, 1.0, 2.0),
            DVec3::new(1.0, 0.0, 2.0),
        ];
        FlatSource::polygon(&Polygon::new(v).unwrap().0).unwrap().0
    }

    #[test]
    fn parts_tile_the_square_once() {
        let s = square();
        for p in [
            DVec3::new(0.5, 0.5, 1.9),
            DVec3::new(0.1, 0.9, 1.98),
            DVec3::new(3.0, -1.0, 0.0),
        ] {
            for ds in [0.02, 0.05, 0.2, 0.5] {
                let parts = s.partitions(p, ds, 1.0);
                assert!(!parts.is_empty() && parts.len() <= MAX_PARTS);
                let total: i64 = parts.iter().map(|q| q.nu * q.nv).sum();
                assert_eq!(total, 64 * 64, "{p} {ds}");
                // every part inside the whole square, none overlapping another
                for (i, a) in parts.iter().enumerate() {
                    assert!(a.cu.abs() + a.nu <= 64 && a.cv.abs() + a.nv <= 64);
                    for b in &parts[i + 1..] {
                        let apart = (a.cu - b.cu).abs() >= a.nu + b.nu
                            || (a.cv - b.cv).abs() >= a.nv + b.nv;
                        assert!(apart, "{a:?} {b:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn no_parts_from_behind_one_far_away() {
        let s = square();
        assert!(s.partitions(DVec3::new(0.5, 0.5, 2.5), 0.2, 1.0).is_empty());
        assert_eq!(s.partitions(DVec3::new(0.5, 0.5, -50.0), 0.2, 1.0).len(), 1);
        assert_eq!(s.partitions(DVec3::new(0.5, 0.5, 1.9), 0.0, 1.0).len(), 1);
    }

    #[test]
    fn solid_angle_far_away_is_projected_area_over_distance_squared() {
        let s = square();
        let whole = s.partitions(DVec3::new(0.5, 0.5, -998.0), 0.2, 1.0)[0];
        let (q, om) = s
            .sample(DVec3::new(0.5, 0.5, -998.0), whole, 1, None)
            .unwrap();
        assert!((q - DVec3::new(0.5, 0.5, 2.0)).length() < 1e-12);
        assert!((om / 1e-6 - 1.0).abs() < 1e-12);
        // edge-on: dropped
        assert!(s
            .sample(DVec3::new(5.0, 0.5, 2.0), whole, 1, None)
            .is_none());
    }

    #[test]
    fn ring_samples_lie_on_the_disk() {
        let r = FlatSource::disk(DVec3::ZERO, DVec3::Z, 0.5);
        let p = DVec3::new(0.1, 0.0, 0.05);
        let parts = r.partitions(p, 0.05, 1.0);
        assert!(parts.len() > 1);
        for part in &parts {
            for u in [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]] {
                if let Some((q, _)) = r.sample(p, *part, parts.len(), Some((1.0, u))) {
                    // the single-precision area (up to 6e-8 relative, halved by the
                    // square root) and the 9-digit constant (3e-9) put the rim up to
                    // 3.3e-8 outside the disk
                    assert!(q.length() <= 0.5 * (1.0 + 4e-8), "{q}");
                }
            }
        }
    }

    #[test]
    fn a_concave_polygon_centred_outside_is_refused() {
        let v = [
            (0.0, 0.0),
            (0.0, 1.0),
            (1.0, 1.0),
            (0.1, 0.9),
            (0.1, 0.1),
            (1.0, 0.0),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 2.0))
        .collect();
        assert!(FlatSource::polygon(&Polygon::new(v).unwrap().0).is_err());
    }
}
