//! Weather tapes for gendaymtx: DAYSIM `.wea` and EnergyPlus `.epw`, read as
//! Radiance 6 reads them (values kept in single precision, hour of an hourly EPW
//! record moved to the middle of its interval).

use std::io::BufRead;

/// Errors reading a weather file; each names the line.
#[derive(Debug, thiserror::Error)]
pub enum WeatherError {
    /// A header line is missing or malformed.
    #[error("header format error in {kind} file at line {line}: expected {expected}")]
    Header {
        /// "WEA" or "EPW".
        kind: &'static str,
        /// 1-based line number.
        line: usize,
        /// What was expected.
        expected: &'static str,
    },
    /// A data line is malformed.
    #[error("{kind} file, format error at line {line}: {what}")]
    Data {
        /// "WEA" or "EPW".
        kind: &'static str,
        /// 1-based line number.
        line: usize,
        /// What was wrong.
        what: String,
    },
    /// Reading failed.
    #[error("read error: {0}")]
    Io(#[from] std::io::Error),
}

/// What the two value columns of a .wea hold (weather_data_file_units).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeaUnits {
    /// 1: direct normal and diffuse horizontal irradiance.
    RadNormal,
    /// 2: direct horizontal and diffuse horizontal irradiance.
    RadHorizontal,
    /// 3: direct normal and diffuse horizontal illuminance.
    PhotNormal,
}

/// The site of a weather tape.
#[derive(Debug, Clone, PartialEq)]
pub struct Location {
    /// Place name.
    pub place: String,
    /// Latitude, degrees north.
    pub latitude: f64,
    /// Longitude, degrees **east** (as Radiance stores it internally).
    pub longitude: f64,
    /// Time zone, hours east of Greenwich (single precision as read).
    pub timezone: f32,
    /// Elevation, m.
    pub elevation: f32,
}

/// One weather record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Record {
    /// Month 1..12.
    pub month: i32,
    /// Day of month.
    pub day: i32,
    /// Hour, local standard time (middle of the interval), single precision.
    pub hour: f32,
    /// Direct normal irradiance (W/m²) or None if missing.
    pub dir_irrad: Option<f32>,
    /// Diffuse horizontal irradiance.
    pub diff_irrad: Option<f32>,
    /// Global horizontal irradiance.
    pub glob_irrad: Option<f32>,
    /// Direct normal illuminance (lux).
    pub dir_illum: Option<f32>,
    /// Diffuse horizontal illuminance (lux).
    pub diff_illum: Option<f32>,
    /// Dew point temperature (°C).
    pub dew_point: Option<f32>,
    /// 1-based line number of the record.
    pub line: usize,
}

/// A whole weather tape.
#[derive(Debug, Clone)]
pub struct Tape {
    /// Site.
    pub location: Location,
    /// `Some(units)` for a .wea, `None` for an EPW.
    pub wea: Option<WeaUnits>,
    /// Records in file order.
    pub records: Vec<Record>,
    /// Warnings to print (Radiance prints these on stderr).
    pub warnings: Vec<String>,
}

fn days_in(month: i32) -> i32 {
    [31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31][(month - 1) as usize]
}

fn date_ok(month: i32, day: i32, hour: f32) -> bool {
    (1..=12).contains(&month) && (0.0..=24.0).contains(&hour) && day >= 1 && day <= days_in(month)
}

/// Leading number of a word as C's `atof` reads it (0 if none).
pub use fenestra_cfmt::atof;

fn parse_f32(w: &str) -> Option<f32> {
    w.parse::<f32>().ok().filter(|v| v.is_finite())
}

/// Whether `s` starts with the ASCII `prefix`, ignoring case (byte-wise: no slicing
/// inside a character).
fn starts_ci(s: &str, prefix: &str) -> bool {
    s.as_bytes()
        .get(..prefix.len())
        .is_some_and(|b| b.eq_ignore_ascii_case(prefix.as_bytes()))
}

