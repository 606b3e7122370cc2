//! gendaymtx's time loop: weather records → solar positions and Perez inputs
//! (sequential, as state such as the leap day and dew point history carries over),
//! then the sky columns (independent, computed in parallel; results do not depend
//! on the thread count).

use crate::patches::Reinhart;
use crate::perez::{self, PatchTable, PerezSettings, Quantity, StepInput, WHITE_EFFICACY};
use crate::solar::{self, Site};
use crate::weather::{Tape, WeaUnits};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The sun's full angle used by gendaymtx (degrees).
pub const SUN_ANGLE_DEG: f64 = 0.533;

/// Options of a gendaymtx run.
#[derive(Debug, Clone)]
pub struct DaymtxOptions {
    /// Reinhart subdivision.
    pub mf: usize,
    /// Colours, ground, output type, sun spreading.
    pub settings: PerezSettings,
    /// Rotation of the sky, degrees counter-clockwise (`-r`).
    pub rotation: f64,
    /// Drop steps with the sun below the horizon (`-u`).
    pub sun_hours_only: bool,
    /// Data interval in minutes for the sunrise/sunset correction (`-i`), 0 = off.
    pub interval: f64,
}

impl Default for DaymtxOptions {
    fn default() -> Self {
        DaymtxOptions {
            mf: 1,
            settings: PerezSettings::default(),
            rotation: 0.0,
            sun_hours_only: false,
            interval: 0.0,
        }
    }
}

/// One time step kept in the output.
#[derive(Debug, Clone, Copy)]
pub struct Step {
    /// Perez inputs (meaningless when `night`).
    pub input: StepInput,
    /// dir + dif ≤ 1e-4: the column is zero.
    pub night: bool,
    /// Sun above −0.2665°.
    pub sun_in_sky: bool,
    /// Minute of the year naming the sun for `-D`.
    pub minute: i64,
}

/// Site of a tape in Radiance's internal convention (radians; longitude and meridian west).
pub fn tape_site(tape: &Tape) -> Site {
    let lat = tape.location.latitude;
    let lon = -tape.location.longitude;
    let mer = -15.0 * f64::from(tape.location.timezone);
    Site::from_degrees(lat, lon, mer)
}

fn sunrise_sunset(site: &Site, month: i32, day: i32) -> (f64, f64) {
    let w =
        (-(site.latitude.tan() * solar::declination(solar::julian_day(month, day)).tan())) as f32;
    let w = f64::from(w);
    let h = (PI / 2.0 - w.atan2((1.0 - w * w).sqrt())) * 180.0 / (PI * 15.0);
    (12.0 - h, 12.0 + h)
}

/// Walks the tape: solar position, unit conversion, warnings (returned in order)
/// and the steps to output. Errors name the offending line.
pub fn plan(tape: &Tape, opt: &DaymtxOptions) -> anyhow::Result<(Vec<Step>, Vec<String>)> {
    let site = tape_site(tape);
    let mut steps = Vec::with_capacity(tape.records.len());
    let mut warnings = Vec::new();
    let mut leap_day = 0;
    let mut dpt_hist = [-100.0f32; 2];
    let mut dew_point = 11.0f64;
    let (quantity, dir_is_horiz) = match tape.wea {
        None | Some(WeaUnits::RadNormal) => (Quantity::Radiometric, false),
        Some(WeaUnits::RadHorizontal) => (Quantity::Radiometric, true),
        Some(WeaUnits::PhotNormal) => (Quantity::Photometric, false),
    };
    let min_alt = -((SUN_ANGLE_DEG / 2.0) * (PI / 180.0));
    for r in &tape.records {
        if let Some(dp) = r.dew_point {
            if dpt_hist[0] < -99.0 {
                dpt_hist = [dp, dp];
            }
            dew_point = (1.0 / 3.0) * f64::from(dpt_hist[0] + dpt_hist[1] + dp);
            dpt_hist = [dpt_hist[1], dp];
        } else {
            dpt_hist[0] = -100.0;
        }
        let (mo, da) = (r.month, r.day);
        let hr = f64::from(r.hour);
        let jd = if mo == 2 && da == 29 {
            leap_day = 1;
            60
        } else {
            solar::julian_day(mo, da) + leap_day
        };
        let sd = solar::declination(jd);
        let mut st = hr + site.time_adjust(jd);
        if opt.interval > 0.0 {
            let (rise, set) = sunrise_sunset(&site, mo, da);
            let half = opt.interval / 120.0;
            if (rise - st).abs() <= half {
                st = (st + half + rise) / 2.0;
            } else if (set - st).abs() < half {
                st = (st - half + set) / 2.0;
            }
        }
        let altitude = site.altitude(sd, st);
        let sun_in_sky = altitude > min_alt;
        if opt.sun_hours_only && !sun_in_sky {
            continue;
        }
        let azimuth = site.azimuth(sd, st) + PI - opt.rotation * (PI / 180.0);
        let missing = |what: &str| {
            anyhow::anyhow!(
                "missing required {what} at line {} of the weather file",
                r.line
            )
        };
        let (mut dir, dif) = match tape.wea {
            None | Some(WeaUnits::RadNormal) => (
                f64::from(
                    r.dir_irrad
                        .ok_or_else(|| missing("direct normal irradiance"))?,
                ),
                f64::from(
                    r.diff_irrad
                        .ok_or_else(|| missing("diffuse horizontal irradiance"))?,
                ),
            ),
            Some(WeaUnits::RadHorizontal) => {
                let g = r.glob_irrad.ok_or_else(|| missing("global irradiance"))?;
                let d = r.diff_irrad.ok_or_else(|| missing("diffuse irradiance"))?;
                (f64::from(g) - f64::from(d), f64::from(d))
            }
            Some(WeaUnits::PhotNormal) => (
                f64::from(r.dir_illum.ok_or_else(|| missing("direct illuminance"))?),
                f64::from(r.diff_illum.ok_or_else(|| missing("diffuse illuminance"))?),
            ),
        };
        let minute = 1440 * i64::from(jd - 1) + (hr * 60.0 + 0.5) as i64;
        let night = dir + dif <= 1e-4;
        if !night {
            let limit = if quantity == Quantity::Radiometric {
                20.0
            } else {
                20.0 * WHITE_EFFICACY
            };
            if !sun_in_sky && dir > limit {
                warnings.push(format!("unusually bright at {hr:.1} on {mo}-{da}"));
            }
            if dir_is_horiz && altitude > 1e-6 {
                dir /= altitude.sin();
            }
        }
        steps.push(Step {
            input: StepInput {
                altitude,
                azimuth,
                julian_date: jd,
                direct: dir,
                diffuse: dif,
                dew_point,
                quantity,
            },
            night,
            sun_in_sky,
            minute,
        });
    }
    Ok((steps, warnings))
}

