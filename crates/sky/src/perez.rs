//! The Perez all-weather sky (Perez, Seals & Michalsky 1993) and the Perez 1990
//! luminous-efficacy model, computed per sky patch as Radiance's gendaymtx does:
//! single-precision patch tables and results, double-precision model.

use crate::patches::Reinhart;
use std::f64::consts::PI;

/// Radiance's white-light luminous efficacy (lm/W) converting lux to W/m².
pub const WHITE_EFFICACY: f64 = 179.0;
/// Solar constant, W/m².
const SOLAR_CONSTANT_E: f64 = 1367.0;
/// Solar constant, klux.
const SOLAR_CONSTANT_L: f64 = 127.5;
/// Radiance's FTINY.
const FTINY: f64 = 1e-6;

/// Perez 1993 Table 1: a..e as (a1,a2,a3,a4) per clearness category.
#[rustfmt::skip]
const PEREZ: [[f64; 20]; 8] = [
    [1.3525, -0.2576, -0.2690, -1.4366, -0.7670, 0.0007, 1.2734, -0.1233, 2.8000, 0.6004,
     1.2375, 1.0000, 1.8734, 0.6297, 0.9738, 0.2809, 0.0356, -0.1246, -0.5718, 0.9938],
    [-1.2219, -0.7730, 1.4148, 1.1016, -0.2054, 0.0367, -3.9128, 0.9156, 6.9750, 0.1774,
     6.4477, -0.1239, -1.5798, -0.5081, -1.7812, 0.1080, 0.2624, 0.0672, -0.2190, -0.4285],
    [-1.1000, -0.2515, 0.8952, 0.0156, 0.2782, -0.1812, -4.5000, 1.1766, 24.7219, -13.0812,
     -37.7000, 34.8438, -5.0000, 1.5218, 3.9229, -2.6204, -0.0156, 0.1597, 0.4199, -0.5562],
    [-0.5484, -0.6654, -0.2672, 0.7117, 0.7234, -0.6219, -5.6812, 2.6297, 33.3389, -18.3000,
     -62.2500, 52.0781, -3.5000, 0.0016, 1.1477, 0.1062, 0.4659, -0.3296, -0.0876, -0.0329],
    [-0.6000, -0.3566, -2.5000, 2.3250, 0.2937, 0.0496, -5.6812, 1.8415, 21.0000, -4.7656,
     -21.5906, 7.2492, -3.5000, -0.1554, 1.4062, 0.3988, 0.0032, 0.0766, -0.0656, -0.1294],
    [-1.0156, -0.3670, 1.0078, 1.4051, 0.2875, -0.5328, -3.8500, 3.3750, 14.0000, -0.9999,
     -7.1406, 7.5469, -3.4000, -0.1078, -1.0750, 1.5702, -0.0672, 0.4016, 0.3017, -0.4844],
    [-1.0000, 0.0211, 0.5025, -0.5119, -0.3000, 0.1922, 0.7023, -1.6317, 19.0000, -5.0000,
     1.2438, -1.9094, -4.0000, 0.0250, 0.3844, 0.2656, 1.0468, -0.3788, -2.4517, 1.4656],
    [-1.0500, 0.0289, 0.4260, 0.3590, -0.3250, 0.1156, 0.7781, 0.0025, 31.0625, -14.5000,
     -46.1148, 55.3750, -7.2312, 0.4050, 13.3500, 0.6234, 1.5000, -0.6426, 1.8564, 0.5636],
];

/// Lower bounds of the eight clearness (ε) categories; the last ends at 12.01.
const EPSILON_BINS: [f64; 9] = [1.0, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2, 12.01];

/// Perez 1990 Table 4 diffuse luminous efficacy (a, b, c, d).
#[rustfmt::skip]
const DIFFUSE_EFF: [[f64; 4]; 8] = [
    [97.24, -0.46, 12.00, -8.91], [107.22, 1.15, 0.59, -3.95], [104.97, 2.96, -5.53, -8.77],
    [102.39, 5.59, -13.95, -13.90], [100.71, 5.94, -22.75, -23.74], [106.42, 3.83, -36.15, -28.83],
    [141.88, 1.90, -53.24, -14.03], [152.23, 0.35, -45.27, -7.98],
];