/// Reads a .wea or .epw tape (decided by the first line).
pub fn read_tape(input: &mut dyn BufRead) -> Result<Tape, WeatherError> {
    // bytes as Radiance reads them: a line that is not UTF-8 is read lossily (names only)
    let mut lines: Vec<String> = Vec::new();
    for l in input.split(b'\n') {
        let mut l = l?;
        if l.last() == Some(&b'\r') {
            l.pop();
        }
        lines.push(String::from_utf8_lossy(&l).into_owned());
    }
    let first = lines.first().map(String::as_str).unwrap_or("");
    if starts_ci(first, "place ") {
        read_wea(&lines)
    } else if starts_ci(first, "LOCATION,") {
        read_epw(&lines)
    } else {
        Err(WeatherError::Header {
            kind: "WEA",
            line: 1,
            expected: "'place <city>_<country>' (.wea) or 'LOCATION,...' (.epw)",
        })
    }
}

fn keyed<'a>(lines: &'a [String], i: usize, key: &str) -> Option<&'a str> {
    let l = lines.get(i)?.trim_start();
    let rest = l.strip_prefix(key)?;
    Some(rest.trim())
}

/// The error maker for data line `line` of a `kind` file; when the line lacks fields (not
/// `complete`), the error that `expected` were expected and `found` found.
fn data_line(
    kind: &'static str,
    line: usize,
    complete: bool,
    expected: &str,
    found: &dyn std::fmt::Display,
) -> Result<impl Fn(String) -> WeatherError, WeatherError> {
    let derr = move |what| WeatherError::Data { kind, line, what };
    if !complete {
        return Err(derr(format!("expected {expected}, found {found}")));
    }
    Ok(derr)
}

fn read_wea(lines: &[String]) -> Result<Tape, WeatherError> {
    let herr = |line: usize, expected: &'static str| WeatherError::Header {
        kind: "WEA",
        line,
        expected,
    };
    // as Radiance's `%[^_]_%[^\r\n]`: a city (the country after '_' may be missing)
    let place = lines[0][6..].trim_end().to_string();
    if place.is_empty() || place.starts_with('_') {
        return Err(herr(1, "'place <city>_<country>'"));
    }
    let num = |i: usize, key: &str, exp: &'static str| -> Result<f64, WeatherError> {
        keyed(lines, i, key)
            .and_then(|v| v.split_whitespace().next())
            .and_then(|w| w.parse::<f64>().ok())
            .ok_or_else(|| herr(i + 1, exp))
    };
    let latitude = num(1, "latitude", "'latitude <degrees north>'")?;
    let lon_west = num(2, "longitude", "'longitude <degrees west>'")?;
    let tz = num(3, "time_zone", "'time_zone <meridian degrees west>'")? as f32;
    let elevation = num(4, "site_elevation", "'site_elevation <m>'")? as f32;
    // Radiance scales the single-precision value in double precision and stores it back
    // in single: time_zone -180 is exactly 12 hours (in f32 arithmetic it would be
    // 12.000001 and refused)
    let timezone = (f64::from(tz) * (-1.0 / 15.0)) as f32;
    let longitude = -lon_west;
    check_location(latitude, longitude, timezone, elevation, "WEA", 5)?;
    let units = match num(
        5,
        "weather_data_file_units",
        "'weather_data_file_units 1|2|3'",
    )? as i64
    {
        1 => WeaUnits::RadNormal,
        2 => WeaUnits::RadHorizontal,
        3 => WeaUnits::PhotNormal,
        _ => return Err(herr(6, "weather_data_file_units 1, 2 or 3")),
    };
    let mut records = Vec::new();
    for (i, l) in lines.iter().enumerate().skip(6) {
        let line = i + 1;
        let w: Vec<&str> = l.split_whitespace().collect();
        if w.is_empty() {
            continue;
        }
        let derr = data_line(
            "WEA",
            line,
            w.len() >= 5,
            "'month day hour value1 value2'",
            &format_args!("'{}'", l.trim()),
        )?;
        let month: i32 = w[0]
            .parse()
            .map_err(|_| derr(format!("bad month '{}'", w[0])))?;
        let day: i32 = w[1]
            .parse()
            .map_err(|_| derr(format!("bad day '{}'", w[1])))?;
        let hour = parse_f32(w[2]).ok_or_else(|| derr(format!("bad hour '{}'", w[2])))?;
        if !date_ok(month, day, hour) {
            return Err(derr(format!("illegal date/time {month} {day} {}", w[2])));
        }
        let v1 = parse_f32(w[3]).ok_or_else(|| derr(format!("bad value '{}'", w[3])))?;
        let v2 = parse_f32(w[4]).ok_or_else(|| derr(format!("bad value '{}'", w[4])))?;
        let mut r = Record {
            month,
            day,
            hour,
            dir_irrad: None,
            diff_irrad: None,
            glob_irrad: None,
            dir_illum: None,
            diff_illum: None,
            dew_point: None,
            line,
        };
        match units {
            WeaUnits::RadNormal => {
                r.dir_irrad = Some(v1);
                r.diff_irrad = Some(v2);
            }
            WeaUnits::RadHorizontal => {
                r.glob_irrad = Some(v1 + v2);
                r.diff_irrad = Some(v2);
            }
            WeaUnits::PhotNormal => {
                r.dir_illum = Some(v1);
                r.diff_illum = Some(v2);
            }
        }
        records.push(r);
    }
    Ok(Tape {
        location: Location {
            place,
            latitude,
            longitude,
            timezone,
            elevation,
        },
        wea: Some(units),
        records,
        warnings: Vec::new(),
    })
}

