//! gensky: CIE sky descriptions (clear, intermediate, overcast, uniform) for a
//! date and time or a given solar position, as Radiance's gensky writes them.

use anyhow::{bail, Result};
use fenestra_sky::cie::{self, CieInputs, Given, SkyType};
use fenestra_sky::solar::Site;
use fenestra_sky::weather::atof;
use std::f64::consts::PI;
use std::io::Write;
use std::process::ExitCode;

/// Time zones gensky knows, with their standard meridians (degrees west).
const ZONES: &[(&str, f64)] = &[
    ("YST", 135.0),
    ("YDT", 120.0),
    ("PST", 120.0),
    ("PDT", 105.0),
    ("MST", 105.0),
    ("MDT", 90.0),
    ("CST", 90.0),
    ("CDT", 75.0),
    ("EST", 75.0),
    ("EDT", 60.0),
    ("AST", 60.0),
    ("ADT", 45.0),
    ("NST", 52.5),
    ("NDT", 37.5),
    ("GMT", 0.0),
    ("BST", -15.0),
    ("CET", -15.0),
    ("CEST", -30.0),
    ("EET", -30.0),
    ("EEST", -45.0),
    ("AST", -45.0),
    ("ADT", -60.0),
    ("GST", -60.0),
    ("GDT", -75.0),
    ("IST", -82.5),
    ("IDT", -97.5),
    ("JST", -135.0),
    ("NDT", -150.0),
    ("NZST", -180.0),
    ("NZDT", -195.0),
];

fn usage(msg: &str) -> anyhow::Error {
    let p = fenestra_cli::prog();
    eprintln!("{p}: Use error - {msg}");
    eprintln!("Usage: {p} month day hour [options]");
    eprintln!("   Or: {p} -ang altitude azimuth [options]");
    eprintln!("   Or: {p} -defaults");
    fenestra_cli::Exit(1).into()
}

fn atoi(s: &str) -> i64 {
    atof(s.split('.').next().unwrap_or("")) as i64
}

/// Parsed time: hour, solar-time flag and a meridian (radians west) from a zone suffix.
fn parse_time(hs: &str) -> Result<(f64, bool, Option<f64>)> {
    let b = hs.as_bytes();
    let solar = b.first() == Some(&b'+');
    let mut cp = usize::from(solar);
    while cp < b.len() && b[cp].is_ascii_digit() {
        cp += 1;
    }
    let hour;
    if cp < b.len() && b[cp] == b':' {
        cp += 1;
        hour = atoi(hs) as f64 + atoi(&hs[cp..]) as f64 / 60.0;
    } else {
        hour = atof(hs);
        if cp < b.len() && b[cp] == b'.' {
            cp += 1;
        }
    }
    while cp < b.len() && b[cp].is_ascii_digit() {
        cp += 1;
    }
    if cp >= b.len() {
        return Ok((hour, solar, None));
    }
    if solar || !b[cp].is_ascii_alphabetic() {
        bail!("bad time format: {hs}");
    }
    let zone = hs[cp..].to_ascii_uppercase();
    match ZONES.iter().find(|(z, _)| *z == zone) {
        Some((_, m)) => Ok((hour, solar, Some(m * (PI / 180.0)))),
        None => {
            let names: Vec<&str> = ZONES.iter().map(|z| z.0).collect();
            bail!(
                "unknown time zone: {}\nKnown time zones:\n\t{}",
                &hs[cp..],
                names.join(" ")
            )
        }
    }
}

fn value(args: &[String], i: usize) -> Result<f64> {
    match args.get(i) {
        Some(w) => Ok(atof(w)),
        None => Err(usage(&format!("missing value after {}", args[i - 1]))),
    }
}

/// A value given with an upper-case option letter (`-B`, `-R`) is a horizontal irradiance,
/// with a lower-case one (`-b`, `-r`) a radiance.
fn given(letter: u8, v: f64) -> Given {
    if letter.is_ascii_uppercase() {
        Given::Irradiance(v)
    } else {
        Given::Radiance(v)
    }
}

