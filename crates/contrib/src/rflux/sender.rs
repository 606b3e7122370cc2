//! Sender-mode sample rays: for every bin of the sender's basis, `count` rays leaving the
//! back of the sender surfaces with directions in that bin, stratified over the bin and
//! over the surfaces. Random numbers are keyed by the seed, the bin and the sample index,
//! so the rays are the same for any thread count and from run to run.

use anyhow::{bail, Result};
use fenestra_bsdf::tree::square_to_disk;
use fenestra_trace::rng::{spread2, stratified2, Rng};
use glam::DVec3;

use super::directive::Basis;
use super::surfaces::{Group, Shape, Surface};

/// One surface prepared for sampling origins.
#[derive(Debug, Clone)]
struct Patch {
    surface: Surface,
    /// Triangles of a polygon and their cumulative area fractions.
    tris: Vec<[DVec3; 3]>,
    cum: Vec<f64>,
    /// Tangent axes of a ring.
    axes: [DVec3; 2],
}

/// The sender's sampler.
#[derive(Debug, Clone)]
pub struct Sampler {
    basis: Basis,
    udir: DVec3,
    vdir: DVec3,
    nrm: DVec3,
    patches: Vec<Patch>,
    nbins: usize,
    count: usize,
    seed: u64,
}

/// Reinhart rows per altitude band (Tregenza's counts).
const TREGENZA: [usize; 7] = [30, 30, 24, 24, 18, 12, 6];

fn reinhart_row_len(mf: usize, row: usize) -> usize {
    let rows = 7 * mf + 1;
    if row >= rows - 1 {
        1
    } else {
        mf * TREGENZA[row / mf]
    }
}

/// A multiplier that permutes 0..n when applied modulo n (coprime with n).
fn coprime_step(n: usize) -> usize {
    const PRIMES: [usize; 6] = [
        7_919, 104_729, 1_299_709, 15_485_863, 32_452_843, 49_979_687,
    ];
    PRIMES.iter().copied().find(|p| n % p != 0).unwrap_or(1)
}

impl Sampler {
    /// The sampler of a sender group with `count` rays per bin.
    pub fn new(group: &Group, count: usize, seed: u64) -> Result<Sampler> {
        let Some(basis) = group.params.basis()? else {
            bail!("missing sender sampling type! (#@rfluxmtx h=… before the sender surfaces)");
        };
        let nbins = match basis {
            Basis::Uniform => 1,
            Basis::Klems(k) => k.basis().len(),
            Basis::Reinhart(mf) => {
                let mf = mf as usize;
                (0..7 * mf + 1).map(|r| reinhart_row_len(mf, r)).sum()
            }
            Basis::ShirleyChiu(n) => (n as usize) * (n as usize),
            Basis::Cie => bail!("unrecognized sender sampling: h=cie (receivers only)"),
        };
        let Some(nrm) = group.normal() else {
            bail!("undefined normal for sender sampling (the sender's normals cancel)");
        };
        let up = group.up(nrm);
        let u = up.cross(nrm);
        if u.length() < 1e-9 * up.length() {
            bail!("up vector coincides with sender normal");
        }
        let mut udir = u.normalize();
        let vdir = nrm.cross(udir);
        if group.params.left {
            udir = -udir;
        }
        if group.surfaces.iter().any(|s| s.is_source()) {
            bail!("cannot use source as a sender!");
        }
        let patches = group
            .surfaces
            .iter()
            .map(prepare)
            .collect::<Result<Vec<_>>>()?;
        Ok(Sampler {
            basis,
            udir,
            vdir,
            nrm,
            patches,
            nbins,
            count: count.max(1),
            seed,
        })
    }

    /// Number of sender bins (matrix rows).
    pub fn bins(&self) -> usize {
        self.nbins
    }

    /// Number of sender surfaces.
    pub fn surfaces(&self) -> usize {
        self.patches.len()
    }

