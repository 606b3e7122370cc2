//! Solar position as Radiance's `sun.c` computes it (IES formulas) plus the
//! Michalsky (1988) variant used by `gensky -y`.
//!
//! Angles are radians. Longitude and standard meridian are measured **west**
//! positive, as in Radiance. Azimuth from [`Site::azimuth`] is measured from
//! south, positive toward west.

use std::f64::consts::PI;

/// Days before the first of each month in a year without a leap day.
const MONTH_START: [i32; 12] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];

/// Day of year (1 = January 1) ignoring leap days, as Radiance's `jdate`.
pub fn julian_day(month: i32, day: i32) -> i32 {
    MONTH_START[(month.clamp(1, 12) - 1) as usize] + day
}

/// Solar declination (radians) for a day of year.
pub fn declination(jd: i32) -> f64 {
    0.4093 * ((2.0 * PI / 365.0) * f64::from(jd - 81)).sin()
}

/// A site: latitude (north), longitude and standard meridian (west), radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    /// Latitude, radians north.
    pub latitude: f64,
    /// Longitude, radians west.
    pub longitude: f64,
    /// Standard meridian, radians west.
    pub meridian: f64,
}

impl Default for Site {
    /// gensky's built-in site (0.66 rad N, 2.13 rad W, meridian 120° W).
    fn default() -> Self {
        Site {
            latitude: 0.66,
            longitude: 2.13,
            meridian: 120.0 * (PI / 180.0),
        }
    }
}

impl Site {
    /// A site from degrees (latitude north, longitude and meridian west).
    pub fn from_degrees(lat: f64, lon: f64, mer: f64) -> Self {
        Site {
            latitude: lat * (PI / 180.0),
            longitude: lon * (PI / 180.0),
            meridian: mer * (PI / 180.0),
        }
    }

    /// Hours to add to standard time to get solar time (equation of time plus
    /// the longitude correction), Radiance's `stadj`.
    pub fn time_adjust(&self, jd: i32) -> f64 {
        0.170 * ((4.0 * PI / 373.0) * f64::from(jd - 80)).sin()
            - 0.129 * ((2.0 * PI / 355.0) * f64::from(jd - 8)).sin()
            + 12.0 * (self.meridian - self.longitude) / PI
    }

    /// Solar altitude (radians) from declination and solar time (hours).
    pub fn altitude(&self, sd: f64, st: f64) -> f64 {
        (self.latitude.sin() * sd.sin() - self.latitude.cos() * sd.cos() * (st * (PI / 12.0)).cos())
            .asin()
    }

    /// Solar azimuth (radians from south, positive west) from declination and solar time.
    pub fn azimuth(&self, sd: f64, st: f64) -> f64 {
        -(sd.cos() * (st * (PI / 12.0)).sin()).atan2(
            -self.latitude.cos() * sd.sin()
                - self.latitude.sin() * sd.cos() * (st * (PI / 12.0)).cos(),
        )
    }

    /// Altitude and azimuth (radians; azimuth from south, west positive) and the
    /// local solar time (hours) for a date and time. `solar_time` means `hour` is
    /// already solar time (gensky's `+` prefix).
    pub fn position(&self, month: i32, day: i32, hour: f64, solar_time: bool) -> SunPosition {
        let jd = julian_day(month, day);
        let sd = declination(jd);
        let st = if solar_time {
            hour
        } else {
            hour + self.time_adjust(jd)
        };
        SunPosition {
            altitude: self.altitude(sd, st),
            azimuth: self.azimuth(sd, st),
            solar_time: st,
        }
    }

