//! A cylinder as a light source (a tube lamp), sampled the way Radiance 6.0a's
//! documentation and source describe it (facts only; own code):
//!
//! - The source stands at the midpoint of the axis. Its sampling frame is the half-axis
//!   `u` (half the length along the axis) and two vectors across it of length
//!   0.8559 × radius (a square of about the disk's area).
//! - A sample's solid angle is the cylinder's projected area, 2 × radius × length, times
//!   the sine of the angle between the sample direction and the axis, times the share of
//!   the length the sample stands for, over the squared distance. Samples whose sine
//!   times share is at most 1e-4 (looking along the axis) are dropped.
//! - With `-ds 0` there is one sample, at the midpoint. With `-ds > 0`: no sample from a
//!   point within the cylinder's radius of its (infinite) axis; one sample from a point
//!   within twice the radius of the axis, or at least 2 × weight × half-length / ds from
//!   the midpoint; else the axis is halved recursively (up to 64 pieces) while a piece's
//!   centre is nearer than that distance (which halves with each level).
//! - `-dj` jitters each sample within its piece along the axis (± dj × half the piece)
//!   and across it (± dj × the square's half side).

use glam::DVec3;

use super::MAX_PARTS;

/// A cylinder light source's sampling geometry.
#[derive(Debug, Clone)]
pub(super) struct CylSource {
    /// Midpoint of the axis.
    mid: DVec3,
    /// Unit axis.
    axis: DVec3,
    /// Half the axis length.
    half: f64,
    /// Radius.
    r: f64,
    /// Across the axis: two orthogonal vectors of length 0.8559 × radius.
    v: DVec3,
    w: DVec3,
}

/// Half side of the square across the axis, per unit radius (Radiance's sampling frame).
const ACROSS: f64 = 0.8559;

impl CylSource {
    pub(super) fn new(p0: DVec3, axis: DVec3, len: f64, r: f64) -> CylSource {
        // across the axis: Radiance's unrandomised choice (its -u-), the last coordinate
        // axis with |component| < 0.6 crossed with the axis
        let a = super::across_unnormalised(axis).normalize();
        let w = a * (ACROSS * r);
        let v = w.cross(axis);
        CylSource {
            mid: p0 + axis * (0.5 * len),
            axis,
            half: 0.5 * len,
            r,
            v,
            w,
        }
    }

    /// How far past a sample point its shadow ray may still meet the cylinder (a jittered
    /// point can lie outside the surface, up to √2 × 0.8559 × radius from the axis).
    pub(super) fn beyond(&self) -> f64 {
        2.5 * self.r
    }

    /// The pieces of the axis that sample the source from `p`: each its centre (in units
    /// of the half-length, from -1 to 1) and its share of the length (1 = all).
    pub(super) fn partitions(&self, p: DVec3, ds: f64, weight: f64) -> Vec<(f64, f64)> {
        if ds <= crate::material::FTINY {
            return vec![(0.0, 1.0)];
        }
        let d = p - self.mid;
        let along = d.dot(self.axis);
        let cent2 = d.length_squared();
        let perp2 = cent2 - along * along;
        // the square's half side, squared, times 1.365: about the radius squared
        let rad2 = 1.365 * (ACROSS * self.r) * (ACROSS * self.r);
        if perp2 <= rad2 {
            return Vec::new();
        }
        let safe2 = self.half * self.half * 4.0 * weight * weight / (ds * ds);
        if perp2 <= 4.0 * rad2 || cent2 >= safe2 {
            return vec![(0.0, 1.0)];
        }
        let mut out = Vec::new();
        self.split(p, 0, MAX_PARTS as i64, MAX_PARTS as i64, safe2, &mut out);
        out
    }

    /// Halves the piece centred at `cent` (size `size`, both in 1/64ths of the half-length)
    /// while `p` is nearer its centre than √`d2` (a quarter each level) and `most` > 1.
    fn split(&self, p: DVec3, cent: i64, size: i64, most: i64, d2: f64, out: &mut Vec<(f64, f64)>) {
        let m = MAX_PARTS as f64;
        let c = self.mid + self.axis * (self.half * cent as f64 / m);
        if most < 2 || (p - c).length_squared() >= d2 {
            out.push((cent as f64 / m, size as f64 / m));
            return;
        }
        let half = size / 2;
        self.split(p, cent - half, half, most / 2, d2 * 0.25, out);
        self.split(p, cent + half, half, most / 2, d2 * 0.25, out);
    }