/// Perez 1990 Table 4 direct luminous efficacy (a, b, c, d).
#[rustfmt::skip]
const DIRECT_EFF: [[f64; 4]; 8] = [
    [57.20, -4.55, -2.98, 117.12], [98.99, -3.46, -1.21, 12.38], [109.83, -4.90, -1.71, -8.81],
    [110.34, -5.84, -1.99, -4.56], [106.36, -3.97, -1.75, -6.16], [107.19, -1.25, -1.51, -26.73],
    [105.75, 0.77, -1.26, -34.44], [101.18, 1.58, -1.10, -8.29],
];

/// Per-patch tables in gendaymtx's precision (single-precision angles and solid angles;
/// the reference build uses libm sine for the patch cosines, not the table cosine).
#[derive(Debug, Clone)]
pub struct PatchTable {
    /// Number of rows (ground + sky patches).
    pub n: usize,
    /// Patch altitude (radians, f32 as gendaymtx stores it).
    pub alt: Vec<f32>,
    /// Patch azimuth from north toward east (radians, f32).
    pub azi: Vec<f32>,
    /// Patch solid angle (sr, f32).
    pub dom: Vec<f32>,
    /// Unit vectors of the patch centres.
    pub dir: Vec<[f64; 3]>,
    cos_zen: Vec<f64>,
    sin_zen: Vec<f64>,
    horiz_weight: Vec<f64>,
}

impl PatchTable {
    /// Builds the tables for a Reinhart basis.
    pub fn new(basis: &Reinhart) -> PatchTable {
        let n = basis.len();
        let mut alt = vec![0f32; n];
        let mut azi = vec![0f32; n];
        let mut dom = vec![0f32; n];
        let a = basis.row_height();
        alt[0] = (-PI / 2.0) as f32;
        dom[0] = (2.0 * PI) as f32;
        alt[n - 1] = (PI / 2.0) as f32;
        dom[n - 1] = (2.0 * PI * (1.0 - (a * 0.5).cos())) as f32;
        let mut p = 1;
        for r in 0..basis.rows() - 1 {
            let ralt = (a * (r as f64 + 0.5)) as f32;
            let nr = basis.row_len(r);
            let d =
                (2.0 * PI * ((a * (r + 1) as f64).sin() - (a * r as f64).sin()) / nr as f64) as f32;
            for j in 0..nr {
                alt[p] = ralt;
                azi[p] = (2.0 * PI * j as f64 / nr as f64) as f32;
                dom[p] = d;
                p += 1;
            }
        }
        let dir = (0..n)
            .map(|i| vector(f64::from(alt[i]), f64::from(azi[i])))
            .collect();
        let cos_zen = (0..n)
            .map(|i| (PI * 0.5 - f64::from(alt[i])).cos())
            .collect();
        let sin_zen = (0..n)
            .map(|i| (PI * 0.5 - f64::from(alt[i])).sin())
            .collect();
        let horiz_weight = (0..n)
            .map(|i| f64::from(alt[i]).sin() * f64::from(dom[i]))
            .collect();
        PatchTable {
            n,
            alt,
            azi,
            dom,
            dir,
            cos_zen,
            sin_zen,
            horiz_weight,
        }
    }
}

/// gendaymtx's direction from altitude and azimuth (azimuth from north toward east).
pub fn vector(alt: f64, azi: f64) -> [f64; 3] {
    let c = alt.cos();
    [c * azi.sin(), c * azi.cos(), alt.sin()]
}

/// What the weather values mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Direct normal and diffuse horizontal irradiance, W/m².
    Radiometric,
    /// Direct normal and diffuse horizontal illuminance, lux.
    Photometric,
}

/// Settings that stay fixed over a run.
#[derive(Debug, Clone)]
pub struct PerezSettings {
    /// Sky colour (`-c`), zero for sun only.
    pub sky_color: [f32; 3],
    /// Sun colour, zero for sky only.
    pub sun_color: [f32; 3],
    /// Ground reflectance (`-g`).
    pub ground: [f32; 3],
    /// `-O1`: solar (total) radiance instead of visible.
    pub solar_output: bool,
    /// Number of patches the sun is spread over (4, or 1 with `-5`).
    pub nsuns: usize,
    /// Fixed solid angle per sun (`-5`), or none for the patch solid angle.
    pub fixed_sun_sa: Option<f64>,
}

