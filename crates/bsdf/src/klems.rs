//! Klems angle bases (LBNL/Klems Full, Half, Quarter, and bases defined in a BSDF XML file).
//!
//! # Conventions (the same as Radiance's)
//! * A basis is a list of rings around the surface normal, numbered from the normal outwards;
//!   patches are numbered ring by ring from 0 (the normal cap), and inside a ring by increasing
//!   azimuth. Patch `j` of a ring with `n` patches is centred on azimuth `360·j/n` degrees, so
//!   patch 0 of every ring straddles azimuth 0.
//! * Directions are expressed in a local frame: `z` = surface normal, `y` = up vector (made
//!   perpendicular to the normal), `x = y × z` ("right" seen from the `+z` side; a left-handed
//!   frame negates `x`). Azimuth runs from `+x` towards `+y`.
//! * Angles at the boundaries follow Radiance's `klems_full.cal` shipped with Radiance 6.0a
//!   (the binning `rcontrib` applies): a polar angle exactly on a ring boundary belongs to the
//!   **inner** ring, a direction at exactly 90° belongs to the outer ring, and a direction with
//!   a negative `z` is in the wrong hemisphere (`None`).
//! * [`Frame`] turns a world ray direction into the local direction the `.cal` functions bin:
//!   the *reversed* ray direction (the propagation direction of light arriving along the ray).

use std::f64::consts::PI;
use std::sync::OnceLock;

/// One ring of a Klems basis: polar bounds in degrees and the number of azimuthal patches.
#[derive(Clone, Debug, PartialEq)]
pub struct Ring {
    /// Lower polar bound (degrees).
    pub theta_lo: f64,
    /// Upper polar bound (degrees).
    pub theta_hi: f64,
    /// Number of azimuthal patches in the ring.
    pub nphi: usize,
    /// Index of the ring's first patch.
    pub first: usize,
}

/// A Klems angle basis.
#[derive(Clone, Debug, PartialEq)]
pub struct KlemsBasis {
    name: String,
    rings: Vec<Ring>,
    len: usize,
    /// cos of each ring's upper polar bound (all rings but the last): the ring of a unit
    /// direction found from its z without an arc cosine.
    cos_hi: Box<[f64]>,
    /// Each ring's azimuthal patch boundaries as [`diamond`] angles, increasing, indexed from
    /// the ring's first patch: a patch found from a direction without an arc tangent.
    dbound: Box<[f64]>,
    /// Per ring, [`CELLS`] entries: how many of the ring's boundaries lie at or below the
    /// start of each equal cell of the diamond range [0, 4), so the patch takes a table read
    /// and one comparison instead of a search; empty where a cell would hold two boundaries.
    cell_start: Box<[u8]>,
}

/// Cells of the diamond range per ring in [`KlemsBasis::cell_start`].
const CELLS: usize = 1024;

/// Error building a basis from ring bounds.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BasisError {
    /// The ring list is empty.
    #[error("angle basis has no rings")]
    Empty,
    /// A ring's bounds are not increasing or do not start at 0 / end at 90 degrees.
    #[error("angle basis ring {ring}: {what}")]
    BadRing {
        /// 0-based ring index.
        ring: usize,
        /// What is wrong.
        what: String,
    },
}

/// Name of the full basis as written in BSDF XML files.
pub const FULL_NAME: &str = "LBNL/Klems Full";
/// Name of the half basis.
pub const HALF_NAME: &str = "LBNL/Klems Half";
/// Name of the quarter basis.
pub const QUARTER_NAME: &str = "LBNL/Klems Quarter";

