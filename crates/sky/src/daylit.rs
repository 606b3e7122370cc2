//! The Perez all-weather sky for one moment as Radiance's gendaylit computes it:
//! Perez (1990) luminous efficacies, the Perez (1993) relative luminance
//! normalised by a 145-direction Tregenza sum, and the description arguments of
//! `perezlum.cal`.

use std::f64::consts::PI;

/// White-light efficacy (lm/W) used to turn lux into Radiance watts.
const WHITE_EFFICACY: f64 = 179.0;
const SOLAR_CONSTANT_E: f64 = 1367.0;
const SOLAR_CONSTANT_L: f64 = 127.5;
const HALF_SUN_ANGLE: f64 = 0.2665;
const CLEAR_INF: f64 = 1.0;
/// Upper clearness kept by gendaylit 2.5 (just inside the last category).
const CLEAR_MAX: f64 = 12.009;
const BRIGHT_INF: f64 = 0.01;
const BRIGHT_SUP: f64 = 0.6;

/// Perez 1993 coefficients a1..e4 per clearness category (as gendaylit stores them, single precision).
#[rustfmt::skip]
const PEREZ: [[f32; 20]; 8] = [
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

const BOUNDS: [f64; 8] = [1.0, 1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200];

#[rustfmt::skip]
const DIFFUSE_EFF: [[f64; 4]; 8] = [
    [97.24, -0.46, 12.00, -8.91], [107.22, 1.15, 0.59, -3.95], [104.97, 2.96, -5.53, -8.77],
    [102.39, 5.59, -13.95, -13.90], [100.71, 5.94, -22.75, -23.74], [106.42, 3.83, -36.15, -28.83],
    [141.88, 1.90, -53.24, -14.03], [152.23, 0.35, -45.27, -7.98],
];

#[rustfmt::skip]
const DIRECT_EFF: [[f64; 4]; 8] = [
    [57.20, -4.55, -2.98, 117.12], [98.99, -3.46, -1.21, 12.38], [109.83, -4.90, -1.71, -8.81],
    [110.34, -5.84, -1.99, -4.56], [106.36, -3.97, -1.75, -6.16], [107.19, -1.25, -1.51, -26.73],
    [105.75, 0.77, -1.26, -34.44], [101.18, 1.58, -1.10, -8.29],
];

/// What the two input values are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DaylitInput {
    /// `-P epsilon delta`.
    Perez(f64, f64),
    /// `-W direct-normal diffuse-horizontal` irradiance (W/m²).
    Irradiance(f64, f64),
    /// `-L direct-normal diffuse-horizontal` illuminance (lux).
    Illuminance(f64, f64),
    /// `-G direct-horizontal diffuse-horizontal` irradiance (W/m²).
    HorizontalIrradiance(f64, f64),
}

/// Output units (`-O`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DaylitOutput {
    /// 0: visible radiance (W/sr/m², lux/179).
    Visible,
    /// 1: solar radiance (W/sr/m²).
    Solar,
    /// 2: luminance (cd/m²).
    Luminance,
}

/// The computed sky.
#[derive(Debug, Clone, PartialEq)]
pub struct DaylitSky {
    /// Sky clearness ε.
    pub epsilon: f64,
    /// Sky brightness Δ.
    pub delta: f64,
    /// Diffuse normalisation (perezlum.cal A1).
    pub diffuse_norm: f64,
    /// Ground brightness (A2).
    pub ground: f64,
    /// Perez a..e (A3..A7).
    pub coeffs: [f64; 5],
    /// Solar radiance of the 0.533° disc.
    pub solar_radiance: f64,
    /// Direction to the sun.
    pub sun_dir: [f64; 3],
}

/// Errors that make gendaylit print its message and stop (or write an error sky).
#[derive(Debug, Clone, PartialEq)]
pub enum DaylitError {
    /// Message and exit.
    Fatal(String),
    /// Warning, then the all-zero "error sky" is written.
    ErrorSky(String),
}

struct Model {
    sunzenith: f64, // degrees
    daynumber: f64,
    eps: f64,
    delta: f64,
    pw: f64,
}