impl Default for PerezSettings {
    fn default() -> Self {
        PerezSettings {
            sky_color: [0.96, 1.004, 1.118],
            sun_color: [1.0, 1.0, 1.0],
            ground: [0.2, 0.2, 0.2],
            solar_output: false,
            nsuns: 4,
            fixed_sun_sa: None,
        }
    }
}

/// Radiance's `bright()`: luminance weighting of an RGB colour.
pub fn bright(c: [f32; 3]) -> f64 {
    0.2651 * f64::from(c[0]) + 0.6701 * f64::from(c[1]) + 0.0648 * f64::from(c[2])
}

/// One time step's inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInput {
    /// Solar altitude, radians.
    pub altitude: f64,
    /// Solar azimuth from north toward east (after any rotation), radians.
    pub azimuth: f64,
    /// Day of year used for the eccentricity.
    pub julian_date: i32,
    /// Direct normal value (irradiance or illuminance).
    pub direct: f64,
    /// Diffuse horizontal value.
    pub diffuse: f64,
    /// Surface dew point (°C).
    pub dew_point: f64,
    /// Meaning of `direct` and `diffuse`.
    pub quantity: Quantity,
}

/// Perez model state for one time step (after [`compute_sky`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepModel {
    /// Diffuse horizontal illuminance (lux, or W/m²·179 with `-O1`).
    pub diff_illum: f64,
    /// Direct normal illuminance.
    pub dir_illum: f64,
    /// Sky clearness ε.
    pub clearness: f64,
    /// Sky brightness Δ.
    pub brightness: f64,
    /// Sun zenith angle used by the model (radians, within [3°, 90°]).
    pub sun_zenith: f64,
    /// Perez a..e.
    pub params: [f64; 5],
    /// Diffuse normalisation (lux per unit relative luminance) — set when the sky is computed.
    pub norm: f64,
}

struct Ctx {
    sun_zenith: f64,
    jd: i32,
    apwc: f64,
    diff_irrad: f64,
    dir_irrad: f64,
    diff_illum: f64,
    dir_illum: f64,
    brightness: f64,
    clearness: f64,
}

impl Ctx {
    fn air_mass(&self) -> f64 {
        1.0 / (self.sun_zenith.cos()
            + 0.15 * (93.885 - self.sun_zenith * (180.0 / PI)).powf(-1.253))
    }
    fn eccentricity(&self) -> f64 {
        let da = (f64::from(self.jd) - 1.0) * (2.0 * PI / 365.0);
        1.00011
            + 0.034221 * da.cos()
            + 0.00128 * da.sin()
            + 0.000719 * (2.0 * da).cos()
            + 0.000077 * (2.0 * da).sin()
    }
    fn sky_brightness(&self) -> f64 {
        self.diff_irrad * self.air_mass() / (SOLAR_CONSTANT_E * self.eccentricity())
    }
    fn sky_clearness(&self) -> f64 {
        let z3 = self.sun_zenith * self.sun_zenith * self.sun_zenith;
        ((self.diff_irrad + self.dir_irrad) / self.diff_irrad + 1.041 * z3) / (1.0 + 1.041 * z3)
    }
    fn category(&self) -> usize {
        (0..8)
            .find(|&i| self.clearness >= EPSILON_BINS[i] && self.clearness < EPSILON_BINS[i + 1])
            .unwrap_or(7)
    }
    fn diffuse_ratio(&self, k: usize) -> f64 {
        let c = &DIFFUSE_EFF[k];
        c[0] + c[1] * self.apwc + c[2] * self.sun_zenith.cos() + c[3] * self.brightness.ln()
    }
    fn direct_ratio(&self, k: usize) -> f64 {
        let c = &DIRECT_EFF[k];
        let v = c[0]
            + c[1] * self.apwc
            + c[2] * (5.73 * self.sun_zenith - 5.0).exp()
            + c[3] * self.brightness;
        if v > 0.0 {
            v
        } else {
            0.0
        }
    }
    fn clamp_photometric(&mut self) {
        if self.clearness > 12.0 {
            self.clearness = 12.0;
        }
        if self.brightness < 0.01 {
            self.brightness = 0.01;
        }
        if self.clearness < 1.0 {
            self.clearness = 1.0;
        }
        if self.brightness > 0.6 {
            self.brightness = 0.6;
        }
    }
    fn solve_from_illuminance(&mut self) -> usize {
        let mut t1 = 0.1;
        let mut t2 = 0.1;
        let mut count = 0;
        self.diff_irrad = self.diff_illum * SOLAR_CONSTANT_E / (SOLAR_CONSTANT_L * 1000.0);
        self.dir_irrad = self.dir_illum * SOLAR_CONSTANT_E / (SOLAR_CONSTANT_L * 1000.0);
        self.brightness = self.sky_brightness();
        self.clearness = self.sky_clearness();
        self.clamp_photometric();
        while ((self.diff_irrad - t1).abs() > 10.0 || (self.dir_irrad - t2).abs() > 10.0)
            && count != 5
        {
            t1 = self.diff_irrad;
            t2 = self.dir_irrad;
            count += 1;
            let k = self.category();
            self.diff_irrad = self.diff_illum / self.diffuse_ratio(k);
            self.dir_irrad = self.direct_ratio(k);
            if self.dir_irrad > 0.1 {
                self.dir_irrad = self.dir_illum / self.dir_irrad;
            }
            self.brightness = self.sky_brightness();
            self.clearness = self.sky_clearness();
            self.clamp_photometric();
        }
        self.category()
    }
}

