//! errplot (fenestra): a log–log chart of error against run time as SVG, from a table of
//! `series x y` lines (benches/accuracy.sh draws docs/accuracy's charts with it).

use std::io::{BufRead, Write};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use fenestra_chart::{Chart, Level, Series};
use fenestra_cli::opts::{Kind, Opt, Spec};

fn spec() -> Spec {
    Spec::new(
        "errplot",
        "Draw a log-log chart (error against run time) as SVG from lines 'series<TAB>x<TAB>y'",
    )
    .usage(
        "[-t title] [-x label] [-y label] [-g series ..] [-H y label ..] [-o out.svg] [table | -]",
    )
    .opts([
        Opt::new("t", Kind::Word, "title"),
        Opt::new("x", Kind::Word, "x-axis label, with its unit"),
        Opt::new("y", Kind::Word, "y-axis label, with its unit"),
        Opt::new(
            "g",
            Kind::Word,
            "draw a 1/sqrt(x) guide through this series' first point (repeatable)",
        ),
        Opt::new(
            "H",
            Kind::Words(2),
            "a horizontal line at y with a legend text (repeatable)",
        ),
        Opt::new("o", Kind::Word, "output file (default: standard output)"),
    ])
}

/// Reads `series<TAB>x<TAB>y` lines (`#` comments and blank lines skipped), series in the
/// order they first appear.
fn read_table(rd: &mut dyn BufRead, name: &str) -> Result<Vec<Series>> {
    let mut series: Vec<Series> = Vec::new();
    for (k, line) in rd.lines().enumerate() {
        let line = line.with_context(|| format!("{name}: cannot read line {}", k + 1))?;
        let t = line.trim_end();
        if t.trim().is_empty() || t.trim_start().starts_with('#') {
            continue;
        }
        let f: Vec<&str> = t.split('\t').collect();
        let num = |s: &str| fenestra_cli::opts::parse_real(s.trim()).filter(|v| v.is_finite());
        let (Some(x), Some(y)) = (f.get(1).and_then(|s| num(s)), f.get(2).and_then(|s| num(s)))
        else {
            bail!(
                "{name}, line {}: 'series<TAB>x<TAB>y' with two numbers expected: {t}",
                k + 1
            );
        };
        if f.len() != 3 {
            bail!(
                "{name}, line {}: three tab-separated fields expected, {} found",
                k + 1,
                f.len()
            );
        }
        match series.iter_mut().find(|s| s.name == f[0]) {
            Some(s) => s.points.push((x, y)),
            None => series.push(Series {
                name: f[0].to_string(),
                points: vec![(x, y)],
                sqrt_guide: false,
            }),
        }
    }
    if series.is_empty() {
        bail!("{name}: no data lines");
    }
    Ok(series)
}

/// Runs errplot.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let mut chart = Chart::default();
    let (mut guides, mut out) = (Vec::<String>::new(), None::<String>);
    let (hits, pos) = spec().parse_apart(&args)?;
    for h in &hits {
        match h.key {
            "t" => chart.title = h.word().to_string(),
            "x" => chart.x_label = h.word().to_string(),
            "y" => chart.y_label = h.word().to_string(),
            "g" => guides.push(h.word().to_string()),
            "H" => {
                let w = h.words();
                let y = fenestra_cli::opts::parse_real(&w[0])
                    .filter(|v| v.is_finite() && *v > 0.0)
                    .with_context(|| format!("-H {}: a positive y value expected", w[0]))?;
                chart.levels.push(Level {
                    y,
                    name: w[1].clone(),
                });
            }
            "o" => out = Some(h.word().to_string()),
            _ => unreachable!("declared options only"),
        }
    }
    let (name, mut rd): (String, Box<dyn BufRead>) = match pos.as_slice() {
        [] => ("standard input".into(), Box::new(std::io::stdin().lock())),
        [p] if p == "-" => ("standard input".into(), Box::new(std::io::stdin().lock())),
        [p] => {
            let f = std::fs::File::open(p).with_context(|| format!("cannot open '{p}'"))?;
            (p.clone(), Box::new(std::io::BufReader::new(f)))
        }
        _ => bail!("one table expected, {} given", pos.len()),
    };
    chart.series = read_table(&mut rd, &name)?;
    for g in &guides {
        match chart.series.iter_mut().find(|s| &s.name == g) {
            Some(s) => s.sqrt_guide = true,
            None => bail!("-g '{g}': no such series in {name}"),
        }
    }
    let svg = fenestra_chart::svg::to_svg(&chart).with_context(|| name.clone())?;
    match out {
        Some(o) => {
            let mut f = fenestra_cli::output::AtomicFile::create(&o)?;
            f.write_all(svg.as_bytes())?;
            f.commit()?;
        }
        None => std::io::stdout().lock().write_all(svg.as_bytes())?,
    }
    Ok(ExitCode::SUCCESS)
}
