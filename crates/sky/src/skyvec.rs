//! Sky vectors as Radiance's genskyvec computes them: each Reinhart row is the
//! plain mean of 16 samples of the sky function (directions from the .cal `rand`
//! hash of the record number, single precision as rcalc `-of` passes them to
//! rtrace), times the sky colour; the sun is then spread over the three patch
//! centres nearest to it, in proportion to 1/(angle + 0.02) and to the sun's
//! solid angle over each patch's.

use crate::patches::Reinhart;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The .cal language's `rand(x)`: a deterministic hash of x into [0, 1).
#[allow(clippy::approx_constant)] // the hash's own truncated constants, not e and π/4
pub fn cal_rand(x: f64) -> f64 {
    let mut x = x;
    x *= 1.0 / (1.0 + x * x) + 2.71828182845904;
    x += 0.785398163397447 - x.floor();
    x = 1e5 / x;
    x - x.floor()
}

/// genskyvec's options.
#[derive(Debug, Clone)]
pub struct SkyVecOptions {
    /// Reinhart subdivision (`-m`, default 4).
    pub mf: usize,
    /// Sky colour (`-c`, default 0.960 1.004 1.118).
    pub color: [f64; 3],
    /// Compute the sky rows (false with `-d`).
    pub sky: bool,
    /// `-5`: put the raw solar radiance into the single nearest patch.
    pub five_phase: bool,
}

impl Default for SkyVecOptions {
    fn default() -> Self {
        SkyVecOptions {
            mf: 4,
            color: [0.960, 1.004, 1.118],
            sky: true,
            five_phase: false,
        }
    }
}

/// The sun of a sky description.
#[derive(Debug, Clone)]
pub struct Sun {
    /// Radiance words as written (`-5` copies them unchanged).
    pub radiance_words: [String; 3],
    /// Radiance values.
    pub radiance: [f64; 3],
    /// Direction toward the sun as written.
    pub dir: [f64; 3],
    /// Angular diameter, degrees.
    pub diameter: f64,
}

/// One output row and how genskyvec prints it.
#[derive(Debug, Clone, PartialEq)]
pub enum Row {
    /// A sample mean (`total` prints 9 significant digits).
    Mean([f64; 3]),
    /// A row with the sun added (Perl prints 15 significant digits).
    WithSun([f64; 3]),
    /// Verbatim words (`-5`).
    Words([String; 3]),
}

impl Row {
    /// The row's values.
    pub fn values(&self) -> [f64; 3] {
        match self {
            Row::Mean(v) | Row::WithSun(v) => *v,
            Row::Words(w) => {
                let p = |s: &str| s.parse::<f64>().unwrap_or(0.0);
                [p(&w[0]), p(&w[1]), p(&w[2])]
            }
        }
    }
}

/// Row (from the horizon, 0-based; the cap is the last) and column of bin `b` ≥ 1.
fn row_col(basis: &Reinhart, b: usize) -> (usize, usize) {
    basis.row_col(b)
}

/// Direction of sample (x1, x2) in bin `b` (bin 0 = ground), genskyvec's formulas.
pub fn sample_dir(basis: &Reinhart, b: usize, x1: f64, x2: f64) -> [f64; 3] {
    let mf = basis.mf() as f64;
    let alpha = 90.0 / (mf * 7.0 + 0.5);
    let rah = alpha * (PI / 180.0);
    let (alt, azi) = if b == 0 {
        ((-x1).asin(), 2.0 * PI * x2)
    } else {
        let (r, c) = row_col(basis, b);
        let width = 2.0 * PI / basis.row_len(r) as f64;
        ((r as f64 + x1) * rah, (c as f64 + x2 - 0.5) * width)
    };
    let ca = alt.cos();
    [azi.sin() * ca, azi.cos() * ca, alt.sin()]
}

/// Solid angle genskyvec assigns to bin `b` (ground 2π).
pub fn bin_omega(basis: &Reinhart, b: usize) -> f64 {
    let mf = basis.mf() as f64;
    let rah = 90.0 / (mf * 7.0 + 0.5) * (PI / 180.0);
    if b == 0 {
        return 2.0 * PI;
    }
    let (r, _) = row_col(basis, b);
    if b == basis.len() - 1 {
        return 2.0 * PI * (1.0 - (rah / 2.0).cos());
    }
    let width = 2.0 * PI / basis.row_len(r) as f64;
    width * ((rah * (r as f64 + 1.0)).sin() - (rah * r as f64).sin())
}

/// A value as rcalc prints it (`%.9g`) and reads back.
fn printed9(v: f64) -> f64 {
    format!("{v:.8e}").parse().unwrap_or(v)
}

