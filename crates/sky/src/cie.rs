//! CIE sky models as Radiance's `gensky` computes them, and the sky brightness
//! function of `skybright.cal` (clear, overcast, uniform, intermediate).

use std::f64::consts::PI;

/// Luminous efficacy of sky light used by gensky (lm/W).
pub const SKY_EFFICACY: f64 = 203.0;
/// Luminous efficacy of sun light used by gensky (lm/W).
pub const SUN_EFFICACY: f64 = 208.0;

/// The four gensky sky types, numbered as in `skybright.cal`'s first argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkyType {
    /// CIE clear sky (1).
    Clear = 1,
    /// CIE overcast sky (2).
    Overcast = 2,
    /// Uniform sky (3).
    Uniform = 3,
    /// CIE intermediate sky (4).
    Intermediate = 4,
}

impl SkyType {
    /// From skybright.cal's numeric type.
    pub fn from_code(code: f64) -> Option<SkyType> {
        match code.round() as i64 {
            1 => Some(SkyType::Clear),
            2 => Some(SkyType::Overcast),
            3 => Some(SkyType::Uniform),
            4 => Some(SkyType::Intermediate),
            _ => None,
        }
    }

    /// Overcast and uniform skies have no sun-dependent distribution.
    pub fn is_cloudy(self) -> bool {
        matches!(self, SkyType::Overcast | SkyType::Uniform)
    }
}

/// How a brightness given on the command line is to be read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Given {
    /// Not given: computed from the model.
    Default,
    /// Radiance (W/sr/m²): `-b` / `-r`.
    Radiance(f64),
    /// Horizontal irradiance (W/m²): `-B` / `-R`.
    Irradiance(f64),
}

/// Inputs to the gensky model other than the solar position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CieInputs {
    /// Sky type.
    pub sky_type: SkyType,
    /// Whether a sun source is wanted (`+s`, `+i`).
    pub with_sun: bool,
    /// Zenith brightness setting (`-b`/`-B`).
    pub zenith: Given,
    /// Solar brightness setting (`-r`/`-R`).
    pub solar: Given,
    /// Linke turbidity (`-t`).
    pub turbidity: f64,
    /// Ground reflectance (`-g`).
    pub ground_reflectance: f64,
}

impl Default for CieInputs {
    fn default() -> Self {
        CieInputs {
            sky_type: SkyType::Clear,
            with_sun: true,
            zenith: Given::Default,
            solar: Given::Default,
            turbidity: 2.45,
            ground_reflectance: 0.2,
        }
    }
}

/// The computed sky: what gensky prints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CieSky {
    /// Sky type.
    pub sky_type: SkyType,
    /// Solar altitude actually used (radians; clamped to 87° for sunny skies).
    pub altitude: f64,
    /// True when the altitude was reduced to 87°.
    pub clamped: bool,
    /// Unit vector toward the sun (x east, y north, z up).
    pub sun_dir: [f64; 3],
    /// Zenith radiance, W/sr/m².
    pub zenith: f64,
    /// Horizontal diffuse level before the sun and reflectance (`# Ground ambient level`).
    pub ground_ambient: f64,
    /// Ground radiance (skybright.cal's A3).
    pub ground: f64,
    /// Normalisation argument F2 (skybright.cal's A4; 0 for cloudy skies).
    pub f2: f64,
    /// Solar radiance when a sun is written.
    pub sun: Option<f64>,
}

impl CieSky {
    /// The scene text after the comment lines: optional sun, then `skyfunc`.
    pub fn scene_text(&self) -> String {
        let mut out = String::new();
        let d = self.sun_dir;
        if let Some(s) = self.sun {
            let e = fenestra_cfmt::fmt_e(s, 3);
            out.push_str(&format!(
                "\nvoid light solar\n0\n0\n3 {e} {e} {e}\n\nsolar source sun\n0\n0\n4 {:.6} {:.6} {:.6} 0.5\n",
                d[0], d[1], d[2]
            ));
        }
        out.push_str("\nvoid brightfunc skyfunc\n2 skybr skybright.cal\n0\n");
        let t = self.sky_type as i32;
        if self.sky_type.is_cloudy() {
            out.push_str(&format!(
                "3 {t} {} {}\n",
                fenestra_cfmt::fmt_e(self.zenith, 3),
                fenestra_cfmt::fmt_e(self.ground, 3)
            ));
        } else {
            out.push_str(&format!(
                "7 {t} {} {} {} {:.6} {:.6} {:.6}\n",
                fenestra_cfmt::fmt_e(self.zenith, 3),
                fenestra_cfmt::fmt_e(self.ground, 3),
                fenestra_cfmt::fmt_e(self.f2, 3),
                d[0],
                d[1],
                d[2]
            ));
        }
        out
    }
}

