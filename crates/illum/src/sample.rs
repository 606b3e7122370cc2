//! Sampling a surface's distribution: for every direction bin, `s` rays shot through the
//! surface from its front (room) side toward its back, whose radiance is what the illum
//! will emit in the opposite direction. Bins are uniform in projected solid angle over
//! the hemisphere (uniform in solid angle over a sphere). Every ray's random numbers and
//! its tracer stream are keyed by the seed, the surface's number and the ray's index, so
//! the result does not depend on the thread count.

use fenestra_trace::rng::Rng;
use fenestra_trace::sobol::{point4, scramble_seeds};
use fenestra_trace::Tracer;
use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::{perpendicular, Face, Ring};

/// Radiance's relative origin offset (R_EPS).
const R_EPS: f64 = 0.005;
/// Radiance's FTINY.
const FTINY: f64 = 1e-6;
/// Rejection tries per origin before a sample gives up (counted against the surface's
/// budget of 5 failures per ray, as Radiance's `nallow`).
const MAX_TRIES: usize = 1000;

/// Per-bin sums of sampled radiance.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution {
    /// Altitude divisions.
    pub nalt: usize,
    /// Azimuth divisions.
    pub nazi: usize,
    /// Rays per bin.
    pub nsamps: usize,
    /// Sum of the rays' RGB radiance per bin (`nalt × nazi`, altitude-major), direct
    /// source samples (`l+`) included.
    pub sums: Vec<[f64; 3]>,
    /// Sum of squared luminance of the bin's sample rays (for the standard error).
    pub sumsq: Vec<f64>,
    /// The part of `sums` the light sources added explicitly (`l+`).
    pub lights: Vec<[f64; 3]>,
}

impl Distribution {
    /// An empty distribution.
    pub fn new(nalt: usize, nazi: usize, nsamps: usize) -> Self {
        Distribution {
            nalt,
            nazi,
            nsamps,
            sums: vec![[0.0; 3]; nalt * nazi],
            sumsq: vec![0.0; nalt * nazi],
            lights: vec![[0.0; 3]; nalt * nazi],
        }
    }

    /// Mean radiance over the bins (each bin's mean over its rays).
    pub fn average(&self) -> [f64; 3] {
        let n = self.sums.len() as f64;
        let s = self.nsamps.max(1) as f64;
        let mut a = [0.0; 3];
        for v in &self.sums {
            for k in 0..3 {
                a[k] += v[k];
            }
        }
        a.map(|x| x / n / s)
    }

    /// A peak: the share of the light (the bins hold equal projected solid angles) in the
    /// brightest bin, and that bin, when it holds more than a quarter of the light and is
    /// over 20 times the median bin (a sun seen by way of specular surfaces, which a cell
    /// spreads out).
    pub fn peak(&self) -> Option<(f64, usize)> {
        let mut lum: Vec<f64> = self.sums.iter().map(|v| crate::bright(*v)).collect();
        let total: f64 = lum.iter().sum();
        if lum.len() < 4 || total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        // the first brightest bin
        let (at, max) =
            lum.iter().copied().enumerate().fold(
                (0, 0.0f64),
                |(k, m), (i, v)| if v > m { (i, v) } else { (k, m) },
            );
        let mid = lum.len() / 2;
        let median = *lum.select_nth_unstable_by(mid, f64::total_cmp).1;
        let share = max / total;
        (share > 0.25 && max > 20.0 * median).then_some((share, at))
    }

