//! Indirect (ambient) light: the stratified hemisphere of `-ab`/`-ad`, super-sampling
//! (`-as`) and the concentric square-to-disk map.

use super::*;

impl Tracer {
    /// Indirect diffuse light by stratified cosine-weighted hemisphere sampling (`-aa 0`),
    /// multiplied by `rcol` (the surface's diffuse colour × reflectance).
    pub(super) fn ambient(
        &self,
        r: &Ray,
        p: DVec3,
        nrm: DVec3,
        rcol: DVec3,
        shape: Option<usize>,
        cx: &mut Ctx,
    ) -> DVec3 {
        if !self.effects.ambient || r.amb >= self.opts.ab {
            return rcol * DVec3::from_array(self.opts.av);
        }
        let ad = self.opts.ad as f64;
        // n = round(sqrt(ad · min(weight, d))) ≥ 1; below ad · weight = 2.25 it is 1 whatever
        // d is (the usual case past the first bounce), without the division and the root
        let (n, wt) = if ad * r.weight < 2.25 {
            (1, r.weight)
        } else {
            let mut wt = r.weight;
            let d = 0.8 * maxc(rcol) * r.weight / (ad * self.opts.lw);
            if wt > d {
                wt = d;
            }
            ((((ad * wt).sqrt() + 0.5) as usize).max(1), wt)
        };
        let (a, b) = frame(nrm);
        let skip = shape.filter(|&s| self.accel.shapes[s].is_flat());
        let shoot = |dir: DVec3, acoef: DVec3, cx: &mut Ctx| {
            let mut rc = acoef;
            let mut c = self.child(r, Origin::at(p, skip), dir, AMBIENT, rc);
            c.amb = r.amb + 1;
            if !self.admit(&mut c, &mut rc, cx) {
                return DVec3::ZERO;
            }
            rc * self.trace(&c, cx)
        };
        let direction = |x: f64, y: f64| {
            let (u, v) = square_to_disk(x, y);
            let z = (1.0 - u * u - v * v).max(0.0).sqrt();
            // unit to within rounding (u² + v² + z² = 1 over an orthonormal frame)
            a * u + b * v + nrm * z
        };
        if n == 1 {
            // one stratum: the unit square itself (no division by 1, no batch)
            let (x, y) = (cx.rng.next_f64(), cx.rng.next_f64());
            return shoot(direction(x, y), rcol, cx);
        }
        let acoef = rcol / (n * n) as f64;
        let mut sum = DVec3::ZERO;
        // Directions are drawn a batch at a time (stratum by stratum, row-major), then
        // traced: the batch's arithmetic runs without waiting on each ray's tracing.
        let nf = n as f64;
        // a jittered direction in stratum (row i, column j)
        let stratum = |i: usize, j: usize, cx: &mut Ctx| {
            let x = (j as f64 + cx.rng.next_f64()) / nf;
            let y = (i as f64 + cx.rng.next_f64()) / nf;
            direction(x, y)
        };
        let total = n * n;
        // -as: extra samples where the neighbouring strata vary most (Radiance's rtrace does
        // it for hemispheres of more than 4×4 strata and more than 8 extra samples)
        let extra = (self.opts.asamp as f64 * wt + 0.5) as usize;
        let keep = n > 4 && extra > 8;
        let mut vals = Vec::with_capacity(if keep { total } else { 0 });
        let (mut i, mut j) = (0usize, 0usize);
        let mut dirs = [DVec3::ZERO; AMB_BATCH];
        let mut done = 0;
        while done < total {
            let m = (total - done).min(AMB_BATCH);
            for d in dirs.iter_mut().take(m) {
                *d = stratum(i, j, cx);
                j += 1;
                if j == n {
                    j = 0;
                    i += 1;
                }
            }
            for &dir in &dirs[..m] {
                let v = shoot(dir, acoef, cx);
                if keep {
                    vals.push(v);
                }
                sum += v;
            }
            done += m;
        }
        if keep {
            sum = super_sample(&mut vals, n, extra, cx, |i, j, cx| {
                shoot(stratum(i, j, cx), acoef, cx)
            });
        }
        sum
    }
}

