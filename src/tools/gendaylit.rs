//! gendaylit: Perez all-weather sky description for one moment (perezlum.cal).

use anyhow::Result;
use fenestra_sky::daylit::{self, DaylitError, DaylitInput, DaylitOutput};
use fenestra_sky::daymtx::fmt_e;
use fenestra_sky::solar::{self, Site};
use fenestra_sky::weather::atof;
use std::f64::consts::PI;
use std::io::Write;
use std::process::ExitCode;

fn usage_text() -> String {
    let p = fenestra_cli::prog();
    format!(
        "Usage: {p}      month day hour [-y year]\t[...]\n   or: {p} -ang altitude azimuth\t\t[...]\n\
         \t\tfollowed by:\t  -P          epsilon delta [options]\n\
         \t\t\t or:\t  [-W|-L|-G]  direct_value diffuse_value [options]\n\
         \t\t\t or:\t  -E          global_irradiance [options]\n\
         \n    Output: -O [0|1|2] (0 = W/sr/m2 visible, 1 = W/sr/m2 solar, 2 = cd/m2), default 0"
    )
}

fn usage(msg: &str) -> anyhow::Error {
    let p = fenestra_cli::prog();
    eprintln!("{p}: Use error - {msg}\n");
    eprintln!("{}", usage_text());
    fenestra_cli::Exit(1).into()
}

fn val(args: &[String], i: usize) -> Result<f64> {
    args.get(i).map(|w| atof(w)).ok_or_else(|| {
        usage(&format!(
            "missing value after {}",
            args[i.min(args.len()) - 1]
        ))
    })
}