fn check_location(
    lat: f64,
    lon: f64,
    tz: f32,
    elev: f32,
    kind: &'static str,
    line: usize,
) -> Result<(), WeatherError> {
    let bad = |expected| WeatherError::Header {
        kind,
        line,
        expected,
    };
    if !(-90.0..=90.0).contains(&lat) {
        return Err(bad("a latitude within -90..90"));
    }
    if !(-180.0..=180.0).contains(&lon) {
        return Err(bad("a longitude within -180..180"));
    }
    if !(-12.0..=12.0).contains(&tz) {
        return Err(bad("a time zone within 12 hours of Greenwich"));
    }
    if !(-1000.0..=9999.9).contains(&elev) {
        return Err(bad("an elevation within -1000..9999.9 m"));
    }
    Ok(())
}

fn read_epw(lines: &[String]) -> Result<Tape, WeatherError> {
    let herr = |line: usize, expected: &'static str| WeatherError::Header {
        kind: "EPW",
        line,
        expected,
    };
    let f: Vec<&str> = lines[0].splitn(10, ',').collect();
    if f.len() < 10 {
        return Err(herr(
            1,
            "LOCATION,city,state,country,source,WMO,lat,lon,tz,elev",
        ));
    }
    let nums: Vec<&str> = f[6..].iter().flat_map(|s| s.split(',')).collect();
    let p = |i: usize| nums.get(i).and_then(|s| s.trim().parse::<f64>().ok());
    let (latitude, longitude, tz, elev) = match (p(0), p(1), p(2), p(3)) {
        (Some(a), Some(b), Some(c), Some(d)) => (a, b, c as f32, d as f32),
        _ => {
            return Err(herr(
                1,
                "numeric latitude, longitude, time zone and elevation",
            ))
        }
    };
    check_location(latitude, longitude, tz, elev, "EPW", 1)?;
    let heads = [
        "DESIGN CONDITIONS,",
        "TYPICAL/EXTREME PERIODS,",
        "GROUND TEMPERATURES,",
        "HOLIDAYS/DAYLIGHT SAVINGS,",
        "COMMENTS 1,",
        "COMMENTS 2,",
        "DATA PERIODS,",
    ];
    for (k, h) in heads.iter().enumerate() {
        let l = lines.get(k + 1).map(String::as_str).unwrap_or("");
        if !starts_ci(l, h) {
            return Err(herr(k + 2, "the EPW header lines in order"));
        }
    }
    let mut warnings = Vec::new();
    let dp: Vec<&str> = lines[7][13..].split(',').collect();
    if dp.first().map(|s| atof(s) as i64) != Some(1) {
        warnings.push("ignoring data periods after first".to_string());
    }
    let nperhour = dp.get(1).map(|s| atof(s) as i64).unwrap_or(0);
    if nperhour <= 0 {
        return Err(herr(
            8,
            "DATA PERIODS with a positive number of records per hour",
        ));
    }
    let mut records = Vec::new();
    for (i, l) in lines.iter().enumerate().skip(8) {
        let line = i + 1;
        if l.trim().is_empty() {
            continue;
        }
        let w: Vec<&str> = l.split(',').collect();
        let derr = data_line(
            "EPW",
            line,
            w.len() >= 22,
            "at least 22 comma-separated fields",
            &w.len(),
        )?;
        let int = |k: usize| -> Result<i32, WeatherError> {
            w[k].trim()
                .parse::<i32>()
                .map_err(|_| derr(format!("field {} '{}' is not an integer", k + 1, w[k])))
        };
        let (_year, month, day, hour, minute) = (int(0)?, int(1)?, int(2)?, int(3)?, int(4)?);
        let mut h = (hour - 1) as f32;
        if nperhour == 1 {
            h += 0.5;
        } else {
            h += minute as f32 * (1.0f32 / 60.0);
        }
        if !date_ok(month, day, h) {
            return Err(derr(format!("illegal date/time {month}/{day} hour {hour}")));
        }
        // Fields after the data-source flags: 6 dry bulb, 7 dew point, ...
        let val = |k: usize, missing: f32| -> Option<f32> {
            let s = w.get(k)?;
            if s.is_empty() {
                return None;
            }
            let v = atof(s) as f32;
            if v >= missing {
                None
            } else {
                Some(v)
            }
        };
        let dew = w.get(7).filter(|s| !s.is_empty()).map(|s| atof(s) as f32);
        let dew = dew.filter(|&v| v != 99.9);
        records.push(Record {
            month,
            day,
            hour: h,
            glob_irrad: val(13, 9999.0),
            dir_irrad: val(14, 9999.0),
            diff_irrad: val(15, 9999.0),
            dir_illum: val(18, 999900.0),
            diff_illum: val(17, 999900.0),
            dew_point: dew,
            line,
        });
    }
    Ok(Tape {
        location: Location {
            place: f[1].to_string(),
            latitude,
            longitude,
            timezone: tz,
            elevation: elev,
        },
        wea: None,
        records,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wea_header_and_records() {
        let text = "place A_B\nlatitude 37.42\nlongitude 122.05\ntime_zone 120\nsite_elevation 12.0\nweather_data_file_units 1\n3 21 5.5 0 0\n3 21 6.5 10 42\n";
        let t = read_tape(&mut text.as_bytes()).unwrap();
        assert_eq!(t.records.len(), 2);
        assert_eq!(t.location.timezone, -8.0);
        assert_eq!(t.records[1].diff_irrad, Some(42.0));
    }

    #[test]
    fn bad_line_names_line() {
        let text = "place A_B\nlatitude 37.42\nlongitude 122.05\ntime_zone 120\nsite_elevation 12.0\nweather_data_file_units 1\n3 21 5.5 0 0\n3 21 x 10 42\n";
        let e = read_tape(&mut text.as_bytes()).unwrap_err().to_string();
        assert!(e.contains("line 8"), "{e}");
    }

    #[test]
    fn atof_prefix() {
        assert_eq!(atof("12.5abc"), 12.5);
        assert_eq!(atof("-3e2,"), -300.0);
        assert_eq!(atof("x"), 0.0);
    }
}