impl KlemsBasis {
    /// Builds a basis from `(upper polar bound in degrees, patches)` per ring, inner to outer;
    /// the first ring starts at 0 and the last must end at 90.
    pub fn from_bounds(name: &str, rings: &[(f64, usize)]) -> Result<Self, BasisError> {
        if rings.is_empty() {
            return Err(BasisError::Empty);
        }
        let mut out = Vec::with_capacity(rings.len());
        let mut lo = 0.0;
        let mut first = 0;
        for (i, &(hi, n)) in rings.iter().enumerate() {
            let bad = |what: &str| BasisError::BadRing {
                ring: i,
                what: what.to_string(),
            };
            if !hi.is_finite() || hi <= lo || hi > 90.0 {
                return Err(bad(&format!("upper bound {hi} must lie in ({lo}, 90]")));
            }
            if n == 0 {
                return Err(bad("needs at least one patch"));
            }
            if n == 1 && i != 0 {
                return Err(bad("a single-patch ring is only allowed around the normal"));
            }
            out.push(Ring {
                theta_lo: lo,
                theta_hi: hi,
                nphi: n,
                first,
            });
            first += n;
            lo = hi;
        }
        if lo != 90.0 {
            return Err(BasisError::BadRing {
                ring: rings.len() - 1,
                what: format!("last ring must end at 90 degrees, not {lo}"),
            });
        }
        let cos_hi: Vec<f64> = out[..out.len() - 1]
            .iter()
            .map(|r| r.theta_hi.to_radians().cos())
            .collect();
        let dbound: Vec<f64> = out
            .iter()
            .flat_map(|r| {
                let inc = 360.0 / r.nphi as f64;
                (0..r.nphi).map(move |k| {
                    let b = ((k as f64 + 0.5) * inc).to_radians();
                    diamond(b.cos(), b.sin())
                })
            })
            .collect();
        let cell_start = cell_table(&out, &dbound).into_boxed_slice();
        Ok(KlemsBasis {
            name: name.to_string(),
            rings: out,
            len: first,
            cos_hi: cos_hi.into_boxed_slice(),
            dbound: dbound.into_boxed_slice(),
            cell_start,
        })
    }