/// `gensky --help`: the synopsis and one line per option.
const GENSKY_HELP: &str = "Usage: gensky month day hour [options]      (hour: local standard time, e.g. 14:30 or 14.5; +H or a zone suffix as Radiance)
   Or: gensky -ang altitude azimuth [options]   (sun position in degrees, azimuth from south, west positive)
   Or: gensky -defaults
Writes a CIE sky (a sun 'source' plus a skybright.cal brightfunc) for oconv/rtrace/genskyvec.
Options:
  +s | -s      CIE clear sky with | without sun (default +s)
  +i | -i      CIE intermediate sky with | without sun
  -c           CIE overcast sky
  -u           uniform sky
  -g rfl       ground reflectance (default 0.2)
  -b L | -B E  zenith radiance (W/sr/m2) | from horizontal diffuse irradiance (W/m2)
  -r L | -R E  solar radiance | from horizontal direct irradiance (W/m2); -r 0 removes the sun
  -t turb      turbidity (default 2.45)
  -a lat       site latitude, degrees north
  -o lon       site longitude, degrees west
  -m mer       standard meridian, degrees west (default 120)
  -y year      solar position for that year (Michalsky)
Full documentation: fenestra doc gensky (docs/tools/gensky.md in the source).";

/// Runs gensky.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let mut inp = CieInputs::default();
    let mut site = Site::default();
    if args.len() == 2 && args[1] == "--help" {
        println!("{}", GENSKY_HELP);
        return Ok(ExitCode::SUCCESS);
    }
    if args.len() == 2 && args[1] == "-defaults" {
        print!("{}", defaults(&inp, &site));
        return Ok(ExitCode::SUCCESS);
    }
    if args.len() < 4 {
        return Err(usage("arg count"));
    }
    let mut month = 0;
    let mut day = 0;
    let mut hour = 0.0;
    let mut solar_time = false;
    let mut given_angles = (0.0, 0.0);
    let mut got_meridian = false;
    if args[1] == "-ang" {
        given_angles = (atof(&args[2]) * (PI / 180.0), atof(&args[3]) * (PI / 180.0));
    } else {
        month = atoi(&args[1]) as i32;
        if !(1..=12).contains(&month) {
            return Err(usage("bad month"));
        }
        day = atoi(&args[2]) as i32;
        if !(1..=31).contains(&day) {
            return Err(usage("bad day"));
        }
        let (h, s, m) = parse_time(&args[3])?;
        hour = h;
        solar_time = s;
        if let Some(m) = m {
            site.meridian = m;
            got_meridian = true;
        }
    }
    let mut year: Option<i32> = None;
    let mut i = 4;
    while i < args.len() {
        let a = args[i].as_bytes();
        if a.is_empty() || (a[0] != b'-' && a[0] != b'+') {
            return Err(usage("bad option"));
        }
        let plus = a[0] == b'+';
        match a.get(1).copied().unwrap_or(0) {
            b's' => {
                inp.sky_type = SkyType::Clear;
                inp.with_sun = plus;
            }
            b'r' | b'R' => {
                i += 1;
                inp.solar = given(a[1], value(&args, i)?);
            }
            b'c' => inp.sky_type = SkyType::Overcast,
            b'u' => inp.sky_type = SkyType::Uniform,
            b'i' => {
                inp.sky_type = SkyType::Intermediate;
                inp.with_sun = plus;
            }
            b't' => {
                i += 1;
                inp.turbidity = value(&args, i)?;
            }
            b'b' | b'B' => {
                i += 1;
                inp.zenith = given(a[1], value(&args, i)?);
            }
            b'g' => {
                i += 1;
                inp.ground_reflectance = value(&args, i)?;
            }
            b'a' => {
                i += 1;
                site.latitude = value(&args, i)? * (PI / 180.0);
            }
            b'o' => {
                i += 1;
                site.longitude = value(&args, i)? * (PI / 180.0);
            }
            b'm' => {
                i += 1;
                let v = value(&args, i)?;
                if !got_meridian {
                    site.meridian = v * (PI / 180.0);
                }
            }
            b'y' => {
                i += 1;
                year = Some(value(&args, i)? as i32);
            }
            _ => return Err(usage(&format!("unknown option: {}", args[i]))),
        }
        i += 1;
    }
    if let Some(y) = year {
        if !(1950..=2050).contains(&y) {
            fenestra_cli::warn("year should be in range 1950-2050");
        }
    }
    if month != 0 && !solar_time && (site.meridian - site.longitude).abs() > 45.0 * PI / 180.0 {
        fenestra_cli::warn(format!(
            "{:.1} hours btwn. standard meridian and longitude",
            (site.longitude - site.meridian) * 12.0 / PI
        ));
    }
    let mut out = String::new();
    out.push('#');
    for (k, a) in args.iter().enumerate() {
        out.push(' ');
        if k == 0 {
            out.push_str(fenestra_cli::prog());
        } else {
            out.push_str(a);
        }
    }
    out.push('\n');
    let (alt, azi) = if month != 0 {
        let p = match year {
            Some(y) => site.position_michalsky(y, month, day, hour, solar_time),
            _ => site.position(month, day, hour, solar_time),
        };
        out.push_str(&format!("# Local solar time: {:.2}\n", p.solar_time));
        out.push_str(&format!(
            "# Solar altitude and azimuth: {:.1} {:.1}\n",
            180.0 / PI * p.altitude,
            180.0 / PI * p.azimuth
        ));
        (p.altitude, p.azimuth)
    } else {
        given_angles
    };
    let sky = cie::compute(&inp, alt, azi);
    if sky.clamped {
        fenestra_cli::warn("sun too close to zenith, reducing altitude to 87 degrees");
        out.push_str("# warning - sun too close to zenith, reducing altitude to 87 degrees\n");
    }
    out.push_str(&format!(
        "# Ground ambient level: {:.1}\n",
        sky.ground_ambient
    ));
    out.push_str(&sky.scene_text());
    std::io::stdout().lock().write_all(out.as_bytes())?;
    Ok(ExitCode::SUCCESS)
}

