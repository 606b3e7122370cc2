//! Floor-plan maps: one panel per metric, a coloured square per sensor at its (x, y) with
//! the value printed in it, a shared colour bar, axes in metres. For annual metrics per
//! sensor (dametrics `-m`).

use std::fmt::Write;

use anyhow::{bail, Result};

/// One panel: a title and a value per sensor.
#[derive(Debug, Clone)]
pub struct Panel {
    /// Title above the panel (the metric and its unit).
    pub title: String,
    /// Value per sensor, in the order of the sensor positions.
    pub values: Vec<f64>,
}

/// A plan: sensor positions (x, y in metres), panels side by side, the colour scale's
/// range and its label.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Title above the panels.
    pub title: String,
    /// Sensor positions.
    pub points: Vec<(f64, f64)>,
    /// The panels.
    pub panels: Vec<Panel>,
    /// Value at the bottom and top of the colour scale.
    pub range: (f64, f64),
    /// Colour bar label (e.g. "% of occupied hours").
    pub scale_label: String,
}

/// Dark blue → teal → green → yellow (perceptually ordered, readable in grey) for t in [0, 1].
pub fn colour(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    } * 4.0;
    let k = (t.floor() as usize).min(3);
    let f = t - k as f64;
    let c = |i: usize| (STOPS[k][i] + f * (STOPS[k + 1][i] - STOPS[k][i])).round() as u8;
    [c(0), c(1), c(2)]
}

/// The cell size along x and along y: the smallest non-zero distance between two sensors
/// along that axis (or the other axis's, or 1, when all sensors share the coordinate).
fn spacing(points: &[(f64, f64)]) -> (f64, f64) {
    let (mut dx, mut dy) = (f64::INFINITY, f64::INFINITY);
    for (i, a) in points.iter().enumerate() {
        for b in &points[i + 1..] {
            let (x, y) = ((a.0 - b.0).abs(), (a.1 - b.1).abs());
            if x > 1e-9 {
                dx = dx.min(x);
            }
            if y > 1e-9 {
                dy = dy.min(y);
            }
        }
    }
    match (dx.is_finite(), dy.is_finite()) {
        (true, true) => (dx, dy),
        (true, false) => (dx, dx),
        (false, true) => (dy, dy),
        (false, false) => (1.0, 1.0),
    }
}