    /// Fills every bin not `picked` from `coarse` (the same rays per bin, a coarser grid
    /// of the same kind) outside its bins `resampled` (those `picked` replaces): its rays'
    /// part is the mean of those coarse bins' over the area it shares with each
    /// ([`overlaps`], renormalised: a resampled coarse bin's light, the peak's, must not
    /// leak out of the refined directions), its light sources' part (`lights`, `l+`) its
    /// own, drawn at this resolution.
    pub fn fill_from(&mut self, coarse: &Distribution, picked: &[bool], resampled: &[bool]) {
        assert_eq!(self.nsamps, coarse.nsamps, "rays per bin differ");
        let fine = (self.nalt, self.nazi);
        let grid = (coarse.nalt, coarse.nazi);
        for (k, &p) in picked.iter().enumerate() {
            if p {
                continue;
            }
            let all = overlaps(k, fine, grid);
            let mut o: Vec<(usize, f64)> = all
                .iter()
                .copied()
                .filter(|&(c, _)| !resampled[c])
                .collect();
            // (a bin not picked has its centre in a coarse bin not resampled, so some of
            // its area lies there; kept whole should rounding say otherwise)
            if o.iter().map(|x| x.1).sum::<f64>() <= 0.0 {
                o = all;
            }
            let total: f64 = o.iter().map(|x| x.1).sum();
            let mut sum = self.lights[k];
            let mut sq = 0.0;
            for (c, w) in o {
                let w = w / total;
                let rays = std::array::from_fn::<f64, 3, _>(|ch| {
                    coarse.sums[c][ch] - coarse.lights[c][ch]
                });
                for (s, r) in sum.iter_mut().zip(rays) {
                    *s += w * r;
                }
                sq += w * coarse.sumsq[c];
            }
            self.sums[k] = sum;
            self.sumsq[k] = sq;
        }
    }

    /// Standard error of each bin's mean luminance (from its rays' spread).
    pub fn std_errors(&self) -> Vec<f64> {
        let s = self.nsamps as f64;
        self.sums
            .iter()
            .zip(&self.sumsq)
            .map(|(v, &q)| {
                if self.nsamps < 2 {
                    return 0.0;
                }
                let m = crate::bright(*v) / s;
                let var = ((q / s - m * m) * s / (s - 1.0)).max(0.0);
                (var / s).sqrt()
            })
            .collect()
    }

    fn add(&mut self, k: usize, v: [f64; 3]) {
        for (s, x) in self.sums[k].iter_mut().zip(v) {
            *s += x;
        }
        let b = crate::bright(v);
        self.sumsq[k] += b * b;
    }

    /// Adds light `v` of a source sample to bin `k`.
    fn add_light(&mut self, k: usize, v: [f64; 3]) {
        for ((s, l), x) in self.sums[k].iter_mut().zip(&mut self.lights[k]).zip(v) {
            *s += x;
            *l += x;
        }
    }
}

/// The bin of a `coarse` grid (altitude, azimuth divisions) holding the centre of bin `k`
/// of a `fine` grid. Both kinds of grid (hemisphere, sphere) are uniform in their altitude
/// coordinate and in azimuth, azimuth bin `j` centred on `j / nazi` of a turn. Exact
/// (integer) arithmetic: a centre on a coarse boundary always goes to the upper bin.
pub fn containing_bin(k: usize, fine: (usize, usize), coarse: (usize, usize)) -> usize {
    let (a, z) = (k / fine.1, k % fine.1);
    // altitude (a + ½)/Fa in row ⌊(2a + 1)·Ca / (2·Fa)⌋; azimuth z/Fz nearest to column
    // ⌊(2·z·Cz + Fz) / (2·Fz)⌋, wrapped
    let i = ((2 * a + 1) * coarse.0 / (2 * fine.0)).min(coarse.0 - 1);
    let j = ((2 * z * coarse.1 + fine.1) / (2 * fine.1)) % coarse.1;
    i * coarse.1 + j
}

/// The coarse bins that bin `k` of a `fine` grid overlaps, each with the fraction of the
/// fine bin's area it holds (the fractions sum to 1). Areas are measured in the grids'
/// coordinates (altitude coordinate × azimuth turns), in which bins of one grid are equal.
pub fn overlaps(k: usize, fine: (usize, usize), coarse: (usize, usize)) -> Vec<(usize, f64)> {
    let (a, z) = (k / fine.1, k % fine.1);
    let (f0, f1) = (fine.0 as f64, fine.1 as f64);
    let (c0, c1) = (coarse.0 as f64, coarse.1 as f64);
    // the fine bin: altitude [a, a + 1)/Fa, azimuth [z − ½, z + ½)/Fz (turns)
    let (alo, ahi) = (a as f64 / f0, (a + 1) as f64 / f0);
    let (zlo, zhi) = ((z as f64 - 0.5) / f1, (z as f64 + 0.5) / f1);
    let mut out = Vec::new();
    let i0 = ((alo * c0) as usize).min(coarse.0 - 1);
    let i1 = ((ahi * c0).ceil() as usize).clamp(i0 + 1, coarse.0);
    // coarse column j covers [j − ½, j + ½)/Cz; the fine interval may straddle 0
    let j0 = (zlo * c1 + 0.5).floor() as i64;
    let j1 = (zhi * c1 + 0.5).ceil() as i64;
    for i in i0..i1 {
        let da = (ahi.min((i + 1) as f64 / c0) - alo.max(i as f64 / c0)).max(0.0);
        if da <= 0.0 {
            continue;
        }
        for jj in j0..j1 {
            let (clo, chi) = ((jj as f64 - 0.5) / c1, (jj as f64 + 0.5) / c1);
            let dz = (zhi.min(chi) - zlo.max(clo)).max(0.0);
            if dz > 0.0 {
                let j = jj.rem_euclid(coarse.1 as i64) as usize;
                out.push((i * coarse.1 + j, da * dz * f0 * f1));
            }
        }
    }
    out
}