    /// Rays per bin.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Sample `k` (0-based) of bin `b`: origin and unit direction.
    pub fn ray(&self, b: usize, k: usize) -> Result<(DVec3, DVec3)> {
        let c = self.count;
        let index = (b as u64) * (c as u64) + k as u64;
        let mut rng = Rng::for_ray(self.seed ^ 0x5f1e_c7ed_0000_0001, index);
        // direction: stratum k of the bin, spread over the square
        let (s1, s2) = stratified2(k, c, &mut rng);
        // origin: an independent stratum (a permutation of k)
        let kk = ((k as u128 * coprime_step(c) as u128 + (b as u128) * 7_777) % c as u128) as f64;
        let x = (kk + rng.next_f64()) / c as f64;
        let local = |l: DVec3| l.x * self.udir + l.y * self.vdir + l.z * self.nrm;
        let dir = match self.basis {
            Basis::Uniform => {
                let (dx, dy) = square_to_disk(s1, s2);
                let dz = -(1.0 - dx * dx - dy * dy).max(0.0).sqrt();
                local(DVec3::new(dx, dy, dz))
            }
            Basis::ShirleyChiu(n) => {
                let n = n as usize;
                let (dx, dy) = square_to_disk(
                    ((b / n) as f64 + s1) / n as f64,
                    ((b % n) as f64 + s2) / n as f64,
                );
                let dz = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
                -local(DVec3::new(dx, dy, dz))
            }
            Basis::Reinhart(mf) => {
                let mf = mf as usize;
                let rows = 7 * mf + 1;
                let (mut row, mut col) = (0usize, b);
                while col >= reinhart_row_len(mf, row) {
                    col -= reinhart_row_len(mf, row);
                    row += 1;
                }
                let step = std::f64::consts::FRAC_PI_2 / (rows as f64 - 0.5);
                let s1 = if row >= rows - 1 { s1 * s1 } else { s1 };
                let alt = (row as f64 + s1) * step;
                let azi = std::f64::consts::TAU * (col as f64 + s2 - 0.5)
                    / reinhart_row_len(mf, row) as f64;
                let ca = alt.cos();
                -local(DVec3::new(azi.sin() * ca, -azi.cos() * ca, alt.sin()))
            }
            Basis::Klems(size) => {
                let v = size
                    .basis()
                    .sample_projected(b, s1, s2)
                    .expect("bin within the basis");
                -local(DVec3::from(v))
            }
            Basis::Cie => unreachable!("refused in Sampler::new"),
        };
        let dir = dir.normalize();
        let org = self.origin(dir, x, &mut rng)?;
        Ok((org, dir))
    }

    /// An origin on the sender surfaces for a ray leaving in `dir`: a surface chosen by its
    /// area projected towards `dir`, a point on it from `x`.
    fn origin(&self, dir: DVec3, x: f64, rng: &mut Rng) -> Result<DVec3> {
        if self.patches.len() == 1 {
            let p = &self.patches[0];
            if p.surface.normal.dot(dir) >= 1e-6 {
                bail!("internal - sample behind sender '{}'", p.surface.name);
            }
            return Ok(point_on(p, x, rng));
        }
        let proj: Vec<f64> = self
            .patches
            .iter()
            .map(|p| (-p.surface.normal.dot(dir) * p.surface.area).max(0.0))
            .collect();
        let total: f64 = proj.iter().sum();
        if total < 1e-12 {
            bail!("internal - sample behind all sender elements!");
        }
        let mut t = x * total;
        for (p, &a) in self.patches.iter().zip(&proj) {
            if t <= a && a > 0.0 {
                return Ok(point_on(p, t / a, rng));
            }
            t -= a;
        }
        let (i, _) = proj
            .iter()
            .enumerate()
            .rev()
            .find(|(_, &a)| a > 0.0)
            .expect("a positive projected area");
        Ok(point_on(&self.patches[i], 1.0 - 1e-12, rng))
    }
}