fn norm_poly(sky: SkyType, altitude: f64) -> f64 {
    const CLEAR: [f64; 5] = [2.766521, 0.547665, -0.369832, 0.009237, 0.059229];
    const INTER: [f64; 5] = [3.5556, -2.7152, -1.3081, 1.0660, 0.60227];
    let c = if sky == SkyType::Intermediate {
        &INTER
    } else {
        &CLEAR
    };
    let x = (altitude - PI / 4.0) / (PI / 4.0);
    let mut v = c[4];
    for k in (0..4).rev() {
        v = v * x + c[k];
    }
    v
}

/// Computes the sky for a solar altitude/azimuth (radians; azimuth from south, west positive).
pub fn compute(inp: &CieInputs, altitude: f64, azimuth: f64) -> CieSky {
    let cloudy = inp.sky_type.is_cloudy();
    let mut alt = altitude;
    let mut clamped = false;
    if !cloudy && alt > 87.0 * PI / 180.0 {
        alt = 87.0 * PI / 180.0;
        clamped = true;
    }
    let sun_dir = [
        -azimuth.sin() * alt.cos(),
        -azimuth.cos() * alt.cos(),
        alt.sin(),
    ];
    let mut f2 = 0.0;
    let norm = match inp.sky_type {
        SkyType::Uniform => 1.0,
        SkyType::Overcast => 0.777778,
        SkyType::Clear => {
            f2 = 0.274
                * (0.91 + 10.0 * (-3.0 * (PI / 2.0 - alt)).exp() + 0.45 * sun_dir[2] * sun_dir[2]);
            norm_poly(inp.sky_type, alt) / f2 / PI
        }
        SkyType::Intermediate => {
            f2 = (2.739 + 0.9891 * (0.3119 + 2.6 * alt).sin())
                * (-(PI / 2.0 - alt) * (0.4441 + 1.48 * alt)).exp();
            norm_poly(inp.sky_type, alt) / f2 / PI
        }
    };
    let zenith = match inp.zenith {
        Given::Irradiance(e) => e / (norm * PI),
        Given::Radiance(l) => l,
        Given::Default => {
            let mut z = if cloudy {
                8.6 * sun_dir[2] + 0.123
            } else {
                (1.376 * inp.turbidity - 1.81) * alt.tan() + 0.38
            };
            if inp.sky_type == SkyType::Intermediate {
                z = (z + 8.6 * sun_dir[2] + 0.123) / 2.0;
            }
            if z < 0.0 {
                0.0
            } else {
                z * (1000.0 / SKY_EFFICACY)
            }
        }
    };
    let ground_ambient = zenith * norm;
    let mut ground = ground_ambient;
    let mut sun = None;
    let solar_ok = match inp.solar {
        Given::Default => true,
        Given::Radiance(v) | Given::Irradiance(v) => v > 0.0,
    };
    if !cloudy && sun_dir[2] > 0.0 && solar_ok {
        let lsun = match inp.solar {
            Given::Irradiance(e) => e / (5.98e-5 * sun_dir[2]),
            Given::Radiance(l) => l,
            Given::Default => {
                let s = 1.5e9 / SUN_EFFICACY
                    * (1.147 - 0.147 / if sun_dir[2] > 0.16 { sun_dir[2] } else { 0.16 });
                if inp.sky_type == SkyType::Intermediate {
                    s * 0.15
                } else {
                    s
                }
            }
        };
        ground += 6e-5 / PI * lsun * sun_dir[2];
        if inp.with_sun {
            sun = Some(lsun);
        }
    }
    ground *= inp.ground_reflectance;
    CieSky {
        sky_type: inp.sky_type,
        altitude: alt,
        clamped,
        sun_dir,
        zenith,
        ground_ambient,
        ground,
        f2,
        sun,
    }
}