/// Bin `k` of an `nalt × nazi` grid and its neighbours: one row up and down, one bin
/// either way in azimuth (wrapping), and the whole of a row at a pole (its bins all meet
/// there; a sphere has a pole at each end).
pub fn neighbourhood(k: usize, (nalt, nazi): (usize, usize), sphere: bool) -> Vec<bool> {
    let (a, z) = (k / nazi, k % nazi);
    let pole = |i: usize| i == 0 || (sphere && i + 1 == nalt);
    (0..nalt * nazi)
        .map(|q| {
            let (i, j) = (q / nazi, q % nazi);
            let dz = j.abs_diff(z).min(nazi - j.abs_diff(z));
            i.abs_diff(a) <= 1 && (dz <= 1 || pole(i))
        })
        .collect()
}

/// A unit direction uniform in projected solid angle: `alt` is sin²θ, `azi` a turn fraction.
fn flatdir(alt: f64, azi: f64) -> DVec3 {
    let d1 = alt.max(0.0).sqrt();
    let d2 = std::f64::consts::TAU * azi;
    DVec3::new(d1 * d2.cos(), d1 * d2.sin(), (1.0 - alt).max(0.0).sqrt())
}

/// A unit direction uniform over the sphere: `alt` in [0,1] from +z to −z.
fn rounddir(alt: f64, azi: f64) -> DVec3 {
    let z = 1.0 - 2.0 * alt;
    let d1 = (1.0 - z * z).max(0.0).sqrt();
    let d2 = std::f64::consts::TAU * azi;
    DVec3::new(d1 * d2.cos(), d1 * d2.sin(), z)
}

/// The bin of a local hemisphere direction (`z` toward the normal), as Radiance's
/// `flatindex`: altitude by sin²θ, azimuth rounded to the nearest bin centre.
pub fn flatindex(dv: DVec3, nalt: usize, nazi: usize) -> usize {
    let d = 1.0 - dv.z * dv.z;
    let i = ((d * nalt as f64) as usize).min(nalt - 1);
    let mut a = dv.y.atan2(dv.x) * (0.5 / std::f64::consts::PI);
    if a < 0.0 {
        a += 1.0;
    }
    let mut j = (a * nazi as f64 + 0.5) as usize;
    if j >= nazi {
        j = 0;
    }
    i * nazi + j
}

/// Sample `i` of bin `k` of surface `surface` under `seed` (see `Job::cell_point`).
fn bin_point(seed: u64, surface: u64, k: usize, i: usize, rng: &mut Rng) -> [f64; 4] {
    let seeds = scramble_seeds(seed ^ 0x6d6b_736f_626f_6c34, (surface << 36) | k as u64);
    point4(i as u32, seeds, || rng.next_f64())
}

/// What the sampler needs besides the surface.
pub struct Job<'a> {
    /// The tracer.
    pub tracer: &'a Tracer,
    /// Seed of the sampling streams.
    pub seed: u64,
    /// The surface's number in the run (keys its streams).
    pub surface: u64,
    /// Altitude and azimuth divisions.
    pub nalt: usize,
    /// Azimuth divisions.
    pub nazi: usize,
    /// Rays per bin.
    pub nsamps: usize,
    /// Add light sources explicitly (`l+`).
    pub light: bool,
    /// The bins to sample (None: all); the others are left empty, for the caller to fill.
    pub only: Option<Vec<bool>>,
    /// The `p+` refinement level (0: the first distribution): its rays' streams are its own.
    pub level: u64,
    /// Progress (one unit per ray), if shown.
    pub progress: Option<&'a fenestra_cli::progress::Progress>,
}

