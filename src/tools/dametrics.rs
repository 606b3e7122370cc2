//! dametrics (fenestra): annual daylight metrics per sensor from an illuminance matrix
//! (sensors × hours, as dctimestep and rmtxop write it) — DA, UDI, mean lux over occupied
//! hours, sDA — and, given the results' standard errors (dctimestep -Eo), how far each
//! metric can move within them.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_cli::opts::{Kind, Opt, Spec};
use fenestra_dc::metrics::{self, SensorMetrics, Thresholds};
use fenestra_dc::metrics_input;

fn spec() -> Spec {
    Spec::new(
        "dametrics",
        "Annual daylight metrics per sensor (DA, UDI, mean lux, sDA) from an illuminance matrix, with how far each can move within the results' standard errors",
    )
    .usage("[-w weather.wea [-o start end]] [-t lux] [-u low high] [-s share] [-E err ..] [-z z] [-p sensors.pts [-m map.svg]] ill.dat")
    .opts([
        Opt::new(
            "w",
            Kind::Word,
            "weather tape (.wea/.epw) whose hours are the matrix's columns; occupied hours from it (default: every column occupied)",
        ),
        Opt::new(
            "o",
            Kind::Words(2),
            "occupied hours of the day, local standard time: start ≤ hour < end (default 8 18; needs -w)",
        ),
        Opt::new(
            "t",
            Kind::Real,
            "daylight-autonomy threshold, lux (default 300)",
        ),
        Opt::new(
            "u",
            Kind::Words(2),
            "useful-daylight range, lux (default 100 2000)",
        ),
        Opt::new(
            "s",
            Kind::Real,
            "share of occupied hours a sensor needs for spatial daylight autonomy (default 0.5)",
        ),
        Opt::new(
            "E",
            Kind::Word,
            "standard errors of the matrix (dctimestep -Eo); repeat for summed parts (window groups): added in quadrature",
        ),
        Opt::new(
            "z",
            Kind::Real,
            "half-width of the band in standard errors (default 2)",
        ),
        Opt::new(
            "p",
            Kind::Word,
            "sensor points (x y z dx dy dz per line), for the table's x y columns",
        ),
        Opt::new(
            "m",
            Kind::Word,
            "write a floor-plan map (SVG) of DA and UDI per sensor here (needs -p)",
        ),
    ])
}

/// Occupied flags per column from a weather tape's records.
fn occupancy(wea: &str, start: f64, end: f64, ncols: usize) -> Result<Vec<bool>> {
    let f =
        std::fs::File::open(wea).with_context(|| format!("cannot open weather tape '{wea}'"))?;
    let tape = fenestra_sky::weather::read_tape(&mut std::io::BufReader::new(f))
        .map_err(|e| anyhow::anyhow!("{wea}: {e}"))?;
    if tape.records.len() != ncols {
        bail!(
            "{wea} has {} hours but the matrix has {ncols} columns: the columns must be the tape's hours",
            tape.records.len()
        );
    }
    Ok(tape
        .records
        .iter()
        .map(|r| {
            let h = f64::from(r.hour);
            h >= start && h < end
        })
        .collect())
}