    /// LBNL/Klems Full: 145 patches.
    pub fn full() -> &'static KlemsBasis {
        static B: OnceLock<KlemsBasis> = OnceLock::new();
        B.get_or_init(|| {
            let bounds = [5., 15., 25., 35., 45., 55., 65., 75., 90.];
            let n = [1, 8, 16, 20, 24, 24, 24, 16, 12];
            Self::builtin(FULL_NAME, &bounds, &n)
        })
    }

    /// LBNL/Klems Half: 77 patches (the current definition used by WINDOW and Radiance 6).
    pub fn half() -> &'static KlemsBasis {
        static B: OnceLock<KlemsBasis> = OnceLock::new();
        B.get_or_init(|| {
            let bounds = [6.5, 19.5, 32.5, 45.5, 58.5, 71.5, 90.];
            let n = [1, 8, 12, 16, 20, 12, 8];
            Self::builtin(HALF_NAME, &bounds, &n)
        })
    }

    /// LBNL/Klems Quarter: 41 patches.
    pub fn quarter() -> &'static KlemsBasis {
        static B: OnceLock<KlemsBasis> = OnceLock::new();
        B.get_or_init(|| {
            let bounds = [9., 27., 45., 63., 90.];
            let n = [1, 8, 12, 12, 8];
            Self::builtin(QUARTER_NAME, &bounds, &n)
        })
    }

    fn builtin(name: &str, bounds: &[f64], n: &[usize]) -> KlemsBasis {
        let rings: Vec<(f64, usize)> = bounds.iter().copied().zip(n.iter().copied()).collect();
        Self::from_bounds(name, &rings).expect("built-in basis is valid")
    }

    /// The built-in basis with this name (case-insensitive), as Radiance recognises them.
    pub fn by_name(name: &str) -> Option<&'static KlemsBasis> {
        let n = name.trim();
        [Self::full(), Self::half(), Self::quarter()]
            .into_iter()
            .find(|b| b.name.eq_ignore_ascii_case(n))
    }

    /// The basis name (e.g. `LBNL/Klems Full`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The rings, inner to outer.
    pub fn rings(&self) -> &[Ring] {
        &self.rings
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True if the basis has no patch (never for a valid basis).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Ring index and position in the ring of a patch (`None` if out of range).
    pub fn ring_of(&self, patch: usize) -> Option<(usize, usize)> {
        if patch >= self.len {
            return None;
        }
        let r = self.rings.partition_point(|ring| ring.first <= patch) - 1;
        Some((r, patch - self.rings[r].first))
    }

    /// The patch holding a direction given by polar angle and azimuth in degrees
    /// (azimuth any real value; polar in [0, 90], else `None`). Boundary rules: see the module.
    pub fn patch_at(&self, theta_deg: f64, phi_deg: f64) -> Option<usize> {
        if !(0.0..=90.0).contains(&theta_deg) || !phi_deg.is_finite() {
            return None;
        }
        let last = self.rings.len() - 1;
        let r = self.rings[..last]
            .iter()
            .position(|ring| theta_deg <= ring.theta_hi)
            .unwrap_or(last);
        Some(self.in_ring(r, phi_deg))
    }

    /// The patch holding a local direction (any length; `z` along the normal), or `None` for a
    /// direction with negative `z` (wrong hemisphere), zero length or non-finite components.
    pub fn patch(&self, v: [f64; 3]) -> Option<usize> {
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let u = [v[0] / len, v[1] / len, v[2] / len];
        // fast path: the ring from z against the bounds' cosines, unless z lies within
        // 1e-12 of one (or of the horizon), where the arc cosine decides as Radiance does
        const NEAR: f64 = 1e-12;
        let r = self
            .cos_hi
            .iter()
            .position(|&c| u[2] >= c)
            .unwrap_or(self.rings.len() - 1);
        // the bounds nearest z are those either side of its ring
        let near = |i: usize| {
            self.cos_hi
                .get(i)
                .is_some_and(|&c| (u[2] - c).abs() <= NEAR)
        };
        if u[2] > NEAR && !near(r) && !(r > 0 && near(r - 1)) {
            if let Some(p) = self.in_ring_fast(r, u[0], u[1]) {
                return Some(p);
            }
            let mut a = u[1].atan2(u[0]);
            if a < 0.0 {
                a += 2.0 * PI;
            }
            return Some(self.in_ring(r, a / (PI / 180.0)));
        }
        let (theta, phi) = local_angles(u);
        if theta > 90.0 {
            return None;
        }
        self.patch_at(theta, phi)
    }

    /// The patch of ring `r` holding the azimuth of (`x`, `y`), found by comparing its
    /// [`diamond`] angle with the ring's boundaries; `None` within 1e-9 of a boundary (about
    /// 1e-9 radians, far above the rounding of either path), where [`Self::in_ring`] on the
    /// arc tangent decides, so both paths give the same patch.
    fn in_ring_fast(&self, r: usize, x: f64, y: f64) -> Option<usize> {
        const MARGIN: f64 = 1e-9;
        let ring = &self.rings[r];
        if ring.nphi == 1 {
            return Some(ring.first);
        }
        if x == 0.0 && y == 0.0 {
            return None;
        }
        let b = &self.dbound[ring.first..ring.first + ring.nphi];
        let d = diamond(x, y);
        let k = if self.cell_start.is_empty() {
            b.partition_point(|&v| v <= d)
        } else {
            // at most one boundary lies in d's cell: the count at the cell's start, plus it
            let cell = ((d * (CELLS / 4) as f64) as usize).min(CELLS - 1);
            let k0 = usize::from(self.cell_start[r * CELLS + cell]);
            k0 + usize::from(b.get(k0).is_some_and(|&v| v <= d))
        };
        let near = |i: usize| b.get(i).is_some_and(|&v| (d - v).abs() <= MARGIN);
        if near(k) || (k > 0 && near(k - 1)) {
            return None;
        }
        // k boundaries at or below the azimuth: patch k, the last boundary wrapping to 0
        Some(ring.first + if k == ring.nphi { 0 } else { k })
    }

    /// The patch of ring `r` at azimuth `phi_deg` (finite).
    fn in_ring(&self, r: usize, phi_deg: f64) -> usize {
        let ring = &self.rings[r];
        let mut azi = phi_deg % 360.0;
        if azi < 0.0 {
            azi += 360.0;
        }
        let inc = 360.0 / ring.nphi as f64;
        let j = if (360.0 - 0.5 * inc) - azi > 0.0 {
            ((azi + 0.5 * inc) / inc).floor() as usize
        } else {
            0
        };
        ring.first + j.min(ring.nphi - 1)
    }

    /// Polar bounds (degrees) and azimuth range (degrees, centre ± half width) of a patch.
    pub fn bounds(&self, patch: usize) -> Option<PatchBounds> {
        let (r, j) = self.ring_of(patch)?;
        let ring = &self.rings[r];
        let inc = 360.0 / ring.nphi as f64;
        Some(PatchBounds {
            theta_lo: ring.theta_lo,
            theta_hi: ring.theta_hi,
            phi_lo: inc * (j as f64 - 0.5),
            phi_hi: inc * (j as f64 + 0.5),
        })
    }

    /// Centre direction of a patch (unit vector in the local frame): the normal for the cap,
    /// else the ring's mid polar angle (the `Theta` a BSDF XML file lists) at azimuth `360·j/n`.
    pub fn centre(&self, patch: usize) -> Option<[f64; 3]> {
        let (r, j) = self.ring_of(patch)?;
        let ring = &self.rings[r];
        let theta = if r == 0 {
            0.0
        } else {
            0.5 * (ring.theta_lo + ring.theta_hi)
        };
        let phi = 360.0 * j as f64 / ring.nphi as f64;
        Some(direction(theta.to_radians().cos(), phi.to_radians()))
    }

    /// A direction in a patch from two numbers in [0,1): uniform in projected solid angle
    /// (cos²θ uniform, as Radiance's BSDF library samples Klems patches).
    pub fn sample_projected(&self, patch: usize, u0: f64, u1: f64) -> Option<[f64; 3]> {
        let b = self.bounds(patch)?;
        let (c_lo, c_hi) = (b.theta_lo.to_radians().cos(), b.theta_hi.to_radians().cos());
        let cos2 = (1.0 - u0) * c_lo * c_lo + u0 * c_hi * c_hi;
        let phi = (b.phi_lo + u1 * (b.phi_hi - b.phi_lo)).to_radians();
        Some(direction(cos2.max(0.0).sqrt(), phi))
    }

    /// A direction in a patch from two numbers in [0,1): uniform in solid angle (cosθ uniform).
    pub fn sample_uniform(&self, patch: usize, u0: f64, u1: f64) -> Option<[f64; 3]> {
        let b = self.bounds(patch)?;
        let (c_lo, c_hi) = (b.theta_lo.to_radians().cos(), b.theta_hi.to_radians().cos());
        let c = c_lo + u0 * (c_hi - c_lo);
        let phi = (b.phi_lo + u1 * (b.phi_hi - b.phi_lo)).to_radians();
        Some(direction(c.clamp(0.0, 1.0), phi))
    }

    /// Solid angle of a patch (sr): `2π (cos θlo − cos θhi) / n`.
    pub fn solid_angle(&self, patch: usize) -> Option<f64> {
        let (c_lo, c_hi, n) = self.ring_cosines(patch)?;
        Some(2.0 * PI * (c_lo - c_hi) / n)
    }

    /// Projected solid angle ("lambda") of a patch (sr): `π (cos²θlo − cos²θhi) / n`.
    pub fn projected_solid_angle(&self, patch: usize) -> Option<f64> {
        let (c_lo, c_hi, n) = self.ring_cosines(patch)?;
        Some(PI * (c_lo * c_lo - c_hi * c_hi) / n)
    }

    /// Cosines of the polar bounds of a patch's ring, and its number of patches `n`.
    fn ring_cosines(&self, patch: usize) -> Option<(f64, f64, f64)> {
        let (r, _) = self.ring_of(patch)?;
        let ring = &self.rings[r];
        let (c_lo, c_hi) = (
            ring.theta_lo.to_radians().cos(),
            ring.theta_hi.to_radians().cos(),
        );
        Some((c_lo, c_hi, ring.nphi as f64))
    }

    /// Projected solid angles of all patches, in patch order.
    pub fn lambdas(&self) -> Vec<f64> {
        (0..self.len)
            .map(|p| self.projected_solid_angle(p).unwrap_or(0.0))
            .collect()
    }

    /// The patch of the same ring rotated by 180° in azimuth.
    pub fn rotate180(&self, patch: usize) -> Option<usize> {
        let (r, j) = self.ring_of(patch)?;
        let ring = &self.rings[r];
        let c = self.centre(patch)?;
        if ring.nphi % 2 == 0 {
            return Some(ring.first + (j + ring.nphi / 2) % ring.nphi);
        }
        self.patch([-c[0], -c[1], c[2]])
    }
}