impl Job<'_> {
    /// Whether bin `k` is sampled.
    fn picked(&self, k: usize) -> bool {
        self.only.as_ref().is_none_or(|m| m[k])
    }

    /// Rays traced: `nsamps` for each bin sampled.
    pub fn rays(&self) -> usize {
        let bins = match &self.only {
            Some(m) => m.iter().filter(|&&p| p).count(),
            None => self.nalt * self.nazi,
        };
        bins * self.nsamps
    }

    /// Counts `n` rays done.
    pub fn tick(&self, n: u64) {
        if let Some(p) = self.progress {
            p.inc(n);
        }
    }

    /// Starts ray `idx` of this surface (counted on the progress bar): its bin (of
    /// `nsamps` rays each), its index in the bin, its sampling stream and tracer ray index.
    pub(crate) fn start_ray(&self, idx: usize) -> (usize, usize, Rng, u64) {
        let (rng, id) = self.stream(idx as u64);
        self.tick(1);
        (idx / self.nsamps, idx % self.nsamps, rng, id)
    }

    /// The sampling stream and tracer ray index of ray `index` of this surface.
    pub fn stream(&self, index: u64) -> (Rng, u64) {
        // the level in the top bits (surface numbers stay below 2^24)
        let id = ((self.surface << 36) | index) ^ (self.level << 60);
        (Rng::for_ray(self.seed ^ 0x6d6b_696c_6c75_6d00, id), id)
    }

    /// Sample `i` of bin `k` as four numbers in [0,1): a point of a Sobol sequence
    /// scrambled for the bin (its own scramble per surface and bin), so the bin's `s`
    /// samples are stratified jointly over where they start and which way they go (a ray
    /// from the window's top heading up meets the overhang, one from its foot may not);
    /// `rng` fills the digits below the 32nd. Order: the start point's two coordinates
    /// (the sequence's best-stratified pair), then the direction's altitude and azimuth.
    pub(crate) fn cell_point(&self, k: usize, i: usize, rng: &mut Rng) -> [f64; 4] {
        bin_point(self.seed, self.surface, k, i, rng)
    }

    /// Direction in local coordinates (toward the normal) of a sample of bin `k` whose
    /// place within the bin is (`s0`, `s1`) (altitude, azimuth), both in [0,1).
    fn local_dir(&self, k: usize, (s0, s1): (f64, f64)) -> DVec3 {
        let alti = k / self.nazi;
        let r1 = (alti as f64 + s0) / self.nalt as f64;
        let r2 = ((k - alti * self.nazi) as f64 + s1 - 0.5) / self.nazi as f64;
        flatdir(r1, r2)
    }

    /// Adds the light sources seen from `org` to the bins of their reversed directions.
    fn add_sources(&self, dist: &mut Distribution, id: u64, org: DVec3, axes: [DVec3; 3]) {
        let [u, v, w] = axes;
        let scale = (self.nalt * self.nazi) as f64 / std::f64::consts::PI;
        for s in self.tracer.source_light(id, org) {
            let l = DVec3::new(s.dir.dot(u), s.dir.dot(v), s.dir.dot(w));
            if l.z >= -FTINY {
                continue;
            }
            let l = -l;
            let k = flatindex(l, self.nalt, self.nazi);
            let d = scale * l.z * s.omega;
            dist.add_light(k, s.value.map(|x| x * d));
        }
    }
}

/// A surface mkillum samples, parsed once for every refinement level.
pub enum Shape {
    /// A polygon.
    Face(Face),
    /// A ring.
    Ring(Ring),
    /// A sphere: centre and radius.
    Sphere(DVec3, f64),
}

impl Shape {
    /// The distribution `job` asks for; `None` when a polygon's origins could not be
    /// placed ("bad aspect").
    pub fn sample(&self, job: &Job) -> Option<Distribution> {
        match self {
            Shape::Face(f) => face(job, f),
            Shape::Ring(r) => Some(ring(job, r)),
            Shape::Sphere(c, radius) => Some(sphere(job, *c, *radius)),
        }
    }