/// Ambient super-sampling (`-as`): `vals` holds one sample per stratum of an n×n hemisphere
/// (row-major). A stratum's need is the variance of its (up to 4) neighbours' samples —
/// not its own, so that the decision to add samples to a stratum does not depend on the
/// sample it is averaged with (which would bias the stratum's mean). `extra` samples are
/// spread in proportion to need, stratum by stratum (⌊need·left/need_left + u⌋, u
/// uniform), drawn with `sample(i, j)` and averaged with the first. Returns the sum over
/// the strata.
pub(super) fn super_sample(
    vals: &mut [DVec3],
    n: usize,
    extra: usize,
    cx: &mut Ctx,
    mut sample: impl FnMut(usize, usize, &mut Ctx) -> DVec3,
) -> DVec3 {
    let bright = |c: DVec3| (c.x + c.y + c.z) / 3.0;
    let mut need = vec![0.0f64; vals.len()];
    for i in 0..n {
        for j in 0..n {
            let k = i * n + j;
            let mut nb = [0.0f64; 4];
            let mut m = 0;
            for (ok, q) in [
                (j > 0, k.wrapping_sub(1)),
                (j + 1 < n, k + 1),
                (i > 0, k.wrapping_sub(n)),
                (i + 1 < n, k + n),
            ] {
                if ok {
                    nb[m] = bright(vals[q]);
                    m += 1;
                }
            }
            let mean = nb[..m].iter().sum::<f64>() / m as f64;
            need[k] = nb[..m].iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (m - 1) as f64;
        }
    }
    let mut need_left: f64 = need.iter().sum();
    let mut left = extra as f64;
    for k in 0..vals.len() {
        if need_left <= 1e-300 || left < 1.0 {
            break;
        }
        let nss = (need[k] * left / need_left + cx.rng.next_f64()) as usize;
        need_left -= need[k];
        if nss < 1 {
            continue;
        }
        left -= nss as f64;
        let mut acc = vals[k];
        for _ in 0..nss {
            acc += sample(k / n, k % n, cx);
        }
        vals[k] = acc / (nss + 1) as f64;
    }
    vals.iter().copied().sum()
}

/// Ambient directions drawn ahead of tracing (see [`Tracer::ambient`]).
pub(super) const AMB_BATCH: usize = 16;

/// Shirley–Chiu concentric map of the unit square onto the unit disk.
pub(super) fn square_to_disk(x: f64, y: f64) -> (f64, f64) {
    let (a, b) = (2.0 * x - 1.0, 2.0 * y - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    // one division and selects instead of branches (the branch is a coin toss); the angle
    // is q (|q| ≤ π/4) or π/2 − q, whose cosine and sine are q's sine and cosine
    let outer_a = a * a > b * b;
    let (r, num) = if outer_a { (a, b) } else { (b, a) };
    let q = (PI / 4.0) * (num / r);
    let (s, c) = sin_cos_quarter(q);
    if outer_a {
        (r * c, r * s)
    } else {
        (r * s, r * c)
    }
}

/// Sine and cosine of |x| ≤ π/4 by their Taylor series to x¹⁵ and x¹⁶ (truncation below
/// 7e-17 and 3e-18; within 2 ulp of the correctly rounded values, checked in the tests),
/// evaluated by Estrin's scheme (three dependent steps instead of eight): no call and no
/// branch, unlike the library's general-argument routine.
pub(super) fn sin_cos_quarter(x: f64) -> (f64, f64) {
    let y = x * x;
    let y2 = y * y;
    let y4 = y2 * y2;
    // sin x = x + x·y·(s0 + s1 y + … + s6 y⁶), s_k = (−1)^(k+1) / (2k+3)!
    const S: [f64; 7] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
    ];
    // cos x = 1 − y·(c0 + c1 y + … + c7 y⁷), c_k = (−1)^k / (2k+2)!
    const C: [f64; 8] = [
        0.5,
        -1.0 / 24.0,
        1.0 / 720.0,
        -1.0 / 40_320.0,
        1.0 / 3_628_800.0,
        -1.0 / 479_001_600.0,
        1.0 / 87_178_291_200.0,
        -1.0 / 20_922_789_888_000.0,
    ];
    let ps = (S[0] + S[1] * y + (S[2] + S[3] * y) * y2) + (S[4] + S[5] * y + S[6] * y2) * y4;
    let pc = (C[0] + C[1] * y + (C[2] + C[3] * y) * y2)
        + (C[4] + C[5] * y + (C[6] + C[7] * y) * y2) * y4;
    (x + x * y * ps, 1.0 - y * pc)
}