/// Polar and azimuthal extent of one patch (degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchBounds {
    /// Lower polar bound.
    pub theta_lo: f64,
    /// Upper polar bound.
    pub theta_hi: f64,
    /// Lower azimuth (may be negative for patch 0 of a ring).
    pub phi_lo: f64,
    /// Upper azimuth.
    pub phi_hi: f64,
}

fn direction(cos_theta: f64, phi: f64) -> [f64; 3] {
    let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    [s * phi.cos(), s * phi.sin(), cos_theta]
}

/// A monotonic stand-in for the azimuth of (`x`, `y`), not both zero: 0 at +x, 1 at +y, 2 at
/// −x, 3 at −y, increasing counter-clockwise below 4 (one division, no arc tangent).
pub fn diamond(x: f64, y: f64) -> f64 {
    if y >= 0.0 {
        if x >= 0.0 {
            y / (x + y)
        } else {
            1.0 - x / (y - x)
        }
    } else if x < 0.0 {
        2.0 - y / (-x - y)
    } else {
        3.0 + x / (x - y)
    }
}

/// The per-ring cell table of [`KlemsBasis::cell_start`], or an empty one if a ring has
/// more than 255 patches or two boundaries in one cell.
fn cell_table(rings: &[Ring], dbound: &[f64]) -> Vec<u8> {
    let mut table = Vec::with_capacity(rings.len() * CELLS);
    for ring in rings {
        let b = &dbound[ring.first..ring.first + ring.nphi];
        if ring.nphi > 255 {
            return Vec::new();
        }
        for cell in 0..CELLS {
            let (lo, hi) = (
                cell as f64 * 4.0 / CELLS as f64,
                (cell + 1) as f64 * 4.0 / CELLS as f64,
            );
            let k0 = b.partition_point(|&v| v <= lo);
            if b.partition_point(|&v| v < hi) > k0 + 1 {
                return Vec::new();
            }
            table.push(k0 as u8);
        }
    }
    table
}

