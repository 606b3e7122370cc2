//! hdr2png (fenestra): a Radiance picture as a PNG anyone can open — tone-mapped (automatic
//! exposure from the log-average luminance, adjustable in stops, gamma), or in false colour
//! with the luminance scale printed on standard error.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};

const USAGE: &str =
    "[-e stops | -m mult] [-g gamma] [-f max|auto [-i]] [-o out.png] [picture.hdr | -]";

/// Radiance's luminous efficacy of its RGB white (lm/W).
const EFFICACY: f64 = 179.0;

fn bright(p: [f32; 3]) -> f64 {
    0.265_074_126 * f64::from(p[0])
        + 0.670_114_631 * f64::from(p[1])
        + 0.064_811_243 * f64::from(p[2])
}

/// Blue → cyan → green → yellow → red for t in [0, 1].
fn ramp(t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, 1.0) * 4.0;
    let k = (t.floor() as usize).min(3);
    let f = t - k as f64;
    let stops = [
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
    ];
    let (a, b) = (stops[k], stops[k + 1]);
    [
        a[0] + f * (b[0] - a[0]),
        a[1] + f * (b[1] - a[1]),
        a[2] + f * (b[2] - a[2]),
    ]
}

/// Runs hdr2png.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    if args.iter().skip(1).any(|a| a == "--help") {
        println!(
            "{} {USAGE}\nWrites a Radiance picture as an 8-bit PNG (standard output unless -o).\nOptions:\n  -e stops     exposure change from the automatic one (log-average luminance to 18% grey)\n  -m mult      a fixed multiplier instead of the automatic exposure\n  -g gamma     display gamma (default 2.2)\n  -f max|auto  false colour: luminance 0..max cd/m2 (179 x Radiance's brightness; lux for an irradiance picture) blue to red, with a legend; auto: the 99th percentile\n  -i           with -f: the picture holds irradiance (the legend says lux)\n  -o file      output file\nFull documentation: fenestra doc hdr2png (docs/tools/hdr2png.md in the source).",
            fenestra_cli::prog()
        );
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
    let (w, h) = (pic.res.xr, pic.res.yr);
    if w == 0 || h == 0 {
        bail!("{name}: empty picture");
    }
    let mut rgb = vec![[0u8; 3]; w * h];
    let mut legend = None;
    let lum: Vec<f64> = pic.pixels.iter().map(|p| bright(*p)).collect();
    let place = |k: usize| -> usize {
        let (px, sc) = (k % pic.res.scanlen(), k / pic.res.scanlen());
        let (x, y) = pic.res.pix2xy(px, sc);
        (h - 1 - y) * w + x
    };
    match falsecolor {
        Some(max) => {
            let max = match max {
                Some(m) => m,
                None => {
                    let mut v: Vec<f64> = lum.iter().map(|l| l * EFFICACY).collect();
                    v.sort_by(f64::total_cmp);
                    v[(v.len() * 99 / 100).min(v.len() - 1)].max(1e-9)
                }
            };
            for (k, l) in lum.iter().enumerate() {
                let c = ramp(l * EFFICACY / max);
                rgb[place(k)] = c.map(|x| (x * 255.0 + 0.5) as u8);
            }
            let unit = if irradiance { "lux" } else { "cd/m2" };
            eprintln!(
                "{}: false colour 0 (blue) .. {max:.4} (red) {unit} (x179 of Radiance's brightness), legend ticks every {:.4}",
                fenestra_cli::prog(),
                max / 4.0
            );
            legend = Some((max, unit));
        }
        None => {
            let m = match mult {
                Some(m) => m,
                None => {
                    let (sum, n) = lum
                        .iter()
                        .filter(|l| **l > 0.0)
                        .fold((0.0, 0usize), |(s, n), l| (s + l.ln(), n + 1));
                    let avg = if n > 0 { (sum / n as f64).exp() } else { 1.0 };
                    0.18 / avg
                }
            } * 2f64.powf(stops);
            for (k, p) in pic.pixels.iter().enumerate() {
                let c = p.map(|v| {
                    let x = (f64::from(v) * m).clamp(0.0, 1.0).powf(1.0 / gamma);
                    (x * 255.0 + 0.5) as u8
                });
                rgb[place(k)] = c;
            }
            eprintln!(
                "{}: exposure multiplier {m:.6e} (white = {:.4} cd/m2)",
                fenestra_cli::prog(),
                EFFICACY / m
            );
        }
    }
    let (w, h, rgb) = match legend {
        Some((max, unit)) => {
            let img = fenestra_chart::raster::Raster {
                width: w,
                height: h,
                pixels: rgb,
            };
            let ramp8 = |t: f64| ramp(t).map(|x| (x * 255.0 + 0.5) as u8);
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