/// Runs gendaylit.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let mut site = Site::default();
    if args.len() == 2 && args[1] == "-defaults" {
        print!(
            "-g {:.6}\t\t\t# Ground plane reflectance\n-t {:.6}\t\t\t# Atmospheric betaturbidity\n-a {:.6}\t\t\t# Site latitude (degrees)\n-o {:.6}\t\t\t# Site longitude (degrees)\n-m {:.6}\t\t\t# Standard meridian (degrees)\n",
            0.2,
            0.1,
            site.latitude * (180.0 / PI),
            site.longitude * (180.0 / PI),
            site.meridian * (180.0 / PI)
        );
        return Ok(ExitCode::SUCCESS);
    }
    if args.len() == 2 && args[1] == "--help" {
        println!(
            "gendaylit: Perez all-weather sky description for one moment\n{}",
            usage_text()
        );
        return Ok(ExitCode::SUCCESS);
    }
    if args.len() < 4 {
        return Err(usage("arg count"));
    }
    let (mut month, mut day, mut hour, mut solar_time) = (0, 0, 0.0, false);
    let mut angles = (0.0, 0.0);
    if args[1] == "-ang" {
        angles = (atof(&args[2]) * (PI / 180.0), atof(&args[3]) * (PI / 180.0));
    } else {
        month = atof(&args[1]) as i32;
        if !(1..=12).contains(&month) {
            return Err(usage("bad month"));
        }
        day = atof(&args[2]) as i32;
        if !(1..=31).contains(&day) {
            return Err(usage("bad day"));
        }
        let w = &args[3];
        // Radiance's gendaylit reads the hour with atof: "14:30" is 14.
        hour = atof(w);
        if !(0.0..24.0).contains(&hour) {
            return Err(usage("bad hour"));
        }
        solar_time = w.starts_with('+');
    }
    let mut input: Option<DaylitInput> = None;
    let mut global: Option<f64> = None;
    let mut output = DaylitOutput::Visible;
    let mut with_sun = true;
    let mut refl = 0.2;
    let mut year: Option<i32> = None;
    let mut i = 4;
    while i < args.len() {
        let a = args[i].as_bytes();
        if a.is_empty() || (a[0] != b'-' && a[0] != b'+') {
            return Err(usage("bad option"));
        }
        match a.get(1).copied().unwrap_or(0) {
            b's' => with_sun = a[0] == b'+',
            b'g' => {
                i += 1;
                refl = val(&args, i)?;
            }
            b'a' => {
                i += 1;
                site.latitude = val(&args, i)? * (PI / 180.0);
            }
            b'o' => {
                i += 1;
                site.longitude = val(&args, i)? * (PI / 180.0);
            }
            b'm' => {
                i += 1;
                site.meridian = val(&args, i)? * (PI / 180.0);
            }
            b'y' => {
                i += 1;
                year = Some(val(&args, i)? as i32);
            }
            b'O' => {
                i += 1;
                output = match val(&args, i)? as i64 {
                    0 => DaylitOutput::Visible,
                    1 => DaylitOutput::Solar,
                    2 => DaylitOutput::Luminance,
                    _ => anyhow::bail!("output argument : wrong number"),
                };
            }
            c @ (b'P' | b'W' | b'L' | b'G') => {
                let (x, y) = (val(&args, i + 1)?, val(&args, i + 2)?);
                i += 2;
                input = Some(match c {
                    b'P' => DaylitInput::Perez(x, y),
                    b'W' => DaylitInput::Irradiance(x, y),
                    b'L' => DaylitInput::Illuminance(x, y),
                    _ => DaylitInput::HorizontalIrradiance(x, y),
                });
            }
            b'E' => {
                i += 1;
                global = Some(val(&args, i)?);
            }
            _ => return Err(usage(&format!("unknown option: {}", args[i]))),
        }
        i += 1;
    }
    if (site.meridian - site.longitude).abs() > 30.0 * PI / 180.0 {
        eprintln!(
            "{}: warning: {:.1} hours btwn. standard meridian and longitude",
            fenestra_cli::prog(),
            (site.longitude - site.meridian) * 12.0 / PI
        );
    }
    let mut out = String::from("#");
    for (k, a) in args.iter().enumerate() {
        out.push(' ');
        out.push_str(if k == 0 { fenestra_cli::prog() } else { a });
    }
    out.push('\n');
    let (mut alt, azi, daynumber, solar_hours) = if month != 0 {
        let p = match year {
            Some(y) => site.position_michalsky(y, month, day, hour, solar_time),
            None => site.position(month, day, hour, solar_time),
        };
        (
            p.altitude,
            p.azimuth,
            f64::from(solar::julian_day(month, day)),
            p.solar_time,
        )
    } else {
        (angles.0, angles.1, 0.0, 0.0)
    };
    if alt > 87.0 * PI / 180.0 {
        eprintln!(
            "{}: warning - sun too close to zenith, reducing altitude to 87 degrees",
            fenestra_cli::prog()
        );
        alt = 87.0 * PI / 180.0;
    }
    if let (Some(g), true) = (global, alt >= 0.0) {
        // Erbs et al. diffuse fraction from the clearness index kt
        let da = 2.0 * PI * (daynumber - 1.0) / 365.0;
        let e0 = 1.00011
            + 0.034221 * da.cos()
            + 0.00128 * da.sin()
            + 0.000719 * (2.0 * da).cos()
            + 0.000077 * (2.0 * da).sin();
        let s0 = 1367.0 * e0 * alt.sin();
        let mut kt = g / s0;
        let mut g = g;
        if kt > 0.999 {
            kt = 0.999;
            g = s0 * kt;
        }
        let frac = if kt <= 0.22 {
            1.0 - 0.09 * kt
        } else if kt <= 0.8 {
            0.9511 - 0.1604 * kt + 4.388 * kt * kt - 16.638 * kt * kt * kt
                + 12.336 * kt * kt * kt * kt
        } else {
            0.165
        };
        let dif = g * frac;
        let dirh = g - dif;
        out.push_str(&format!(
            "# erbs_s0, erbs_kt, irr_dir_h, irr_diff: {s0:.3} {kt:.3} {dirh:.3} {dif:.3}\n# WARNING: the -E option is only recommended for a rough estimation!\n"
        ));
        input = Some(DaylitInput::HorizontalIrradiance(dirh, dif));
    }
    {
        let st = solar_hours;
        out.push_str(&format!("# Local solar time: {st:.2}\n"));
        out.push_str(&format!(
            "# Solar altitude and azimuth: {:.1} {:.1}\n",
            180.0 / PI * alt,
            180.0 / PI * azi
        ));
    }

    let error_sky = |out: &mut String, alt: f64| {
        let d = [-azi.sin() * alt.cos(), -azi.cos() * alt.cos(), alt.sin()];
        out.push_str(&format!(
            "\nvoid brightfunc skyfunc\n2 skybright perezlum.cal\n0\n10 0.00 0.00  0.000 0.000 0.000 0.000 0.000  {:.6} {:.6} {:.6} \n",
            d[0], d[1], d[2]
        ));
    };
    if input.is_none() && alt >= 0.0 {
        return Err(usage("error at the input arguments"));
    }
    let zero = match input {
        Some(
            DaylitInput::Irradiance(a, b)
            | DaylitInput::HorizontalIrradiance(a, b)
            | DaylitInput::Illuminance(a, b),
        ) => a == 0.0 && b == 0.0,
        Some(DaylitInput::Perez(..)) => false,
        None => false,
    };
    if alt < 0.0 {
        eprintln!(
            "Warning: sun altitude below zero at time step {month} {day} {hour:.2}, printing error sky"
        );
        error_sky(&mut out, alt);
        std::io::stdout().lock().write_all(out.as_bytes())?;
        return Ok(ExitCode::SUCCESS);
    }
    if zero {
        eprintln!(
            "Warning: zero {} at sun altitude > 0, printing error sky",
            if matches!(input, Some(DaylitInput::Illuminance(..))) {
                "illuminance"
            } else {
                "irradiance"
            }
        );
        error_sky(&mut out, alt);
        std::io::stdout().lock().write_all(out.as_bytes())?;
        return Ok(ExitCode::SUCCESS);
    }
    let Some(input) = input else {
        return Err(usage("error at the input arguments"));
    };
    let sky = match daylit::compute(alt, azi, daynumber, input, output, with_sun, refl) {
        Ok(s) => s,
        Err(DaylitError::Fatal(m)) => {
            std::io::stdout().lock().write_all(out.as_bytes())?;
            anyhow::bail!("{m}");
        }
        Err(DaylitError::ErrorSky(m)) => {
            eprintln!("Warning: {m}");
            let _ = &m;
            error_sky(&mut out, alt);
            std::io::stdout().lock().write_all(out.as_bytes())?;
            return Ok(ExitCode::SUCCESS);
        }
    };
    out.push_str(&format!(
        "# epsilon, delta, atmospheric precipitable water content : {:.4} {:.4} {:.4} \n",
        sky.epsilon,
        sky.delta,
        daylit::PRECIPITABLE_WATER
    ));
    let d = sky.sun_dir;
    if with_sun && sky.epsilon > 1.0 {
        let e = fmt_e(sky.solar_radiance, 3);
        out.push_str(&format!(
            "\nvoid light solar\n0\n0\n3 {e} {e} {e}\n\nsolar source sun\n0\n0\n4 {:.6} {:.6} {:.6} {:.6}\n",
            d[0], d[1], d[2], 0.533
        ));
    } else if with_sun {
        out.push_str(&format!(
            "\nvoid light solar\n0\n0\n3 0.0 0.0 0.0\n\nsolar source sun\n0\n0\n4 {:.6} {:.6} {:.6} {:.6}\n",
            d[0], d[1], d[2], 0.533
        ));
    }
    let c = sky.coeffs;
    out.push_str(&format!(
        "\nvoid brightfunc skyfunc\n2 skybright perezlum.cal\n0\n10 {} {} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} \n",
        fmt_e(sky.diffuse_norm, 3),
        fmt_e(sky.ground, 3),
        c[0], c[1], c[2], c[3], c[4], d[0], d[1], d[2]
    ));
    std::io::stdout().lock().write_all(out.as_bytes())?;
    Ok(ExitCode::SUCCESS)
}