/// Polar angle (degrees, from +z, clamped to [0,180]) and azimuth (degrees in [0,360), from +x
/// towards +y) of a unit local direction, computed as Radiance's `klems_full.cal` does.
pub fn local_angles(v: [f64; 3]) -> (f64, f64) {
    const DEGREE: f64 = PI / 180.0;
    let theta = if v[2] > 1.0 {
        0.0
    } else if v[2] < -1.0 {
        PI / DEGREE
    } else {
        v[2].acos() / DEGREE
    };
    let mut a = v[1].atan2(v[0]);
    if a < 0.0 {
        a += 2.0 * PI;
    }
    (theta, a / DEGREE)
}

/// A surface frame: normal `n` (local +z) and up vector `u` (local +y after removing its
/// normal component), right-handed (`x = u × n`) unless made left-handed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    n: [f64; 3],
    u: [f64; 3],
    rhs: f64,
}

impl Frame {
    /// A right-handed frame; `n` should be unit length, `u` need not be (nor be perpendicular).
    pub fn new(n: [f64; 3], u: [f64; 3]) -> Self {
        Frame { n, u, rhs: 1.0 }
    }

    /// The same frame with `x` negated (Radiance's `RHS=-1`, rfluxmtx `h=-kf`).
    pub fn left_handed(mut self) -> Self {
        self.rhs = -self.rhs;
        self
    }

    /// Local coordinates `(x, y, z)` of the **reversed** ray direction `-d` (unnormalised in x and
    /// y; z = cosθ for unit `d`), as `klems_full.cal`'s `kbin(N, U)` computes them.
    pub fn reversed_local(&self, d: [f64; 3]) -> [f64; 3] {
        let (n, u) = (self.n, self.u);
        let dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
        let du = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
        let nu = n[0] * u[0] + n[1] * u[1] + n[2] * u[2];
        let uxn = [
            u[1] * n[2] - u[2] * n[1],
            u[2] * n[0] - u[0] * n[2],
            u[0] * n[1] - u[1] * n[0],
        ];
        let d_uxn = d[0] * uxn[0] + d[1] * uxn[1] + d[2] * uxn[2];
        [-self.rhs * d_uxn, -du + dn * nu, -dn]
    }