    /// The distribution's frame (u, v, normal) of a flat surface; None for a sphere.
    pub fn axes(&self) -> Option<[DVec3; 3]> {
        match self {
            Shape::Face(f) => Some([f.u, f.v, f.norm]),
            Shape::Ring(r) => Some([r.u, r.v, r.axis]),
            Shape::Sphere(..) => None,
        }
    }
}

/// A polygon's distribution; `None` when origins could not be placed ("bad aspect").
pub fn face(job: &Job, f: &Face) -> Option<Distribution> {
    let n = job.nalt * job.nazi;
    let s = job.nsamps;
    let eps = R_EPS * f.area.sqrt();
    // a start point uniform over the polygon (Face::uniform_point)
    let origin = |xy: (f64, f64), rng: &mut Rng| f.uniform_point(xy, rng, MAX_TRIES);
    let rays: Vec<(usize, [f64; 3], usize)> = (0..n * s)
        .into_par_iter()
        .filter(|idx| job.picked(idx / s))
        .map(|idx| {
            let (k, i, mut rng, id) = job.start_ray(idx);
            let [x, y, s0, s1] = job.cell_point(k, i, &mut rng);
            let dn = job.local_dir(k, (s0, s1));
            let dir = -(dn.x * f.u + dn.y * f.v + dn.z * f.norm);
            let (org, fails) = origin((x, y), &mut rng);
            match org {
                Some(o) => (
                    k,
                    job.tracer.radiance_specular(id, o - eps * dir, dir),
                    fails,
                ),
                None => (k, [0.0; 3], fails),
            }
        })
        .collect();
    let fails: usize = rays.iter().map(|r| r.2).sum();
    if fails > 5 * rays.len() {
        return None;
    }
    let mut dist = Distribution::new(job.nalt, job.nazi, s);
    for (k, v, _) in rays {
        dist.add(k, v);
    }
    if job.light {
        for i in 0..s {
            let (mut rng, id) = job.stream((n * s + i) as u64);
            let (org, _) = origin((rng.next_f64(), rng.next_f64()), &mut rng);
            let org = org?;
            job.add_sources(&mut dist, id, org, [f.u, f.v, f.norm]);
        }
    }
    Some(dist)
}

/// A ring's distribution.
pub fn ring(job: &Job, r: &Ring) -> Distribution {
    let n = job.nalt * job.nazi;
    let s = job.nsamps;
    let eps = R_EPS * r.r1;
    let rays: Vec<(usize, [f64; 3])> = (0..n * s)
        .into_par_iter()
        .filter(|idx| job.picked(idx / s))
        .map(|idx| {
            let (k, i, mut rng, id) = job.start_ray(idx);
            let [x, y, s0, s1] = job.cell_point(k, i, &mut rng);
            let dn = job.local_dir(k, (s0, s1));
            let dir = -(dn.x * r.u + dn.y * r.v + dn.z * r.axis);
            let org = r.point(x, y) + eps * r.axis;
            (k, job.tracer.radiance_specular(id, org, dir))
        })
        .collect();
    let mut dist = Distribution::new(job.nalt, job.nazi, s);
    for (k, v) in rays {
        dist.add(k, v);
    }
    if job.light {
        for i in 0..s {
            let (mut rng, id) = job.stream((n * s + i) as u64);
            let org = r.point(rng.next_f64(), rng.next_f64());
            job.add_sources(&mut dist, id, org, [r.u, r.v, r.axis]);
        }
    }
    dist
}