    /// Michalsky (1988) solar position for a calendar date and local time
    /// (`solar_time`: the hour is solar time and only the declination comes from
    /// the Michalsky model, evaluated as if the hour were standard time).
    pub fn position_michalsky(
        &self,
        year: i32,
        month: i32,
        day: i32,
        hour: f64,
        solar_time: bool,
    ) -> SunPosition {
        let deg = PI / 180.0;
        // Days since J2000.0 (2000-01-01 12:00 UT) for the UT instant.
        let ut = hour + self.meridian * (12.0 / PI);
        let jdn = days_from_civil(year, month, day) as f64;
        let n = jdn - 0.5 + ut / 24.0;
        let mean_lon = (280.460 + 0.9856474 * n).rem_euclid(360.0);
        let anomaly = ((357.528 + 0.9856003 * n).rem_euclid(360.0)) * deg;
        let ecl = (mean_lon + 1.915 * anomaly.sin() + 0.020 * (2.0 * anomaly).sin()) * deg;
        let obliq = (23.439 - 4e-7 * n) * deg;
        let ra = (obliq.cos() * ecl.sin()).atan2(ecl.cos());
        let sd = (obliq.sin() * ecl.sin()).asin();
        let gmst = (6.697375 + 0.0657098242 * n + ut).rem_euclid(24.0);
        let lmst = (gmst - self.longitude * (12.0 / PI)).rem_euclid(24.0);
        let st = if solar_time {
            hour
        } else {
            (lmst - ra * (12.0 / PI) + 12.0).rem_euclid(24.0)
        };
        SunPosition {
            altitude: self.altitude(sd, st),
            azimuth: self.azimuth(sd, st),
            solar_time: st,
        }
    }
}

/// Days from 2000-01-01 to a date as Radiance's almanac count does it: the day of the year,
/// a leap day whenever the year is divisible by 4, and (year − 1949) × 365 + (year − 1949)/4
/// (C's division, toward zero) days before. It is the calendar for 1901–2099; outside, where
/// Radiance warns that its formula is out of range, it is kept so that positions agree with
/// Radiance's (1900: a day from the Gregorian date).
fn days_from_civil(y: i32, m: i32, d: i32) -> i64 {
    let m = m.clamp(1, 12);
    let leap = i64::from(m > 2 && y & 3 == 0);
    let since = i64::from(y) - 1949;
    // Radiance's Julian-date origin is 2432916.5 (1948-12-31 00:00 UT); J2000 is 2451545.
    i64::from(MONTH_START[(m - 1) as usize]) + i64::from(d) + leap + since * 365 + since / 4 - 18628
}

/// A computed solar position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunPosition {
    /// Altitude above the horizon, radians.
    pub altitude: f64,
    /// Azimuth from south, positive toward west, radians.
    pub azimuth: f64,
    /// Local solar time, hours.
    pub solar_time: f64,
}

impl SunPosition {
    /// Unit vector toward the sun (x east, y north, z up).
    pub fn direction(&self) -> [f64; 3] {
        [
            -self.azimuth.sin() * self.altitude.cos(),
            -self.azimuth.cos() * self.altitude.cos(),
            self.altitude.sin(),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn julian_days() {
        assert_eq!(julian_day(1, 1), 1);
        assert_eq!(julian_day(3, 21), 80);
        assert_eq!(julian_day(12, 31), 365);
        assert_eq!(days_from_civil(2000, 1, 1), 0);
        assert_eq!(days_from_civil(2000, 3, 1), 60);
        // Radiance's almanac count: 2100 has a leap day, 1900 is counted from 1949 by truncation
        assert_eq!(
            days_from_civil(2100, 3, 1) - days_from_civil(2100, 2, 28),
            2
        );
        assert_eq!(days_from_civil(1949, 1, 1), -18627);
    }

    #[test]
    fn equinox_noon_altitude_is_colatitude() {
        // Solar time 12 at the equinox: altitude ≈ 90° − latitude (declination ~0).
        let site = Site::from_degrees(40.0, 0.0, 0.0);
        let p = site.position(3, 22, 12.0, true);
        assert!((p.altitude.to_degrees() - 50.0).abs() < 0.5);
        assert!(p.azimuth.abs() < 1e-9);
    }
}