/// Two unit vectors completing `n` to an orthonormal frame.
pub(super) fn frame(n: DVec3) -> (DVec3, DVec3) {
    let a = n.any_orthonormal_vector();
    (a, n.cross(a))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_sin_cos_within_two_ulp() {
        let ulp = |v: f64| f64::EPSILON * v.abs().max(f64::MIN_POSITIVE);
        let mut worst: f64 = 0.0;
        for k in -100_000..=100_000 {
            let x = (PI / 4.0) * k as f64 / 100_000.0;
            let (s, c) = sin_cos_quarter(x);
            let es = (s - x.sin()).abs() / ulp(x.sin());
            let ec = (c - x.cos()).abs() / ulp(x.cos());
            worst = worst.max(es).max(ec);
        }
        assert!(worst <= 2.0, "{worst} ulp");
    }

    #[test]
    fn super_sampling_keeps_the_mean_and_lowers_the_spread() {
        // 8×8 strata: a bright disc (value 10) on a dark background (1), each sample
        // uniform ±100% noise around its stratum's value: the true sum is known
        let n = 8;
        let truth = |i: usize, j: usize| {
            let (x, y) = (i as f64 - 2.0, j as f64 - 5.0);
            if x * x + y * y < 5.0 {
                10.0
            } else {
                1.0
            }
        };
        let exact: f64 = (0..n * n).map(|k| truth(k / n, k % n)).sum();
        let run = |seed: u64, extra: usize| {
            let mut cx = Ctx {
                rng: Rng::for_ray(seed, 0),
                rays: [0; 4],
                tracked: &[],
                sink: None,
                ds: None,
            };
            let draw = |i: usize, j: usize, cx: &mut Ctx| {
                DVec3::splat(truth(i, j) * 2.0 * cx.rng.next_f64())
            };
            let mut vals: Vec<DVec3> = (0..n * n).map(|k| draw(k / n, k % n, &mut cx)).collect();
            if extra == 0 {
                return vals.iter().map(|v| v.x).sum::<f64>();
            }
            super_sample(&mut vals, n, extra, &mut cx, draw).x
        };
        let stats = |extra: usize| {
            let xs: Vec<f64> = (0..4000).map(|s| run(s, extra)).collect();
            let m = xs.iter().sum::<f64>() / xs.len() as f64;
            let var = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (xs.len() - 1) as f64;
            (m, var)
        };
        let (m0, v0) = stats(0);
        let (m1, v1) = stats(64);
        // means within 4 standard errors of the exact sum
        assert!(
            (m0 - exact).abs() < 4.0 * (v0 / 4000.0).sqrt(),
            "{m0} {exact}"
        );
        assert!(
            (m1 - exact).abs() < 4.0 * (v1 / 4000.0).sqrt(),
            "{m1} {exact}"
        );
        // the extra samples go where the disc's edge is: the spread drops well below the
        // 1/2 that 64 evenly spread extra samples would give at best
        assert!(v1 < 0.5 * v0, "{v1} {v0}");
    }

    #[test]
    fn concentric_map_equals_its_library_trig_form() {
        let mut rng = Rng::for_ray(1, 2);
        for _ in 0..100_000 {
            let (x, y) = (rng.next_f64(), rng.next_f64());
            let (u, v) = square_to_disk(x, y);
            let (a, b) = (2.0 * x - 1.0, 2.0 * y - 1.0);
            let (r, phi) = if a * a > b * b {
                (a, (PI / 4.0) * (b / a))
            } else {
                (b, PI / 2.0 - (PI / 4.0) * (a / b))
            };
            assert!((u - r * phi.cos()).abs() < 1e-15, "{x} {y}");
            assert!((v - r * phi.sin()).abs() < 1e-15, "{x} {y}");
        }
    }
}