/// A sphere's distribution (centre and radius), over the whole sphere in world axes.
pub fn sphere(job: &Job, centre: DVec3, radius: f64) -> Distribution {
    let n = job.nalt * job.nazi;
    let s = job.nsamps;
    let rays: Vec<(usize, [f64; 3])> = (0..n * s)
        .into_par_iter()
        .filter(|idx| job.picked(idx / s))
        .map(|idx| {
            let (k, i, mut rng, id) = job.start_ray(idx);
            let [p0, p1, s0, s1] = job.cell_point(k, i, &mut rng);
            let (a, z) = (k / job.nazi, k % job.nazi);
            let out = rounddir(
                (a as f64 + s0) / job.nalt as f64,
                (z as f64 + s1 - 0.5) / job.nazi as f64,
            );
            let u = perpendicular(out);
            let v = out.cross(u);
            let r3 = p0.sqrt();
            let ph = std::f64::consts::TAU * p1;
            let org = centre
                + r3 * radius * ph.cos() * u
                + r3 * radius * ph.sin() * v
                + radius * (1.01 - r3 * r3).sqrt() * out;
            (k, job.tracer.radiance_specular(id, org, -out))
        })
        .collect();
    let mut dist = Distribution::new(job.nalt, job.nazi, s);
    for (k, v) in rays {
        dist.add(k, v);
    }
    dist
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bin_s_samples_are_stratified_and_uniform() {
        // 16 samples of a bin: every coordinate has one sample in each sixteenth, and the
        // start point (coordinates 0 and 1) one in each cell of a 4 x 4 grid
        for k in 0..50 {
            let pts: Vec<[f64; 4]> = (0..16)
                .map(|i| bin_point(7, 1, k, i, &mut Rng::for_ray(3, (k * 16 + i) as u64)))
                .collect();
            for d in 0..4 {
                let mut seen = [false; 16];
                for p in &pts {
                    seen[(p[d] * 16.0) as usize] = true;
                }
                assert!(seen.iter().all(|&x| x), "bin {k} coordinate {d}");
            }
            let mut grid = [false; 16];
            for p in &pts {
                grid[(p[0] * 4.0) as usize * 4 + (p[1] * 4.0) as usize] = true;
            }
            assert!(grid.iter().all(|&x| x), "bin {k} start points");
        }
        // over many bins (scrambles), each coordinate of one sample is uniform: mean 1/2,
        // variance 1/12 (20 000 bins: standard error of the mean 0.002)
        let n = 20_000;
        for d in 0..4 {
            let xs: Vec<f64> = (0..n)
                .map(|k| bin_point(11, 2, k, 5, &mut Rng::for_ray(5, k as u64))[d])
                .collect();
            let m = xs.iter().sum::<f64>() / n as f64;
            let v = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n as f64;
            assert!((m - 0.5).abs() < 0.008, "coordinate {d}: mean {m}");
            assert!(
                (v - 1.0 / 12.0).abs() < 0.004,
                "coordinate {d}: variance {v}"
            );
        }
    }

    #[test]
    fn coarse_bins_hold_the_fine_bins_centres() {
        // d=48 and d=192 (4x): every fine bin's centre lies in the coarse bin found for it
        // (every other fine azimuth centre lies on a coarse boundary: either side will do)
        let (coarse, fine) = ((7, 22), (14, 44));
        for k in 0..fine.0 * fine.1 {
            let c = containing_bin(k, fine, coarse);
            let (a, z) = (k / fine.1, k % fine.1);
            let alt = (a as f64 + 0.5) / fine.0 as f64;
            let sides: Vec<usize> = [-1e-9, 0.0, 1e-9]
                .iter()
                .map(|e| {
                    flatindex(
                        flatdir(alt, z as f64 / fine.1 as f64 + e),
                        coarse.0,
                        coarse.1,
                    )
                })
                .collect();
            assert!(sides.contains(&c), "fine bin {k}: {c} not in {sides:?}");
            if z % 2 == 0 {
                assert!(
                    sides.iter().all(|&x| x == c),
                    "fine bin {k}: {c}, {sides:?}"
                );
            }
        }
        // nested grids: every coarse bin holds the centres of exactly four fine bins
        let mut count = vec![0; coarse.0 * coarse.1];
        for k in 0..fine.0 * fine.1 {
            count[containing_bin(k, fine, coarse)] += 1;
        }
        assert!(count.iter().all(|&c| c == 4), "{count:?}");
        // the neighbourhood: 3 x 3 bins away from the pole (wrapping in azimuth), a whole
        // row at the pole
        let m = neighbourhood(3 * 22, (7, 22), false);
        let picked: Vec<usize> = (0..m.len()).filter(|&q| m[q]).collect();
        assert_eq!(picked, [44, 45, 65, 66, 67, 87, 88, 89, 109]);
        let m = neighbourhood(1, (7, 22), false);
        assert_eq!(m.iter().filter(|&&p| p).count(), 22 + 3);
        assert!(m[22] && m[23] && m[24] && !m[25]);
        // a sphere's last row is a pole too
        let m = neighbourhood(6 * 22 + 5, (7, 22), true);
        assert_eq!(m.iter().filter(|&&p| p).count(), 22 + 3);
    }

    #[test]
    fn filling_spreads_each_coarse_bin_s_flux() {
        // grids that do not nest (d=768 and d=3072): the overlap fractions of a fine bin
        // sum to 1, every coarse bin's area is handed out whole, and a distribution filled
        // from a coarser one keeps its flux (bins of a grid hold equal projected solid
        // angles, so flux = sum / bins)
        let (coarse, fine) = ((28, 88), (55, 173));
        let nf = fine.0 * fine.1;
        let mut given = vec![0.0; coarse.0 * coarse.1];
        for k in 0..nf {
            let o = overlaps(k, fine, coarse);
            let total: f64 = o.iter().map(|x| x.1).sum();
            assert!((total - 1.0).abs() < 1e-12, "fine bin {k}: {total}");
            for (c, w) in o {
                given[c] += w;
            }
        }
        let per = nf as f64 / given.len() as f64;
        for (c, g) in given.iter().enumerate() {
            assert!((g - per).abs() < 1e-9 * per, "coarse bin {c}: {g} of {per}");
        }
        let mut rng = Rng::for_ray(4, 5);
        let mut coarse_d = Distribution::new(coarse.0, coarse.1, 8);
        for v in coarse_d.sums.iter_mut() {
            *v = [rng.next_f64(), rng.next_f64(), 0.0];
        }
        let mut fine_d = Distribution::new(fine.0, fine.1, 8);
        fine_d.fill_from(
            &coarse_d,
            &vec![false; nf],
            &vec![false; coarse.0 * coarse.1],
        );
        let flux = |d: &Distribution| {
            d.sums.iter().map(|v| v[0] + v[1]).sum::<f64>() / d.sums.len() as f64
        };
        assert!((flux(&fine_d) / flux(&coarse_d) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn filling_leaves_out_the_resampled_bins_and_the_coarse_sources() {
        // d=48 -> d=192: one coarse bin resampled (value 1e6, the peak), every other with
        // rays worth 1 per bin plus a light-source part; the fine grid's own source part is
        // 0.25 everywhere. A fine bin not picked must get exactly 1 (rays, the peak left out)
        // + 0.25 (its own sources), whatever coarse sources it overlaps.
        let (coarse, fine) = ((7, 22), (14, 44));
        let nc = coarse.0 * coarse.1;
        let peak = 3 * 22 + 5;
        let mut c = Distribution::new(coarse.0, coarse.1, 4);
        let mut rng = Rng::for_ray(6, 7);
        for k in 0..nc {
            let l = 5.0 * rng.next_f64();
            c.lights[k] = [l; 3];
            c.sums[k] = [if k == peak { 1e6 } else { 1.0 + l }; 3];
        }
        let resampled: Vec<bool> = (0..nc).map(|k| k == peak).collect();
        let picked: Vec<bool> = (0..fine.0 * fine.1)
            .map(|k| resampled[containing_bin(k, fine, coarse)])
            .collect();
        assert!(picked.iter().any(|&p| p) && picked.iter().any(|&p| !p));
        let mut f = Distribution::new(fine.0, fine.1, 4);
        f.lights = vec![[0.25; 3]; fine.0 * fine.1];
        f.sums = f.lights.clone();
        f.fill_from(&c, &picked, &resampled);
        for (k, &p) in picked.iter().enumerate() {
            if !p {
                assert!(
                    (f.sums[k][0] - 1.25).abs() < 1e-12,
                    "fine bin {k}: {:?}",
                    f.sums[k]
                );
            }
        }
    }

    #[test]
    fn flatindex_inverts_the_bins() {
        let (nalt, nazi) = (10, 31);
        let mut rng = Rng::for_ray(1, 2);
        for k in 0..nalt * nazi {
            for _ in 0..20 {
                let alti = k / nazi;
                let r1 = (alti as f64 + rng.next_f64()) / nalt as f64;
                let r2 = ((k - alti * nazi) as f64 + rng.next_f64() - 0.5) / nazi as f64;
                assert_eq!(flatindex(flatdir(r1, r2), nalt, nazi), k);
            }
        }
    }
}