/// Computes the sky vector: `radiance(dir)` is the sky function (skyfunc) for a
/// unit direction.
pub fn sky_vector(
    opt: &SkyVecOptions,
    radiance: &(dyn Fn([f64; 3]) -> f64 + Sync),
    sun: Option<&Sun>,
) -> Vec<Row> {
    let basis = Reinhart::new(opt.mf);
    let n = basis.len();
    let color = opt.color.map(|c| c as f32);
    let mut rows: Vec<Row> = (0..n)
        .into_par_iter()
        .map(|b| {
            if !opt.sky {
                return Row::Mean([0.0; 3]);
            }
            let mut sum = [0.0f64; 3];
            for j in 0..16 {
                let rec = (b * 16 + j + 1) as f64;
                let x1 = cal_rand(rec * 0.37 - 5.3);
                let x2 = cal_rand(rec * -1.47 + 0.86);
                let d = sample_dir(&basis, b, x1, x2).map(|v| f64::from(v as f32));
                let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let d = [d[0] / len, d[1] / len, d[2] / len];
                // rtrace keeps the pattern value and the colour in single precision
                let v = radiance(d) as f32;
                for k in 0..3 {
                    sum[k] += f64::from(color[k] * v);
                }
            }
            Row::Mean(sum.map(|s| s / 16.0))
        })
        .collect();
    let Some(sun) = sun else { return rows };
    if sun.dir[2] <= 0.0 {
        return rows;
    }
    // candidate patch centres within ~30° of the sun, sorted by angle (stable)
    let mut cand: Vec<(f64, f64, usize)> = Vec::new();
    for b in 1..n {
        let d = sample_dir(&basis, b, 0.5, 0.5);
        let dot = d[0] * sun.dir[0] + d[1] * sun.dir[1] + d[2] * sun.dir[2];
        if dot - 0.866 > 0.0 {
            let ang = if 1.0 - dot > 0.0 { dot.acos() } else { 0.0 };
            // genskyvec reads these back from rcalc's text output (9 digits), so
            // near-equal angles tie and keep patch order, as in Radiance
            cand.push((printed9(ang), printed9(bin_omega(&basis, b)), b));
        }
    }
    cand.sort_by(|a, b| a.0.total_cmp(&b.0));
    if opt.five_phase {
        if let Some(&(_, _, b)) = cand.first() {
            rows[b] = Row::Words(sun.radiance_words.clone());
        }
        return rows;
    }
    // genskyvec's own truncated π
    #[allow(clippy::approx_constant)]
    let pi_9 = 3.141592654f64;
    let somega = (sun.diameter / 360.0).powi(2) * pi_9.powi(3);
    let take = cand.len().min(3);
    let wtot: f64 = cand[..take].iter().map(|c| 1.0 / (c.0 + 0.02)).sum();
    for &(ang, dom, b) in &cand[..take] {
        let wt = 1.0 / (ang + 0.02) / wtot * somega / dom;
        let mut v = rows[b].values();
        for (x, s) in v.iter_mut().zip(sun.radiance) {
            *x += wt * s;
        }
        rows[b] = Row::WithSun(v);
    }
    rows
}

/// The .cal library's `Exp`: 0 below −100, else `exp`.
pub fn cal_exp(x: f64) -> f64 {
    if -x - 100.0 > 0.0 {
        0.0
    } else {
        x.exp()
    }
}

/// The Perez all-weather sky as `perezlum.cal` describes it (gendaylit output):
/// arguments diffuse normalisation, ground brightness, a..e, sun direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerezLum {
    /// A1..A10 of perezlum.cal.
    pub a: [f64; 10],
}

impl PerezLum {
    /// From the real arguments of `brightfunc skyfunc 2 skybright perezlum.cal`.
    pub fn from_args(a: &[f64]) -> Option<PerezLum> {
        let a: [f64; 10] = a.get(..10)?.try_into().ok()?;
        Some(PerezLum { a })
    }

    /// Radiance toward unit direction `d`, blended into the ground below the horizon.
    pub fn radiance(&self, d: [f64; 3]) -> f64 {
        let a = &self.a;
        let cg = d[0] * a[7] + d[1] * a[8] + d[2] * a[9];
        let g = crate::cie::bounded_acos(cg);
        let dz = if d[2] - 0.01 > 0.0 { d[2] } else { 0.01 };
        let sky = a[0]
            * (1.0 + a[2] * (a[3] / dz).exp())
            * (1.0 + a[4] * (a[5] * g).exp() + a[6] * cg * cg);
        crate::cie::blend_ground(d[2], sky, a[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rand_is_in_unit_interval() {
        for k in 0..1000 {
            let v = cal_rand(k as f64 * 0.37 - 5.3);
            assert!((0.0..1.0).contains(&v));
        }
    }

    #[test]
    fn uniform_sky_gives_uniform_vector() {
        let opt = SkyVecOptions {
            mf: 1,
            color: [1.0, 1.0, 1.0],
            ..Default::default()
        };
        let rows = sky_vector(&opt, &|_| 2.0, None);
        assert_eq!(rows.len(), 146);
        for r in rows {
            assert!((r.values()[1] - 2.0).abs() < 1e-6);
        }
    }
}
