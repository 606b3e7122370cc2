//! hdr2png (fenestra): a Radiance picture as a PNG anyone can open — tone-mapped (automatic
//! exposure from the log-average luminance, adjustable in stops, gamma), or in false colour
//! with the luminance scale printed on standard error.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};

const USAGE: &str =
    "[-e stops | -m mult] [-g gamma] [-f max|auto [-i]] [-o out.png] [picture.hdr | -]";

use fenestra_chart::tone;

/// Runs hdr2png.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    if fenestra_cli::help_asked(&args, USAGE, "Writes a Radiance picture as an 8-bit PNG (standard output unless -o).\nOptions:\n  -e stops     exposure change from the automatic one (log-average luminance to 18% grey)\n  -m mult      a fixed multiplier instead of the automatic exposure\n  -g gamma     display gamma (default 2.2)\n  -f max|auto  false colour: luminance 0..max cd/m2 (179 x Radiance's brightness; lux for an irradiance picture) blue to red, with a legend; auto: the 99th percentile\n  -i           with -f: the picture holds irradiance (the legend says lux)\n  -o file      output file\nFull documentation: fenestra doc hdr2png (docs/tools/hdr2png.md in the source).") {
        return Ok(ExitCode::SUCCESS);
    }
    let (mut stops, mut mult, mut gamma) = (0.0f64, None::<f64>, 2.2f64);
    let mut falsecolor: Option<Option<f64>> = None;
    let (mut input, mut output) = (None::<String>, None::<String>);
    let mut irradiance = false;
    let mut i = 1;
    let num = |i: usize| -> Result<f64> {
        let w = args
            .get(i)
            .with_context(|| format!("option {} needs a value", args[i - 1]))?;
        fenestra_cli::opts::parse_real(w)
            .filter(|v| v.is_finite())
            .with_context(|| format!("option {}: '{w}' is not a number", args[i - 1]))
    };
    while i < args.len() {
        match args[i].as_str() {
            "-e" => {
                stops = num(i + 1)?;
                i += 1;
            }
            "-m" => {
                let m = num(i + 1)?;
                if m <= 0.0 {
                    bail!("-m {m}: the multiplier must be positive");
                }
                mult = Some(m);
                i += 1;
            }
            "-g" => {
                gamma = num(i + 1)?;
                if gamma <= 0.0 {
                    bail!("-g {gamma}: gamma must be positive");
                }
                i += 1;
            }
            "-f" => {
                let w = args
                    .get(i + 1)
                    .context("-f needs a maximum (cd/m2) or auto")?;
                falsecolor = Some(if w == "auto" {
                    None
                } else {
                    let v = num(i + 1)?;
                    if v <= 0.0 {
                        bail!("-f {v}: the maximum must be positive");
                    }
                    Some(v)
                });
                i += 1;
            }
            "-o" => {
                output = Some(args.get(i + 1).context("-o needs a file name")?.clone());
                i += 1;
            }
            "-i" => irradiance = true,
            a if a.starts_with('-') && a != "-" => {
                bail!(
                    "unknown option '{a}'\nusage: {} {USAGE}",
                    fenestra_cli::prog()
                )
            }
            a => {
                if input.is_some() {
                    bail!(
                        "one picture at a time\nusage: {} {USAGE}",
                        fenestra_cli::prog()
                    );
                }
                input = Some(a.to_string());
            }
        }
        i += 1;
    }
    let name = input.unwrap_or_else(|| "-".into());
    let mut r = fenestra_cli::input::open(&name)?;
    let mut pic = fenestra_formats::picture::Picture::read(&mut r, fenestra_cli::prog())
        .map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    pic.undo_exposure();
    let (w, h, px) = pic.to_standard();
    if w == 0 || h == 0 {
        bail!("{name}: empty picture");
    }
    let mut legend = None;
    let rgb = match falsecolor {
        Some(max) => {
            let max = max.unwrap_or_else(|| tone::luminance_p99(&px));
            let unit = if irradiance { "lux" } else { "cd/m2" };
            eprintln!(
                "{}: false colour 0 (blue) .. {max:.4} (red) {unit} (x179 of Radiance's brightness), legend ticks every {:.4}",
                fenestra_cli::prog(),
                max / 4.0
            );
            legend = Some((max, unit));
            tone::false_colour(&px, max)
        }
        None => {
            let m = mult.unwrap_or_else(|| tone::auto_multiplier(&px)) * 2f64.powf(stops);
            eprintln!(
                "{}: exposure multiplier {m:.6e} (white = {:.4} cd/m2)",
                fenestra_cli::prog(),
                tone::EFFICACY / m
            );
            tone::tone_map(&px, m, gamma)
        }
    };
    let (w, h, rgb) = match legend {
        Some((max, unit)) => {
            let img = fenestra_chart::raster::Raster {
                width: w,
                height: h,
                pixels: rgb,
            };
            let ramp8 = |t: f64| tone::to_u8(tone::ramp(t));
            let l = fenestra_chart::raster::with_legend(&img, max, unit, &ramp8);
            (l.width, l.height, l.pixels)
        }
        None => (w, h, rgb),
    };
    let png = fenestra_formats::png::encode_rgb8(w, h, &rgb);
    match output {
        Some(o) => {
            let mut f = fenestra_cli::output::AtomicFile::create(&o)?;
            f.write_all(&png)?;
            f.commit()?;
        }
        None => {
            let mut out = std::io::stdout().lock();
            out.write_all(&png)?;
            out.flush()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