impl Model {
    fn eccentricity(&self) -> f64 {
        let da = 2.0 * PI * (self.daynumber - 1.0) / 365.0;
        1.00011
            + 0.034221 * da.cos()
            + 0.00128 * da.sin()
            + 0.000719 * (2.0 * da).cos()
            + 0.000077 * (2.0 * da).sin()
    }
    fn air_mass(&self) -> f64 {
        1.0 / ((self.sunzenith * PI / 180.0).cos()
            + 0.15 * ((93.885 - self.sunzenith).ln() * (-1.253)).exp())
    }
    fn category(&self, top: f64) -> usize {
        let mut c = 0;
        for i in 0..8 {
            let hi = if i == 7 { top } else { BOUNDS[i + 1] };
            if self.eps >= BOUNDS[i] && self.eps < hi {
                c = i;
            }
        }
        c
    }
    fn diffuse_eff(&self) -> f64 {
        let c = &DIFFUSE_EFF[self.category(12.01)];
        c[0] + c[1] * self.pw + c[2] * (self.sunzenith * PI / 180.0).cos() + c[3] * self.delta.ln()
    }
    fn direct_eff(&self) -> f64 {
        let c = &DIRECT_EFF[self.category(12.1)];
        let v = c[0]
            + c[1] * self.pw
            + c[2] * (5.73 * self.sunzenith * PI / 180.0 - 5.0).exp()
            + c[3] * self.delta;
        v.max(0.0)
    }
    fn brightness(&self, dif: f64) -> f64 {
        dif * self.air_mass() / (SOLAR_CONSTANT_E * self.eccentricity())
    }
    fn clearness(&self, dir: f64, dif: f64) -> f64 {
        let z = self.sunzenith;
        let z3 = 1.041 * z * PI / 180.0 * z * PI / 180.0 * z * PI / 180.0;
        ((dif + dir) / dif + z3) / (1.0 + z3)
    }
}

/// Keeps ε and Δ inside the model's range as gendaylit 2.5 does.
fn check_param(m: &mut Model) -> Result<(), DaylitError> {
    if m.eps.is_nan() || m.delta.is_nan() {
        return Err(DaylitError::ErrorSky(
            "sky clearness or brightness undefined".into(),
        ));
    }
    m.eps = m.eps.clamp(CLEAR_INF, CLEAR_MAX);
    m.delta = m.delta.clamp(BRIGHT_INF, BRIGHT_SUP);
    Ok(())
}

fn check_irr(dir: &mut f64, dif: &mut f64) -> Result<(), DaylitError> {
    check_direct_diffuse(dir, dif, SOLAR_CONSTANT_E, "irradiance")
}

fn check_ill(dir: &mut f64, dif: &mut f64) -> Result<(), DaylitError> {
    check_direct_diffuse(dir, dif, SOLAR_CONSTANT_L * 1000.0, "illuminance")
}

/// Refuses a direct `what` (irradiance or illuminance) above the solar constant `limit`;
/// negative direct and diffuse values become 0 with a warning.
fn check_direct_diffuse(
    dir: &mut f64,
    dif: &mut f64,
    limit: f64,
    what: &str,
) -> Result<(), DaylitError> {
    if *dir > limit {
        return Err(DaylitError::ErrorSky(format!(
            "direct {what} exceeds solar constant"
        )));
    }
    if *dir < 0.0 {
        eprintln!("Warning: direct {what} < 0. Using 0.0");
        *dir = 0.0;
    }
    if *dif < 0.0 {
        eprintln!("Warning: diffuse {what} < 0. Using 0.0");
        *dif = 0.0;
    }
    Ok(())
}

/// Perez a..e for zenith angle `z` (radians), clearness and brightness.
pub fn perez_coeffs(z: f64, eps: f64, delta: f64) -> [f64; 5] {
    let delta = if eps > 1.065 && eps < 2.8 && delta < 0.2 {
        0.2
    } else {
        delta
    };
    let mut k = 7;
    for (i, &b) in BOUNDS.iter().enumerate() {
        if eps >= b {
            k = i;
        }
    }
    let x = |i: usize, j: usize| f64::from(PEREZ[k][4 * i + j]);
    let lin = |i: usize| x(i, 0) + x(i, 1) * z + delta * (x(i, 2) + x(i, 3) * z);
    if k != 0 {
        [lin(0), lin(1), lin(2), lin(3), lin(4)]
    } else {
        [
            lin(0),
            lin(1),
            (delta * (x(2, 0) + x(2, 1) * z)).powf(x(2, 2)).exp() - x(2, 3),
            -(delta * (x(3, 0) + x(3, 1) * z)).exp() + x(3, 2) + delta * x(3, 3),
            lin(4),
        ]
    }
}