/// skybright.cal's arguments as written in a sky description: A1..A7
/// (type, zenith, ground, F2, sun direction; cloudy skies give only A1..A3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyBright {
    /// Sky type (A1).
    pub sky_type: SkyType,
    /// Zenith brightness (A2).
    pub zenith: f64,
    /// Ground brightness (A3).
    pub ground: f64,
    /// Normalisation (A4).
    pub f2: f64,
    /// Sun direction (A5..A7).
    pub sun: [f64; 3],
}

impl SkyBright {
    /// From the real arguments of a `brightfunc` using `skybr skybright.cal`.
    pub fn from_args(a: &[f64]) -> Option<SkyBright> {
        let t = SkyType::from_code(*a.first()?)?;
        if a.len() < 3 {
            return None;
        }
        let (f2, sun) = if a.len() >= 7 {
            (a[3], [a[4], a[5], a[6]])
        } else if t.is_cloudy() {
            (1.0, [0.0, 0.0, 1.0])
        } else {
            return None;
        };
        Some(SkyBright {
            sky_type: t,
            zenith: a[1],
            ground: a[2],
            f2,
            sun,
        })
    }

    /// Sky radiance toward unit direction `d` (x east, y north, z up), blended
    /// smoothly into the ground brightness below the horizon.
    pub fn radiance(&self, d: [f64; 3]) -> f64 {
        let sky = match self.sky_type {
            SkyType::Overcast => self.zenith * (1.0 + 2.0 * d[2]) / 3.0,
            SkyType::Uniform => self.zenith,
            SkyType::Clear => {
                let cg = d[0] * self.sun[0] + d[1] * self.sun[1] + d[2] * self.sun[2];
                let g = bounded_acos(cg);
                let horizon = if d[2] - 0.01 > 0.0 {
                    1.0 - (-0.32 / d[2]).exp()
                } else {
                    1.0
                };
                self.zenith * (0.91 + 10.0 * (-3.0 * g).exp() + 0.45 * cg * cg) * horizon / self.f2
            }
            SkyType::Intermediate => {
                let cg = d[0] * self.sun[0] + d[1] * self.sun[1] + d[2] * self.sun[2];
                let g = bounded_acos(cg);
                let zt = bounded_acos(self.sun[2]);
                let eta = bounded_acos(d[2]);
                self.zenith
                    * ((1.35 * (5.631 - 3.59 * eta).sin() + 3.12) * (4.396 - 2.6 * zt).sin() + 6.37
                        - eta)
                    / 2.326
                    * (g * -0.563 * ((2.629 - eta) * (1.562 - zt) + 0.812)).exp()
                    / self.f2
            }
        };
        blend_ground(d[2], sky, self.ground)
    }
}

/// The horizon blend shared by skybright.cal and perezlum.cal:
/// weights (Dz+1.01)^10 for the sky and (Dz+1.01)^-10 for the ground.
pub fn blend_ground(dz: f64, sky: f64, ground: f64) -> f64 {
    let a = (dz + 1.01).powf(10.0);
    let b = (dz + 1.01).powf(-10.0);
    (a * sky + b * ground) / (a + b)
}

/// The .cal language's `Acos`: arc cosine with its argument clamped to [-1, 1].
pub fn bounded_acos(x: f64) -> f64 {
    x.clamp(-1.0, 1.0).acos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gensky_3_21_12_values() {
        // gensky 3 21 12 +s with the default site (spec/tools.md §4.1 [ran]).
        let site = crate::solar::Site::default();
        let p = site.position(3, 21, 12.0, false);
        let s = compute(&CieInputs::default(), p.altitude, p.azimuth);
        assert_eq!(format!("{:.1}", s.ground_ambient), "15.1");
        assert_eq!(format!("{:.3e}", s.sun.unwrap()), "6.919e6");
    }

    #[test]
    fn uniform_sky_is_flat_above_horizon() {
        let b = SkyBright::from_args(&[3.0, 10.0, 2.0]).unwrap();
        let v = b.radiance([0.0, 0.0, 1.0]);
        // the ground weight (Dz+1.01)^-20 leaves ~1e-6 relative at the zenith
        assert!((v - 10.0).abs() < 1e-4);
    }
}