    /// The Klems patch `kbin(N, U)` gives a ray direction `d` (unit length): the patch of `-d`.
    pub fn bin(&self, basis: &KlemsBasis, d: [f64; 3]) -> Option<usize> {
        let l = self.reversed_local(d);
        const DEGREE: f64 = PI / 180.0;
        let z = l[2];
        let theta = if z > 1.0 {
            0.0
        } else if z < -1.0 {
            180.0
        } else {
            z.acos() / DEGREE
        };
        if theta > 90.0 {
            return None;
        }
        let mut a = l[1].atan2(l[0]);
        if a < 0.0 {
            a += 2.0 * PI;
        }
        basis.patch_at(theta, a / DEGREE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The azimuth found through diamond angles equals the arc tangent's patch for every ring
    /// of the three built-in bases: random directions, and directions at, just beside and
    /// 1e-12 rad beside every patch boundary (where the fast path must defer).
    #[test]
    fn diamond_azimuth_matches_arc_tangent() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let exact = |b: &KlemsBasis, r: usize, x: f64, y: f64| {
            let mut a = y.atan2(x);
            if a < 0.0 {
                a += 2.0 * PI;
            }
            b.in_ring(r, a / (PI / 180.0))
        };
        let (mut checked, mut deferred) = (0usize, 0usize);
        // a ring of 300 patches (no cell table: the search path) beside the three bases
        let fine = KlemsBasis::from_bounds("fine", &[(10.0, 1), (50.0, 300), (90.0, 36)]).unwrap();
        assert!(fine.cell_start.is_empty() && !KlemsBasis::full().cell_start.is_empty());
        for b in [
            KlemsBasis::full(),
            KlemsBasis::half(),
            KlemsBasis::quarter(),
            &fine,
        ] {
            for r in 0..b.rings.len() {
                let inc = 360.0 / b.rings[r].nphi as f64;
                let mut angles: Vec<f64> = (0..20_000).map(|_| rnd() * 2.0 * PI).collect();
                for k in 0..b.rings[r].nphi {
                    let at = ((k as f64 + 0.5) * inc).to_radians();
                    for e in [0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-8, -1e-8, 1e-6, -1e-6] {
                        angles.push(at + e);
                    }
                }
                angles.extend([0.0, PI / 2.0, PI, 1.5 * PI, 2.0 * PI - 1e-15]);
                for a in angles {
                    let len = 0.3 + rnd();
                    let (x, y) = (len * a.cos(), len * a.sin());
                    match b.in_ring_fast(r, x, y) {
                        Some(p) => {
                            assert_eq!(p, exact(b, r, x, y), "ring {r} angle {a}");
                            checked += 1;
                        }
                        None => deferred += 1,
                    }
                }
            }
        }
        assert!(
            deferred > 0 && checked > 100 * deferred,
            "{checked} {deferred}"
        );
    }

    fn all() -> [&'static KlemsBasis; 3] {
        [
            KlemsBasis::full(),
            KlemsBasis::half(),
            KlemsBasis::quarter(),
        ]
    }

    #[test]
    fn sizes() {
        assert_eq!(KlemsBasis::full().len(), 145);
        assert_eq!(KlemsBasis::half().len(), 77);
        assert_eq!(KlemsBasis::quarter().len(), 41);
    }

    #[test]
    fn sums_are_2pi_and_pi() {
        for b in all() {
            let omega: f64 = (0..b.len()).map(|p| b.solid_angle(p).unwrap()).sum();
            let lambda: f64 = b.lambdas().iter().sum();
            assert!((omega - 2.0 * PI).abs() < 1e-12, "{} {omega}", b.name());
            assert!((lambda - PI).abs() < 1e-12, "{} {lambda}", b.name());
        }
    }

    #[test]
    fn spec_table_values() {
        // formats.md §3.1 tables, printed to 7 significant digits.
        let f = KlemsBasis::full();
        assert!((f.solid_angle(133).unwrap() / 1.355173e-01 - 1.0).abs() < 1e-6);
        assert!((f.projected_solid_angle(0).unwrap() / 2.386393e-02 - 1.0).abs() < 1e-6);
        let h = KlemsBasis::half();
        assert!((h.projected_solid_angle(70).unwrap() / 3.953783e-02 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn centres_and_samples_map_back() {
        for b in all() {
            for p in 0..b.len() {
                assert_eq!(
                    b.patch(b.centre(p).unwrap()),
                    Some(p),
                    "{} centre {p}",
                    b.name()
                );
                for (u0, u1) in [(0.01, 0.02), (0.5, 0.5), (0.98, 0.97), (0.3, 0.999)] {
                    assert_eq!(b.patch(b.sample_projected(p, u0, u1).unwrap()), Some(p));
                    assert_eq!(b.patch(b.sample_uniform(p, u0, u1).unwrap()), Some(p));
                }
                let r = b.rotate180(p).unwrap();
                assert_eq!(b.rotate180(r), Some(p));
            }
        }
    }

    #[test]
    fn fast_patch_lookup_is_the_arc_cosine_one() {
        // random directions, and directions on and 1e-13 either side of every ring bound
        let slow = |b: &KlemsBasis, v: [f64; 3]| {
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let (t, p) = local_angles([v[0] / len, v[1] / len, v[2] / len]);
            if t > 90.0 {
                None
            } else {
                b.patch_at(t, p)
            }
        };
        let mut x: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        for b in [
            KlemsBasis::full(),
            KlemsBasis::half(),
            KlemsBasis::quarter(),
        ] {
            for _ in 0..200_000 {
                let (z, phi) = (next(), next() * 2.0 * PI);
                let r = (1.0 - z * z).sqrt();
                let v = [r * phi.cos(), r * phi.sin(), z];
                assert_eq!(b.patch(v), slow(b, v), "{v:?}");
            }
            for ring in &b.rings {
                for d in [-1e-13, 0.0, 1e-13] {
                    let t = (ring.theta_hi + d).to_radians();
                    for k in 0..64 {
                        let phi = k as f64 * PI / 32.0;
                        let v = [t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos()];
                        assert_eq!(b.patch(v), slow(b, v), "{v:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn edges() {
        let f = KlemsBasis::full();
        assert_eq!(f.patch([0.0, 0.0, 1.0]), Some(0));
        assert_eq!(f.patch([1.0, 0.0, 0.0]), Some(133));
        assert_eq!(f.patch([0.0, 0.0, -1.0]), None);
        assert_eq!(f.patch([0.0, 0.0, 0.0]), None);
        assert_eq!(f.patch([f64::NAN, 0.0, 1.0]), None);
        assert_eq!(f.patch_at(5.0, 0.0), Some(0));
        assert_eq!(f.patch_at(90.0, 359.9), Some(133));
        // klems_full.cal verified examples (kbinN: N = (0,-1,0), U = +Z).
        let north = Frame::new([0.0, -1.0, 0.0], [0.0, 0.0, 1.0]);
        let s10 = 10f64.to_radians().sin();
        let c10 = 10f64.to_radians().cos();
        assert_eq!(north.bin(f, [0.0, 1.0, 0.0]), Some(0));
        assert_eq!(north.bin(f, [s10, c10, 0.0]), Some(5));
        assert_eq!(north.bin(f, [-s10, c10, 0.0]), Some(1));
        assert_eq!(north.bin(f, [0.0, c10, s10]), Some(7));
        assert_eq!(north.bin(f, [0.0, c10, -s10]), Some(3));
        assert_eq!(north.bin(f, [0.0, -1.0, 0.0]), None);
        let z = 0.7072; // the spec example uses .7071; any z near it lands in the same patch
        let s = 0.5f64.hypot(0.5).hypot(z);
        assert_eq!(north.bin(f, [0.5 / s, 0.5 / s, z / s]), Some(109));
    }

    #[test]
    fn custom_basis_checks() {
        assert!(KlemsBasis::from_bounds("x", &[]).is_err());
        assert!(KlemsBasis::from_bounds("x", &[(10.0, 1), (80.0, 4)]).is_err());
        assert!(KlemsBasis::from_bounds("x", &[(10.0, 1), (90.0, 1)]).is_err());
        let b = KlemsBasis::from_bounds("x", &[(30.0, 1), (90.0, 6)]).unwrap();
        assert_eq!(b.len(), 7);
        assert_eq!(KlemsBasis::by_name("lbnl/klems full").unwrap().len(), 145);
    }
}