fn perez_params(sz: f64, epsilon: f64, delta: f64, k: usize) -> [f64; 5] {
    let delta = if epsilon > 1.065 && epsilon < 2.8 && delta < 0.2 {
        0.2
    } else {
        delta
    };
    let x = |i: usize, j: usize| PEREZ[k][4 * i + j];
    let lin = |i: usize| x(i, 0) + x(i, 1) * sz + delta * (x(i, 2) + x(i, 3) * sz);
    if k != 0 {
        [lin(0), lin(1), lin(2), lin(3), lin(4)]
    } else {
        [
            lin(0),
            lin(1),
            (delta * (x(2, 0) + x(2, 1) * sz)).powf(x(2, 2)).exp() - x(2, 3),
            -(delta * (x(3, 0) + x(3, 1) * sz)).exp() + x(3, 2) + delta * x(3, 3),
            lin(4),
        ]
    }
}

/// Fills `out` (3 floats per patch, ground first) with the sky and ground of one
/// time step, without the sun, and returns the model state (for the sun).
pub fn compute_sky(
    t: &PatchTable,
    s: &PerezSettings,
    inp: &StepInput,
    out: &mut [f32],
) -> StepModel {
    let altitude = inp.altitude;
    let sun_zenith = if altitude <= 0.0 {
        90.0 * (PI / 180.0)
    } else if altitude >= 87.0 * (PI / 180.0) {
        3.0 * (PI / 180.0)
    } else {
        90.0 * (PI / 180.0) - altitude
    };
    let mut c = Ctx {
        sun_zenith,
        jd: inp.julian_date,
        apwc: (0.07 * inp.dew_point - 0.075).exp(),
        diff_irrad: 0.0,
        dir_irrad: 0.0,
        diff_illum: 0.0,
        dir_illum: 0.0,
        brightness: 0.0,
        clearness: 0.0,
    };
    let k = match inp.quantity {
        Quantity::Radiometric => {
            c.dir_irrad = inp.direct;
            c.diff_irrad = inp.diffuse;
            c.brightness = c.sky_brightness();
            c.clearness = c.sky_clearness();
            c.clearness = c.clearness.clamp(1.0, 11.9);
            c.brightness = c.brightness.clamp(0.01, 0.6);
            let k = c.category();
            c.diff_illum = c.diff_irrad * c.diffuse_ratio(k);
            c.dir_illum = c.dir_irrad * c.direct_ratio(k);
            k
        }
        Quantity::Photometric => {
            c.dir_illum = inp.direct;
            c.diff_illum = inp.diffuse;
            c.solve_from_illuminance()
        }
    };
    if s.solar_output {
        c.diff_illum = c.diff_irrad * WHITE_EFFICACY;
        c.dir_illum = c.dir_irrad * WHITE_EFFICACY;
    }
    let mut g = c.diff_illum as f32;
    if altitude > 0.0 {
        g = (f64::from(g) + c.dir_illum * altitude.sin()) as f32;
    }
    g = (f64::from(g) * (1.0 / PI / WHITE_EFFICACY)) as f32;
    out[0] = g * s.ground[0];
    out[1] = g * s.ground[1];
    out[2] = g * s.ground[2];
    let mut model = StepModel {
        diff_illum: c.diff_illum,
        dir_illum: c.dir_illum,
        clearness: c.clearness,
        brightness: c.brightness,
        sun_zenith,
        params: [0.0; 5],
        norm: 0.0,
    };
    if bright(s.sky_color) <= 1e-4 {
        out[3..3 * t.n].fill(0.0);
        return model;
    }
    let p = perez_params(sun_zenith, c.clearness, c.brightness, k);
    model.params = p;
    let (czs, szs) = (sun_zenith.cos(), sun_zenith.sin());
    let mut horiz = 0.0f64;
    for i in 1..t.n {
        let aas = (f64::from(t.azi[i]) - inp.azimuth).abs();
        let cz = t.cos_zen[i];
        let cosg = czs * cz + szs * t.sin_zen[i] * aas.cos();
        let gamma = cosg.clamp(-1.0, 1.0).acos();
        let cg = gamma.cos();
        let lum =
            (1.0 + p[0] * (p[1] / cz).exp()) * (1.0 + p[2] * (p[3] * gamma).exp() + p[4] * cg * cg);
        let v = if lum < 0.0 { 0.0 } else { lum as f32 };
        out[3 * i] = v;
        horiz += f64::from(v) * t.horiz_weight[i];
    }
    if horiz <= FTINY {
        for i in 1..t.n {
            out[3 * i] = 1.0;
        }
        horiz = PI;
    }
    let norm = c.diff_illum / horiz;
    model.norm = norm;
    let sf = norm * (1.0 / WHITE_EFFICACY);
    for i in 1..t.n {
        let v = (f64::from(out[3 * i]) * sf) as f32;
        out[3 * i] = v * s.sky_color[0];
        out[3 * i + 1] = v * s.sky_color[1];
        out[3 * i + 2] = v * s.sky_color[2];
    }
    model
}