/// The computed columns: `data[step][patch][rgb]` and each step's direct illuminance.
pub struct Columns {
    /// Rows per column (ground + sky patches).
    pub n: usize,
    /// Step-major values, 3 floats per patch.
    pub data: Vec<f32>,
    /// Direct normal illuminance per step (0 at night), for `-D`.
    pub dir_illum: Vec<f64>,
}

/// Computes every step's column (sky, ground and, unless `skip_sun`, the sun).
pub fn compute(basis: &Reinhart, s: &PerezSettings, steps: &[Step], skip_sun: bool) -> Columns {
    let table = PatchTable::new(basis);
    let n = table.n;
    let mut data = vec![0f32; 3 * n * steps.len()];
    let mut dir_illum = vec![0f64; steps.len()];
    data.par_chunks_mut(3 * n)
        .zip(dir_illum.par_iter_mut())
        .zip(steps.par_iter())
        .for_each(|((col, di), st)| {
            if st.night {
                return;
            }
            let m = perez::compute_sky(&table, s, &st.input, col);
            *di = m.dir_illum;
            if !skip_sun {
                perez::add_direct(
                    &table,
                    s,
                    st.input.altitude,
                    st.input.azimuth,
                    m.dir_illum,
                    col,
                );
            }
        });
    Columns { n, data, dir_illum }
}

/// Averages columns as gendaymtx `-A` does (float accumulation in step order,
/// night steps counted but adding nothing).
pub fn average(c: &Columns, steps: &[Step]) -> Vec<f32> {
    let m = 3 * c.n;
    let mut acc = vec![0f32; m];
    for (k, st) in steps.iter().enumerate() {
        if st.night {
            continue;
        }
        let col = &c.data[k * m..(k + 1) * m];
        if k == 0 {
            acc.copy_from_slice(col);
        } else {
            for (a, v) in acc.iter_mut().zip(col) {
                *a += *v;
            }
        }
    }
    let f = 1.0 / steps.len() as f64;
    for a in acc.iter_mut() {
        *a = (f64::from(*a) * f) as f32;
    }
    acc
}

/// Radiance sun description for `-D` (name `solarN`/`sunN`, N = minute of year).
pub fn sun_text(step: &Step, dir_illum: f64, good: bool, sun_color: [f32; 3]) -> String {
    let r = (SUN_ANGLE_DEG / 2.0) * (PI / 180.0);
    let srad = if good {
        dir_illum / (WHITE_EFFICACY * PI * r * r)
    } else {
        0.0
    };
    let v = perez::vector(step.input.altitude, step.input.azimuth);
    let id = step.minute;
    format!(
        "\nvoid light solar{id}\n0\n0\n3 {} {} {}\n\nsolar{id} source sun{id}\n0\n0\n4 {:.6} {:.6} {:.6} {:.4}\n",
        fmt_e(srad * f64::from(sun_color[0]), 3),
        fmt_e(srad * f64::from(sun_color[1]), 3),
        fmt_e(srad * f64::from(sun_color[2]), 3),
        v[0],
        v[1],
        v[2],
        SUN_ANGLE_DEG
    )
}

pub use fenestra_cfmt::{fmt_e, fmt_g};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c_formats() {
        assert_eq!(fmt_g(28.0, 3), "28");
        assert_eq!(fmt_g(0.000123456, 3), "0.000123");
        assert_eq!(fmt_g(1234.5, 3), "1.23e+03");
        assert_eq!(fmt_g(21.849, 3), "21.8");
        assert_eq!(fmt_g(1e-5, 3), "1e-05");
        assert_eq!(fmt_e(6.919e6, 3), "6.919e+06");
        assert_eq!(fmt_e(0.0, 3), "0.000e+00");
    }
}