fn prepare(s: &Surface) -> Result<Patch> {
    let mut p = Patch {
        surface: s.clone(),
        tris: Vec::new(),
        cum: Vec::new(),
        axes: [DVec3::ZERO; 2],
    };
    match &s.shape {
        Shape::Polygon(v) => {
            let tris = crate::klemsamp::triangulate(v);
            let mut acc = 0.0;
            for t in &tris {
                acc += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
                p.cum.push(acc);
            }
            if tris.is_empty() || acc <= 0.0 || (acc - s.area).abs() > 1e-6 * s.area.max(1e-12) {
                bail!("cannot triangulate polygon '{}'", s.name);
            }
            p.tris = tris;
        }
        Shape::Ring { axis, .. } => {
            let a = if axis.x.abs() < 0.6 {
                DVec3::X
            } else if axis.y.abs() < 0.6 {
                DVec3::Y
            } else {
                DVec3::Z
            };
            let u = axis.cross(a).normalize();
            p.axes = [u, axis.cross(u)];
        }
        Shape::Source { .. } => bail!("illegal sender surface '{}'", s.name),
    }
    Ok(p)
}

/// A point on a prepared surface from a number in [0,1): the triangle by area, the point
/// uniform in it (rings: uniform over the annulus).
fn point_on(p: &Patch, x: f64, rng: &mut Rng) -> DVec3 {
    match &p.surface.shape {
        Shape::Polygon(_) => {
            let total = *p.cum.last().expect("triangles");
            let t = x * total;
            let i = p.cum.partition_point(|&c| c < t).min(p.tris.len() - 1);
            let lo = if i == 0 { 0.0 } else { p.cum[i - 1] };
            let f = ((t - lo) / (p.cum[i] - lo)).clamp(0.0, 1.0);
            let (a, b) = spread2(f, rng);
            let sb = b.sqrt();
            let [v0, v1, v2] = p.tris[i];
            v0 + a * sb * (v1 - v0) + (1.0 - sb) * (v2 - v0)
        }
        Shape::Ring { centre, r0, r1, .. } => {
            let (a, b) = spread2(x, rng);
            let r = (a * (r1 * r1 - r0 * r0) + r0 * r0).sqrt();
            let th = std::f64::consts::TAU * b;
            *centre + r * th.cos() * p.axes[0] + r * th.sin() * p.axes[1]
        }
        Shape::Source { .. } => unreachable!("refused in prepare"),
    }
}

/// The sender rays as rcontrib reads them with `-fd`: origin and direction, six native
/// doubles per ray, bin by bin, generated as they are read.
pub struct RayStream {
    sampler: Sampler,
    next: usize,
    buf: Vec<u8>,
    pos: usize,
}

impl RayStream {
    /// All rays of `sampler`.
    pub fn new(sampler: Sampler) -> Self {
        RayStream {
            sampler,
            next: 0,
            buf: Vec::new(),
            pos: 0,
        }
    }

    fn refill(&mut self) -> std::io::Result<()> {
        let total = self.sampler.nbins * self.sampler.count;
        self.buf.clear();
        self.pos = 0;
        let end = (self.next + 4096).min(total);
        for i in self.next..end {
            let (b, k) = (i / self.sampler.count, i % self.sampler.count);
            let (o, d) = self
                .sampler
                .ray(b, k)
                .map_err(|e| std::io::Error::other(format!("{e:#}")))?;
            for v in [o.x, o.y, o.z, d.x, d.y, d.z] {
                self.buf.extend_from_slice(&v.to_ne_bytes());
            }
        }
        self.next = end;
        Ok(())
    }
}

impl std::io::Read for RayStream {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.pos >= self.buf.len() {
            self.refill()?;
        }
        let n = out.len().min(self.buf.len() - self.pos);
        out[..n].copy_from_slice(&self.buf[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concentric_map_stays_in_the_disk_and_preserves_area() {
        let mut inner = 0;
        let n = 200;
        for i in 0..n {
            for j in 0..n {
                let (x, y) =
                    square_to_disk((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                let r2 = x * x + y * y;
                assert!(r2 < 1.0);
                inner += (r2 < 0.25) as usize;
            }
        }
        // a quarter of the disk's area lies within radius 1/2
        assert!((inner as f64 / (n * n) as f64 - 0.25).abs() < 0.01);
    }
}