/// Adds the sun (direct illuminance `dir_illum`) into the patches nearest the
/// solar direction, weighted by proximity, as gendaymtx's `AddDirect`.
pub fn add_direct(
    t: &PatchTable,
    s: &PerezSettings,
    altitude: f64,
    azimuth: f64,
    dir_illum: f64,
    out: &mut [f32],
) {
    if dir_illum <= 1e-4 || bright(s.sun_color) <= 1e-4 {
        return;
    }
    let nsuns = s.nsuns.clamp(1, 4);
    let sv = vector(altitude, azimuth);
    let mut near = [-1.0f64; 4];
    let mut patch = [0usize; 4];
    for p in 1..t.n {
        let pv = &t.dir[p];
        let d = pv[0] * sv[0] + pv[1] * sv[1] + pv[2] * sv[2];
        for i in 0..nsuns {
            if d > near[i] {
                for j in (i + 1..nsuns).rev() {
                    near[j] = near[j - 1];
                    patch[j] = patch[j - 1];
                }
                near[i] = d;
                patch[i] = p;
                break;
            }
        }
    }
    let mut wt = [0.0f64; 4];
    let mut wtot = 0.0;
    for i in (0..nsuns).rev() {
        wt[i] = 1.0 / (1.002 - near[i]);
        wtot += wt[i];
    }
    for i in (0..nsuns).rev() {
        let mut v = (wt[i] * dir_illum / (WHITE_EFFICACY * wtot)) as f32;
        v = match s.fixed_sun_sa {
            Some(sa) => (f64::from(v) / sa) as f32,
            None => v / t.dom[patch[i]],
        };
        let q = 3 * patch[i];
        out[q] += v * s.sun_color[0];
        out[q + 1] += v * s.sun_color[1];
        out[q + 2] += v * s.sun_color[2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_sizes() {
        let t = PatchTable::new(&Reinhart::new(1));
        assert_eq!(t.n, 146);
        let s: f64 = t.dom[1..].iter().map(|&d| f64::from(d)).sum();
        assert!((s - 2.0 * PI).abs() < 1e-4);
    }
}
