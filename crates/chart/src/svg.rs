//! The SVG writer: plot area with a log–log grid and tick labels, axis labels, the series
//! (lines and markers, colour and marker shape per series), dashed 1/√x guides, horizontal
//! levels, and the legend to the right of the plot (long entries wrapped), so text never
//! covers data.

use std::fmt::Write;

use anyhow::{bail, Result};

use crate::axis::{label, LogAxis};
use crate::Chart;

const W: f64 = 800.0;
const H: f64 = 470.0;
const LEFT: f64 = 78.0;
const TOP: f64 = 48.0;
const PW: f64 = 440.0;
const PH: f64 = 340.0;
const LEGEND_X: f64 = LEFT + PW + 24.0;
/// Characters per legend line (12 px sans-serif, about 6.6 px per character).
const LEGEND_CHARS: usize = 34;
/// Stroke colour and dash pattern of the horizontal levels, in turn.
const LEVELS: [(&str, &str); 3] = [
    ("#444444", "8 4 2 4"),
    ("#8b0000", "2 3"),
    ("#006400", "12 4"),
];
const COLOURS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
];

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Splits `s` into lines of at most `n` characters at spaces (a longer word stays whole).
fn wrap(s: &str, n: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut cur = String::new();
    for w in s.split_whitespace() {
        if !cur.is_empty() && cur.chars().count() + 1 + w.chars().count() > n {
            lines.push(std::mem::take(&mut cur));
        }
        if !cur.is_empty() {
            cur.push(' ');
        }
        cur.push_str(w);
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
}

fn marker(out: &mut String, k: usize, x: f64, y: f64, colour: &str) {
    let r = 4.0;
    match k % 4 {
        0 => {
            let _ = write!(
                out,
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="{r}" fill="{colour}"/>"#
            );
        }
        1 => {
            let _ = write!(
                out,
                r#"<rect x="{:.1}" y="{:.1}" width="{}" height="{}" fill="{colour}"/>"#,
                x - r,
                y - r,
                2.0 * r,
                2.0 * r
            );
        }
        2 => {
            let _ = write!(
                out,
                r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="{colour}"/>"#,
                x,
                y - r - 1.0,
                x - r - 1.0,
                y + r,
                x + r + 1.0,
                y + r
            );
        }
        _ => {
            let _ = write!(
                out,
                r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="{colour}"/>"#,
                x,
                y - r - 1.0,
                x + r + 1.0,
                y,
                x,
                y + r + 1.0,
                x - r - 1.0,
                y
            );
        }
    }
    out.push('\n');
}

/// The chart as an SVG document.
pub fn to_svg(chart: &Chart) -> Result<String> {
    let xs = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0));
    let ys = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1));
    let levels = chart.levels.iter().map(|l| l.y);
    let (Some(ax), Some(ay)) = (LogAxis::covering(xs), LogAxis::covering(ys.chain(levels))) else {
        bail!("no positive values to draw on log axes");
    };
    for s in &chart.series {
        if let Some(p) = s
            .points
            .iter()
            .find(|p| !(p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite()))
        {
            bail!(
                "series '{}': point ({}, {}) cannot be drawn on log axes",
                s.name,
                p.0,
                p.1
            );
        }
    }
    let px = |x: f64| LEFT + PW * ax.frac(x);
    let py = |y: f64| TOP + PH * (1.0 - ay.frac(y));
    let mut o = String::new();
    let _ = writeln!(
        o,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="DejaVu Sans, Arial, sans-serif" font-size="12">"#
    );
    let _ = writeln!(o, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let _ = writeln!(
        o,
        r#"<defs><clipPath id="plot"><rect x="{LEFT}" y="{TOP}" width="{PW}" height="{PH}"/></clipPath></defs>"#
    );
    let _ = writeln!(
        o,
        r#"<text x="{:.1}" y="26" text-anchor="middle" font-size="15" font-weight="bold">{}</text>"#,
        W / 2.0,
        esc(&chart.title)
    );
    // grid and tick labels
    for t in ax.ticks() {
        let x = px(t);
        let _ = writeln!(
            o,
            r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#dddddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            TOP + PH,
            TOP + PH + 17.0,
            label(t)
        );
    }
    for t in ay.ticks() {
        let y = py(t);
        let _ = writeln!(
            o,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#dddddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            LEFT + PW,
            LEFT - 7.0,
            y + 4.0,
            label(t)
        );
    }
    let _ = writeln!(
        o,
        r#"<rect x="{LEFT}" y="{TOP}" width="{PW}" height="{PH}" fill="none" stroke="black"/>"#
    );
    let _ = writeln!(
        o,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="13">{}</text>"#,
        LEFT + PW / 2.0,
        TOP + PH + 40.0,
        esc(&chart.x_label)
    );
    let _ = writeln!(
        o,
        r#"<text transform="translate(20 {:.1}) rotate(-90)" text-anchor="middle" font-size="13">{}</text>"#,
        TOP + PH / 2.0,
        esc(&chart.y_label)
    );
    // levels, guides, series (clipped to the plot)
    let _ = writeln!(o, r#"<g clip-path="url(#plot)">"#);
    for (k, l) in chart.levels.iter().enumerate() {
        let y = py(l.y);
        let (c, dash) = LEVELS[k % LEVELS.len()];
        let _ = writeln!(
            o,
            r#"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{c}" stroke-width="1.5" stroke-dasharray="{dash}"/>"#,
            LEFT + PW
        );
    }
    for (k, s) in chart.series.iter().enumerate() {
        let c = COLOURS[k % COLOURS.len()];
        if s.sqrt_guide && !s.points.is_empty() {
            let (x0, y0) = s.points[0];
            let x1 = 10f64.powi(ax.hi);
            let _ = writeln!(
                o,
                r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{c}" stroke-opacity="0.55" stroke-dasharray="5 4"/>"#,
                px(x0),
                py(y0),
                px(x1),
                py(y0 * (x0 / x1).sqrt())
            );
        }
        let pts: Vec<String> = s
            .points
            .iter()
            .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
            .collect();
        let _ = writeln!(
            o,
            r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="2"/>"#,
            pts.join(" ")
        );
        for &(x, y) in &s.points {
            marker(&mut o, k, px(x), py(y), c);
        }
    }
    o.push_str("</g>\n");
    // legend
    let mut y = TOP + 6.0;
    let mut entry = |o: &mut String, text: &str, sample: &dyn Fn(&mut String, f64)| {
        sample(o, y);
        let lines = wrap(text, LEGEND_CHARS);
        for (i, line) in lines.iter().enumerate() {
            let _ = writeln!(
                o,
                r#"<text x="{:.1}" y="{:.1}">{}</text>"#,
                LEGEND_X + 34.0,
                y + 4.0 + 15.0 * i as f64,
                esc(line)
            );
        }
        y += 15.0 * lines.len().saturating_sub(1) as f64 + 22.0;
    };
    for (k, s) in chart.series.iter().enumerate() {
        let c = COLOURS[k % COLOURS.len()];
        entry(&mut o, &s.name, &|o, y| {
            let _ = writeln!(
                o,
                r#"<line x1="{LEGEND_X}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{c}" stroke-width="2"/>"#,
                LEGEND_X + 26.0
            );
            marker(o, k, LEGEND_X + 13.0, y, c);
        });
    }
    if chart.series.iter().any(|s| s.sqrt_guide) {
        entry(
            &mut o,
            "dashed: error ∝ 1/√time through the first point (half the error costs 4× the time)",
            &|o, y| {
                let _ = writeln!(
                    o,
                    r##"<line x1="{LEGEND_X}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#777777" stroke-dasharray="5 4"/>"##,
                    LEGEND_X + 26.0
                );
            },
        );
    }
    for (k, l) in chart.levels.iter().enumerate() {
        let (c, dash) = LEVELS[k % LEVELS.len()];
        entry(&mut o, &l.name, &|o, y| {
            let _ = writeln!(
                o,
                r#"<line x1="{LEGEND_X}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{c}" stroke-width="1.5" stroke-dasharray="{dash}"/>"#,
                LEGEND_X + 26.0
            );
        });
    }
    o.push_str("</svg>\n");
    Ok(o)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Level, Series};

    #[test]
    fn chart_holds_every_element_and_refuses_bad_points() {
        let mut c = Chart {
            title: "t <1>".into(),
            x_label: "wall time (s)".into(),
            y_label: "rms error (%)".into(),
            series: vec![Series {
                name: "D -c".into(),
                points: vec![(0.2, 5.0), (0.8, 2.5), (3.2, 1.3)],
                sqrt_guide: true,
            }],
            levels: vec![Level {
                y: 0.5,
                name: "method limit".into(),
            }],
        };
        let s = to_svg(&c).unwrap();
        assert!(s.starts_with("<svg") && s.ends_with("</svg>\n"));
        assert!(
            s.contains("t &lt;1&gt;") && s.contains("wall time (s)") && s.contains("rms error (%)")
        );
        assert_eq!(s.matches("<polyline").count(), 1);
        assert_eq!(s.matches("<circle").count(), 4); // 3 points and the legend sample
        assert!(s.contains("method limit") && s.contains("stroke-dasharray=\"5 4\""));
        c.series[0].points.push((1.0, 0.0));
        assert!(to_svg(&c).is_err());
    }

    #[test]
    fn legend_lines_wrap_at_spaces() {
        assert_eq!(wrap("a bb ccc", 4), vec!["a bb", "ccc"]);
        assert_eq!(wrap("abcdefgh", 3), vec!["abcdefgh"]);
    }
}