/// The plan as an SVG document.
pub fn to_svg(plan: &Plan) -> Result<String> {
    let n = plan.points.len();
    if n == 0 || plan.panels.is_empty() {
        bail!("a plan needs sensors and at least one panel");
    }
    if let Some(p) = plan.panels.iter().find(|p| p.values.len() != n) {
        bail!(
            "panel '{}': {} values for {n} sensors",
            p.title,
            p.values.len()
        );
    }
    let (lo, hi) = plan.range;
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        bail!("colour scale {lo}..{hi}: the top must be above the bottom");
    }
    let (cw, ch) = spacing(&plan.points);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in &plan.points {
        x0 = x0.min(x - cw / 2.0);
        x1 = x1.max(x + cw / 2.0);
        y0 = y0.min(y - ch / 2.0);
        y1 = y1.max(y + ch / 2.0);
    }
    // scale: the taller side 300 px
    let s = 300.0 / (x1 - x0).max(y1 - y0);
    let (pw, ph) = ((x1 - x0) * s, (y1 - y0) * s);
    let (left, top, gap) = (60.0, 70.0, 70.0);
    let bar_x = left + plan.panels.len() as f64 * (pw + gap);
    let (w, h) = (bar_x + 110.0, top + ph + 60.0);
    let mut o = String::new();
    let _ = writeln!(
        o,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="DejaVu Sans, Arial, sans-serif" font-size="12">"#
    );
    let _ = writeln!(o, r#"<rect width="{w:.0}" height="{h:.0}" fill="white"/>"#);
    let _ = writeln!(
        o,
        r#"<text x="{:.1}" y="24" text-anchor="middle" font-size="15" font-weight="bold">{}</text>"#,
        w / 2.0,
        esc(&plan.title)
    );
    let font = (cw.min(ch) * s * 0.32).clamp(8.0, 13.0);
    for (k, panel) in plan.panels.iter().enumerate() {
        let ox = left + k as f64 * (pw + gap);
        let _ = writeln!(
            o,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="13">{}</text>"#,
            ox + pw / 2.0,
            top - 12.0,
            esc(&panel.title)
        );
        for (&(x, y), &v) in plan.points.iter().zip(&panel.values) {
            let [r, g, b] = colour((v - lo) / (hi - lo));
            // y grows upward in the room, downward on the page
            let (cx, cy) = (ox + (x - x0) * s, top + (y1 - y) * s);
            let (hw, hh) = (cw * s / 2.0, ch * s / 2.0);
            let _ = writeln!(
                o,
                r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="rgb({r},{g},{b})" stroke="white"/>"#,
                cx - hw,
                cy - hh,
                2.0 * hw,
                2.0 * hh
            );
            let ink = if 0.299 * f64::from(r) + 0.587 * f64::from(g) + 0.114 * f64::from(b) > 128.0
            {
                "black"
            } else {
                "white"
            };
            let _ = writeln!(
                o,
                r#"<text x="{cx:.1}" y="{:.1}" text-anchor="middle" font-size="{font:.1}" fill="{ink}">{v:.0}</text>"#,
                cy + font * 0.35
            );
        }
        let _ = writeln!(
            o,
            r#"<rect x="{ox:.1}" y="{top:.1}" width="{pw:.1}" height="{ph:.1}" fill="none" stroke="black"/>"#
        );
        // axis ends in metres
        let _ = writeln!(
            o,
            r#"<text x="{ox:.1}" y="{:.1}" text-anchor="middle">{}</text><text x="{:.1}" y="{:.1}" text-anchor="middle">{} m</text><text x="{:.1}" y="{:.1}" text-anchor="middle">x</text>"#,
            top + ph + 16.0,
            fmt_m(x0),
            ox + pw,
            top + ph + 16.0,
            fmt_m(x1),
            ox + pw / 2.0,
            top + ph + 16.0
        );
        let _ = writeln!(
            o,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text><text x="{:.1}" y="{:.1}" text-anchor="end">{} m</text><text x="{:.1}" y="{:.1}" text-anchor="end">y</text>"#,
            ox - 5.0,
            top + ph,
            fmt_m(y0),
            ox - 5.0,
            top + 10.0,
            fmt_m(y1),
            ox - 5.0,
            top + ph / 2.0
        );
    }
    // colour bar
    let steps = 20;
    for i in 0..steps {
        let t0 = i as f64 / steps as f64;
        let [r, g, b] = colour(t0 + 0.5 / steps as f64);
        let y = top + ph * (1.0 - (i + 1) as f64 / steps as f64);
        let _ = writeln!(
            o,
            r#"<rect x="{bar_x:.1}" y="{y:.1}" width="18" height="{:.2}" fill="rgb({r},{g},{b})"/>"#,
            ph / steps as f64 + 0.3
        );
    }
    for i in 0..=4 {
        let t = i as f64 / 4.0;
        let y = top + ph * (1.0 - t);
        let _ = writeln!(
            o,
            r#"<text x="{:.1}" y="{:.1}">{}</text>"#,
            bar_x + 24.0,
            y + 4.0,
            fmt_m(lo + t * (hi - lo))
        );
    }
    let _ = writeln!(
        o,
        r#"<text transform="translate({:.1} {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        bar_x + 80.0,
        top + ph / 2.0,
        esc(&plan.scale_label)
    );
    o.push_str("</svg>\n");
    Ok(o)
}

fn fmt_m(v: f64) -> String {
    let s = format!("{v:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_per_sensor_per_panel_and_bad_plans_refused() {
        let plan = Plan {
            title: "t".into(),
            points: vec![(0.5, 0.5), (1.0, 0.5), (0.5, 1.0), (1.0, 1.0)],
            panels: vec![
                Panel {
                    title: "DA300 %".into(),
                    values: vec![10.0, 20.0, 90.0, 100.0],
                },
                Panel {
                    title: "UDI %".into(),
                    values: vec![0.0, 50.0, 50.0, 60.0],
                },
            ],
            range: (0.0, 100.0),
            scale_label: "% of occupied hours".into(),
        };
        let s = to_svg(&plan).unwrap();
        assert_eq!(s.matches("stroke=\"white\"").count(), 8);
        assert!(s.contains(">DA300 %<") && s.contains(">90<") && s.contains("% of occupied hours"));
        let mut bad = plan.clone();
        bad.panels[1].values.pop();
        assert!(to_svg(&bad).is_err());
        assert_eq!(colour(0.0), [68, 1, 84]);
        assert_eq!(colour(1.0), [253, 231, 37]);
    }
}