    /// The sample of the piece (`cent`, `share`) seen from `p`: its point and solid angle,
    /// or None if it is (nearly) end-on. `jitter`: `-dj` and three uniform numbers.
    pub(super) fn sample(
        &self,
        p: DVec3,
        cent: f64,
        share: f64,
        jitter: Option<(f64, [f64; 3])>,
    ) -> Option<(DVec3, f64)> {
        let (du, dv, dw) = match jitter {
            Some((dj, u)) => (
                dj * (1.0 - 2.0 * u[0]) * share,
                dj * (1.0 - 2.0 * u[1]),
                dj * (1.0 - 2.0 * u[2]),
            ),
            None => (0.0, 0.0, 0.0),
        };
        let q = self.mid + self.axis * (self.half * (cent + du)) + self.v * dv + self.w * dw;
        let l = q - p;
        let dist = l.length();
        if dist == 0.0 {
            return None;
        }
        let c = l.dot(self.axis) / dist;
        let dom = (1.0 - c * c).max(0.0).sqrt() * share;
        if dom <= 1e-4 {
            return None;
        }
        let area = 2.0 * self.r * 2.0 * self.half;
        Some((q, dom * area / (dist * dist)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tube() -> CylSource {
        CylSource::new(DVec3::ZERO, DVec3::X, 2.0, 0.05)
    }

    #[test]
    fn pieces_cover_the_axis_once() {
        let c = tube();
        for p in [
            DVec3::new(0.3, 0.4, 0.0),
            DVec3::new(1.0, 0.0, 0.2),
            DVec3::new(-0.5, 0.0, 0.5),
        ] {
            for ds in [0.02, 0.05, 0.2] {
                let parts = c.partitions(p, ds, 1.0);
                assert!(!parts.is_empty() && parts.len() <= MAX_PARTS);
                let total: f64 = parts.iter().map(|&(_, s)| s).sum();
                assert!((total - 1.0).abs() < 1e-12, "{p} {ds}: {total}");
                // in order from one end to the other, touching
                let mut edge = -1.0;
                for &(cent, s) in &parts {
                    assert!((cent - s - edge).abs() < 1e-12);
                    edge = cent + s;
                }
            }
        }
    }

    #[test]
    fn no_pieces_inside_the_radius_one_far_away() {
        let c = tube();
        assert!(c
            .partitions(DVec3::new(3.0, 0.04, 0.0), 0.2, 1.0)
            .is_empty());
        assert_eq!(c.partitions(DVec3::new(1.0, 0.0, 0.09), 0.2, 1.0).len(), 1);
        assert_eq!(c.partitions(DVec3::new(1.0, 0.0, 50.0), 0.2, 1.0).len(), 1);
        assert_eq!(c.partitions(DVec3::new(1.0, 0.0, 0.5), 0.0, 1.0).len(), 1);
    }

    #[test]
    fn solid_angle_far_away_is_projected_area_over_distance_squared() {
        let c = tube();
        // square to the axis, 1000 from the midpoint (1, 0, 0); then 45° off the axis
        let (_, om) = c
            .sample(DVec3::new(1.0, 1000.0, 0.0), 0.0, 1.0, None)
            .unwrap();
        let want = 2.0 * 0.05 * 2.0 / 1e6;
        assert!((om / want - 1.0).abs() < 1e-12);
        let (_, om) = c.sample(DVec3::new(4.0, 3.0, 0.0), 0.0, 1.0, None).unwrap();
        let want = 2.0 * 0.05 * 2.0 * 0.5f64.sqrt() / 18.0;
        assert!((om / want - 1.0).abs() < 1e-12);
        assert!(c
            .sample(DVec3::new(10.0, 0.0, 0.0), 0.0, 1.0, None)
            .is_none());
    }
}