fn defaults(inp: &CieInputs, site: &Site) -> String {
    let mut s = String::new();
    s.push_str(match (inp.sky_type, inp.with_sun) {
        (SkyType::Overcast, _) => "-c\t\t\t\t# Cloudy sky\n",
        (SkyType::Uniform, _) => "-u\t\t\t\t# Uniform cloudy sky\n",
        (SkyType::Intermediate, true) => "+i\t\t\t\t# Intermediate sky with sun\n",
        (SkyType::Intermediate, false) => "-i\t\t\t\t# Intermediate sky without sun\n",
        (SkyType::Clear, true) => "+s\t\t\t\t# Sunny sky with sun\n",
        (SkyType::Clear, false) => "-s\t\t\t\t# Sunny sky without sun\n",
    });
    s.push_str(&format!(
        "-g {:.6}\t\t\t# Ground plane reflectance\n",
        inp.ground_reflectance
    ));
    s.push_str(&format!(
        "-t {:.6}\t\t\t# Atmospheric turbidity\n",
        inp.turbidity
    ));
    s.push_str(&format!(
        "-a {:.6}\t\t\t# Site latitude (degrees)\n",
        site.latitude * (180.0 / PI)
    ));
    s.push_str(&format!(
        "-o {:.6}\t\t\t# Site longitude (degrees)\n",
        site.longitude * (180.0 / PI)
    ));
    s.push_str(&format!(
        "-m {:.6}\t\t\t# Standard meridian (degrees)\n",
        site.meridian * (180.0 / PI)
    ));
    s
}