fn reals2(words: &[String], what: &str) -> Result<(f64, f64)> {
    let v: Vec<f64> = words
        .iter()
        .map(|w| fenestra_cli::opts::parse_real(w).filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .with_context(|| format!("{what}: two numbers expected, not '{}'", words.join(" ")))?;
    if v[0] >= v[1] {
        bail!(
            "{what}: {} {}: the first must be below the second",
            v[0],
            v[1]
        );
    }
    Ok((v[0], v[1]))
}

/// Runs dametrics.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let mut th = Thresholds::default();
    let (mut wea, mut hours, mut share) = (None::<String>, None::<(f64, f64)>, 0.5f64);
    let (mut errs, mut pts, mut map) = (Vec::<String>::new(), None::<String>, None::<String>);
    let (hits, pos) = spec().parse_apart(&args)?;
    for h in &hits {
        match h.key {
            "w" => wea = Some(h.word().to_string()),
            "o" => hours = Some(reals2(h.words(), "-o")?),
            "t" => th.da = h.real(),
            "u" => (th.udi_low, th.udi_high) = reals2(h.words(), "-u")?,
            "s" => share = h.real(),
            "E" => errs.push(h.word().to_string()),
            "z" => th.z = h.real(),
            "p" => pts = Some(h.word().to_string()),
            "m" => map = Some(h.word().to_string()),
            _ => unreachable!("declared options only"),
        }
    }
    if !(th.z > 0.0 && th.z.is_finite()) {
        bail!(
            "-z {}: the band's half-width must be a positive number of standard errors",
            th.z
        );
    }
    if !(0.0..=1.0).contains(&share) {
        bail!("-s {share}: a share of hours from 0 to 1 expected");
    }
    let [name] = pos.as_slice() else {
        bail!(
            "one illuminance matrix expected, {} given (see --help)",
            pos.len()
        );
    };
    let (rows, cols, lux) = metrics_input::lux_rows(name)?;
    // standard errors of summed parts add in quadrature (independent runs)
    let sd = if errs.is_empty() {
        None
    } else {
        let mut var = vec![0.0; rows * cols];
        for e in &errs {
            let (r, c, s) = metrics_input::lux_rows(e)?;
            if (r, c) != (rows, cols) {
                bail!("{e}: {r}×{c} standard errors for a {rows}×{cols} matrix ({name})");
            }
            for (v, x) in var.iter_mut().zip(&s) {
                *v += x * x;
            }
        }
        Some(var.into_iter().map(f64::sqrt).collect::<Vec<f64>>())
    };
    let occupied = match (&wea, hours) {
        (Some(w), h) => {
            let (a, b) = h.unwrap_or((8.0, 18.0));
            occupancy(w, a, b, cols)?
        }
        (None, Some(_)) => bail!("-o needs -w: the weather tape gives each column's hour"),
        (None, None) => vec![true; cols],
    };
    let xy = pts.as_deref().map(metrics_input::sensor_xy).transpose()?;
    if let Some(xy) = &xy {
        if xy.len() != rows {
            bail!(
                "{}: {} points for {rows} sensors",
                pts.unwrap_or_default(),
                xy.len()
            );
        }
    }
    let sensors: Vec<SensorMetrics> = (0..rows)
        .map(|k| {
            let r = k * cols..(k + 1) * cols;
            metrics::sensor(&lux[r.clone()], sd.as_ref().map(|s| &s[r]), &occupied, &th)
        })
        .collect();
    if let Some(m) = &map {
        let Some(xy) = &xy else {
            bail!("-m needs -p: the map places each sensor at its x y");
        };
        write_map(m, xy, &sensors, &th)?;
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    write_table(&mut out, &sensors, xy.as_deref(), &th)?;
    let room = metrics::room(&sensors, share, sd.is_some());
    let (sda, band, mean_da) = (room.sda, room.sda_band, room.mean_da);
    let occ = sensors.first().map_or(0, |s| s.hours);
    let pct = |x: f64| 100.0 * x;
    write!(
        out,
        "room: sDA{}/{:.0}% {:.1} %",
        th.da,
        pct(share),
        pct(sda)
    )?;
    if let Some((lo, hi)) = band {
        write!(out, " (within ±{}σ: {:.1}–{:.1})", th.z, pct(lo), pct(hi))?;
    }
    write!(out, ", mean DA{} {:.1} %", th.da, pct(mean_da))?;
    if let Some((lo, hi, flip)) = room.da_band {
        write!(
            out,
            " ({:.1}–{:.1}; {:.1} % of hours could flip)",
            pct(lo),
            pct(hi),
            pct(flip)
        )?;
    }
    writeln!(out, " over {} sensors, {occ} occupied hours", sensors.len())?;
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

/// The floor-plan map of DA and UDI per sensor (SVG, written whole then moved into place).
fn write_map(
    name: &str,
    xy: &[(f64, f64)],
    sensors: &[SensorMetrics],
    th: &Thresholds,
) -> Result<()> {
    use fenestra_chart::plan::{Panel, Plan};
    let pct = |f: &dyn Fn(&SensorMetrics) -> f64| sensors.iter().map(|s| 100.0 * f(s)).collect();
    let plan = Plan {
        title: format!(
            "Annual daylight metrics per sensor ({} occupied hours)",
            sensors.first().map_or(0, |s| s.hours)
        ),
        points: xy.to_vec(),
        panels: vec![
            Panel {
                title: format!("DA{} (%)", th.da),
                values: pct(&|s| s.da),
            },
            Panel {
                title: format!("UDI {}-{} lux (%)", th.udi_low, th.udi_high),
                values: pct(&|s| s.udi),
            },
        ],
        range: (0.0, 100.0),
        scale_label: "% of occupied hours".into(),
    };
    let svg = fenestra_chart::plan::to_svg(&plan)?;
    let mut f = fenestra_cli::output::AtomicFile::create(name)?;
    f.write_all(svg.as_bytes())?;
    f.commit()?;
    Ok(())
}

fn write_table(
    out: &mut impl Write,
    sensors: &[SensorMetrics],
    xy: Option<&[(f64, f64)]>,
    th: &Thresholds,
) -> Result<()> {
    let errors = sensors.iter().any(|s| s.band.is_some());
    write!(out, "{:<7}", "sensor")?;
    if xy.is_some() {
        write!(out, " {:>7} {:>7}", "x", "y")?;
    }
    let (da, udi) = (
        format!("DA{} %", th.da),
        format!("UDI{}-{} %", th.udi_low, th.udi_high),
    );
    write!(out, " {da:>10} {udi:>14} {:>10}", "mean lux")?;
    if errors {
        write!(
            out,
            " {:>13} {:>7} {:>13} {:>7} {:>9}",
            format!("DA ±{}σ", th.z),
            "flip %",
            format!("UDI ±{}σ", th.z),
            "flip %",
            "lux se≤"
        )?;
    }
    writeln!(out)?;
    for (k, s) in sensors.iter().enumerate() {
        write!(out, "{:<7}", k + 1)?;
        if let Some(xy) = xy {
            write!(out, " {:>7.2} {:>7.2}", xy[k].0, xy[k].1)?;
        }
        write!(
            out,
            " {:>10.1} {:>14.1} {:>10.1}",
            100.0 * s.da,
            100.0 * s.udi,
            s.mean
        )?;
        if let Some(b) = s.band {
            write!(
                out,
                " {:>13} {:>7.1} {:>13} {:>7.1} {:>9.1}",
                format!("{:.1}–{:.1}", 100.0 * b.da.0, 100.0 * b.da.1),
                100.0 * b.da_flip,
                format!("{:.1}–{:.1}", 100.0 * b.udi.0, 100.0 * b.udi.1),
                100.0 * b.udi_flip,
                b.mean_se
            )?;
        }
        writeln!(out)?;
    }
    Ok(())
}