fn rel_lum(c: &[f64; 5], dzeta: f64, gamma: f64) -> f64 {
    (1.0 + c[0] * (c[1] / dzeta.cos()).exp())
        * (1.0 + c[2] * (c[3] * gamma).exp() + c[4] * gamma.cos() * gamma.cos())
}

fn normsc(intermediate: bool, altitude: f64) -> f64 {
    const CLEAR: [f64; 5] = [2.766521, 0.547665, -0.369832, 0.009237, 0.059229];
    const INTER: [f64; 5] = [3.5556, -2.7152, -1.3081, 1.0660, 0.60227];
    let c = if intermediate { &INTER } else { &CLEAR };
    let x = (altitude - PI / 4.0) / (PI / 4.0);
    let mut v = c[4];
    for k in (0..4).rev() {
        v = v * x + c[k];
    }
    v
}

/// Precipitable water content gendaylit assumes (cm).
pub const PRECIPITABLE_WATER: f64 = 2.0;

/// Computes the sky for a solar altitude/azimuth (radians; azimuth from south,
/// west positive), day of year, input values, output units, sun on/off and
/// ground reflectance.
pub fn compute(
    altitude: f64,
    azimuth: f64,
    daynumber: f64,
    input: DaylitInput,
    output: DaylitOutput,
    with_sun: bool,
    ground_refl: f64,
) -> Result<DaylitSky, DaylitError> {
    let sun_dir = [
        -azimuth.sin() * altitude.cos(),
        -azimuth.cos() * altitude.cos(),
        altitude.sin(),
    ];
    let mut m = Model {
        sunzenith: 90.0 - altitude * 180.0 / PI,
        daynumber,
        eps: 0.0,
        delta: 0.0,
        pw: PRECIPITABLE_WATER,
    };
    let (mut dir_irr, mut dif_irr);
    let (mut dir_ill, mut dif_ill) = (0.0, 0.0);
    let visible = output != DaylitOutput::Solar;
    match input {
        DaylitInput::Perez(e, d) => {
            m.eps = e;
            m.delta = d;
            check_param(&mut m)?;
            let _ = (e, d);
            dif_irr = m.delta / m.air_mass() * (SOLAR_CONSTANT_E * m.eccentricity());
            let z = m.sunzenith;
            dir_irr = dif_irr
                * ((m.eps - 1.0)
                    * (1.0 + 1.041 * z * PI / 180.0 * z * PI / 180.0 * z * PI / 180.0));
            check_irr(&mut dir_irr, &mut dif_irr)?;
            if visible {
                dif_ill = dif_irr * m.diffuse_eff();
                dir_ill = dir_irr * m.direct_eff();
                check_ill(&mut dir_ill, &mut dif_ill)?;
            }
        }
        DaylitInput::Irradiance(dir, dif) | DaylitInput::HorizontalIrradiance(dir, dif) => {
            dir_irr = dir;
            dif_irr = dif;
            if matches!(input, DaylitInput::HorizontalIrradiance(..)) {
                if altitude <= 0.0 {
                    return Err(DaylitError::Fatal(
                        "solar zenith angle larger than 90 degrees: the models used are not valid"
                            .into(),
                    ));
                }
                dir_irr /= altitude.sin();
            }
            check_irr(&mut dir_irr, &mut dif_irr)?;
            m.delta = m.brightness(dif_irr);
            m.eps = m.clearness(dir_irr, dif_irr);
            check_param(&mut m)?;
            if visible {
                dif_ill = dif_irr * m.diffuse_eff();
                dir_ill = dir_irr * m.direct_eff();
                check_ill(&mut dir_ill, &mut dif_ill)?;
            }
        }
        DaylitInput::Illuminance(dir, dif) => {
            dir_ill = dir;
            dif_ill = dif;
            check_ill(&mut dir_ill, &mut dif_ill)?;
            dif_irr = dif_ill * SOLAR_CONSTANT_E / (SOLAR_CONSTANT_L * 1000.0);
            dir_irr = dir_ill * SOLAR_CONSTANT_E / (SOLAR_CONSTANT_L * 1000.0);
            m.eps = m.clearness(dir_irr, dif_irr);
            m.delta = m.brightness(dif_irr);
            check_param(&mut m)?;
            // irradiance from illuminance through the efficacies, exactly 9 times as
            // Radiance's gendaylit (its stop test never holds once the parameters are
            // clamped, so it ends at its counter): where the clearness flips between two
            // Perez categories the values cycle and the ninth is the one printed. A direct
            // efficacy below 0.1 lm/W (a sun at the horizon) gives no direct irradiance.
            for _ in 0..9 {
                dif_irr = dif_ill / m.diffuse_eff();
                let d_eff = m.direct_eff();
                dir_irr = if d_eff < 0.1 { 0.0 } else { dir_ill / d_eff };
                m.delta = m.brightness(dif_irr);
                m.eps = m.clearness(dir_irr, dif_irr);
                check_param(&mut m)?;
            }
            check_param(&mut m)?;
        }
    }
    let z = m.sunzenith * PI / 180.0;
    let coeffs = perez_coeffs(z, m.eps, m.delta);
    if coeffs[1] > 0.0 {
        return Err(DaylitError::ErrorSky(format!(
            "positive Perez parameter B (= {:.6}), printing error sky",
            coeffs[1]
        )));
    }
    // 145 Tregenza directions, azimuth measured from the sun
    let mut integ = 0.0f64;
    let basis = crate::patches::Reinhart::new(1);
    let mut dirs: Vec<(f32, f32)> = Vec::with_capacity(145);
    for r in 0..basis.rows() {
        let n = basis.row_len(r);
        let theta = if r == basis.rows() - 1 {
            0.0
        } else {
            90.0 - (12.0 * r as f64 + 6.0)
        };
        for j in 0..n {
            dirs.push((theta as f32, (360.0 * j as f64 / n as f64) as f32));
        }
    }
    for &(th, ph) in &dirs {
        let th = f64::from(th) * PI / 180.0;
        let ph = f64::from(ph) * PI / 180.0;
        let c = z.cos() * th.cos() + z.sin() * th.sin() * ph.cos();
        let gamma = if c > 1.0 { 0.0 } else { c.acos() };
        let lv = rel_lum(&coeffs, th, gamma) as f32;
        integ += f64::from(lv) * th.cos();
    }
    let integ = integ * 2.0 * PI / 145.0;
    let diffuse_norm = match output {
        DaylitOutput::Visible => dif_ill / integ / WHITE_EFFICACY,
        DaylitOutput::Solar => dif_irr / integ,
        DaylitOutput::Luminance => dif_ill / integ,
    };
    let disc = 2.0 * PI * (1.0 - (HALF_SUN_ANGLE * PI / 180.0).cos());
    let solar_radiance = match output {
        DaylitOutput::Visible => dir_ill / disc / WHITE_EFFICACY,
        DaylitOutput::Solar => dir_irr / disc,
        DaylitOutput::Luminance => dir_ill / disc,
    };
    let zenith = rel_lum(&coeffs, 0.0, z) * diffuse_norm;
    let mut normfactor = 0.0;
    if m.eps == 1.0 {
        normfactor = 0.777778;
    }
    if m.eps >= 6.0 {
        let f2 = 0.274
            * (0.91 + 10.0 * (-3.0 * (PI / 2.0 - altitude)).exp() + 0.45 * sun_dir[2] * sun_dir[2]);
        normfactor = normsc(false, altitude) / f2 / PI;
    }
    if m.eps > 1.0 && m.eps < 6.0 {
        let f2 = (2.739 + 0.9891 * (0.3119 + 2.6 * altitude).sin())
            * (-(PI / 2.0 - altitude) * (0.4441 + 1.48 * altitude)).exp();
        normfactor = normsc(true, altitude) / f2 / PI;
    }
    let mut ground = zenith * normfactor;
    if with_sun && m.eps > 1.0 {
        ground += 6.8e-5 / PI * solar_radiance * sun_dir[2];
    }
    ground *= ground_refl;
    Ok(DaylitSky {
        epsilon: m.eps,
        delta: m.delta,
        diffuse_norm,
        ground,
        coeffs,
        solar_radiance,
        sun_dir,
    })
}
