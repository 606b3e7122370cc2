//! Drawing on an RGB raster (for PNG output): text in a 5 × 7 pixel font (the characters a
//! number or a photometric unit needs) and the vertical colour legend of a false-colour
//! picture.

/// An RGB image, row 0 at the top.
pub struct Raster {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Pixels, row by row.
    pub pixels: Vec<[u8; 3]>,
}

/// The 5 × 7 glyph of `c` (rows top to bottom, bit 4 = leftmost column); `None` for
/// characters the font does not have.
fn glyph(c: char) -> Option<[u8; 7]> {
    Some(match c {
        '0' => [0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e],
        '1' => [0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e],
        '2' => [0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f],
        '3' => [0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e],
        '4' => [0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02],
        '5' => [0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e],
        '6' => [0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e],
        '7' => [0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e],
        '9' => [0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c],
        '.' => [0, 0, 0, 0, 0, 0x0c, 0x0c],
        '-' => [0, 0, 0, 0x1f, 0, 0, 0],
        '+' => [0, 0x04, 0x04, 0x1f, 0x04, 0x04, 0],
        'e' => [0, 0, 0x0e, 0x11, 0x1f, 0x10, 0x0e],
        'c' => [0, 0, 0x0e, 0x10, 0x10, 0x11, 0x0e],
        'd' => [0x01, 0x01, 0x0d, 0x13, 0x11, 0x11, 0x0f],
        'm' => [0, 0, 0x1a, 0x15, 0x15, 0x11, 0x11],
        'l' => [0x0c, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e],
        'u' => [0, 0, 0x11, 0x11, 0x11, 0x13, 0x0d],
        'x' => [0, 0, 0x11, 0x0a, 0x04, 0x0a, 0x11],
        '/' => [0, 0x01, 0x02, 0x04, 0x08, 0x10, 0],
        ' ' => [0; 7],
        _ => return None,
    })
}

impl Raster {
    /// A white raster.
    pub fn white(width: usize, height: usize) -> Raster {
        Raster {
            width,
            height,
            pixels: vec![[255; 3]; width * height],
        }
    }

    /// Sets pixel (x, y) when it is inside.
    pub fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            self.pixels[y * self.width + x] = c;
        }
    }

    /// Width in pixels of `text` at `scale` (6 columns per character, the last without a gap).
    pub fn text_width(text: &str, scale: usize) -> usize {
        (text.chars().count() * 6).saturating_sub(1) * scale
    }

    /// Draws `text` with its top-left corner at (x, y), each font pixel `scale` × `scale`;
    /// characters the font lacks are left blank.
    pub fn text(&mut self, x: usize, y: usize, text: &str, scale: usize, c: [u8; 3]) {
        for (k, ch) in text.chars().enumerate() {
            let Some(g) = glyph(ch) else { continue };
            for (row, bits) in g.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0x10 >> col) != 0 {
                        for dy in 0..scale {
                            for dx in 0..scale {
                                self.set(x + (k * 6 + col) * scale + dx, y + row * scale + dy, c);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A label for a legend value: up to 4 significant digits, no exponent between 0.01 and 99 999.
pub fn legend_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if (0.01..1e5).contains(&v.abs()) {
        let digits = (3 - v.abs().log10().floor() as i32).clamp(0, 4) as usize;
        let s = format!("{v:.digits$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.2e}")
    }
}

/// `image` (width × height) with a legend strip on its right: the colour scale `ramp` from
/// 0 (bottom) to `max` (top), five labelled ticks and `unit` above it.
pub fn with_legend(image: &Raster, max: f64, unit: &str, ramp: &dyn Fn(f64) -> [u8; 3]) -> Raster {
    let scale = (image.height / 240).max(1);
    let labels: Vec<String> = (0..=4)
        .map(|k| legend_label(max * k as f64 / 4.0))
        .collect();
    let text_w = labels
        .iter()
        .map(|l| Raster::text_width(l, scale))
        .chain([Raster::text_width(unit, scale)])
        .max()
        .unwrap_or(0);
    let bar_w = 12 * scale;
    let strip = 6 * scale + bar_w + 4 * scale + text_w + 6 * scale;
    let height = image.height.max(60 * scale);
    let mut out = Raster::white(image.width + strip, height);
    for y in 0..image.height {
        for x in 0..image.width {
            out.pixels[y * out.width + x] = image.pixels[y * image.width + x];
        }
    }
    let x0 = image.width + 6 * scale;
    let (top, bottom) = (12 * scale, height - 6 * scale);
    let span = (bottom - top) as f64;
    for y in top..bottom {
        let t = (bottom - 1 - y) as f64 / (span - 1.0).max(1.0);
        let c = ramp(t);
        for x in x0..x0 + bar_w {
            out.set(x, y, c);
        }
    }
    let ink = [0, 0, 0];
    out.text(x0, 2 * scale, unit, scale, ink);
    for (k, l) in labels.iter().enumerate() {
        let y = bottom as f64 - 1.0 - span * k as f64 / 4.0;
        let ly = (y as usize)
            .saturating_sub(3 * scale)
            .clamp(top.saturating_sub(3 * scale), bottom - 7 * scale);
        for x in x0 + bar_w..x0 + bar_w + 3 * scale {
            out.set(x, y as usize, ink);
        }
        out.text(x0 + bar_w + 4 * scale, ly, l, scale, ink);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_and_legend() {
        let mut r = Raster::white(20, 10);
        r.text(0, 0, "1", 1, [0, 0, 0]);
        // '1': row 0 = 0x04 → column 2 set
        assert_eq!(r.pixels[2], [0, 0, 0]);
        assert_eq!(r.pixels[0], [255; 3]);
        assert_eq!(Raster::text_width("10", 1), 11);
        assert_eq!(legend_label(4116.1656), "4116");
        assert_eq!(legend_label(1029.0414), "1029");
        assert_eq!(legend_label(2.5), "2.5");
        assert_eq!(legend_label(0.0), "0");
        let img = Raster::white(100, 80);
        let l = with_legend(&img, 4000.0, "cd/m2", &|t| [(t * 255.0) as u8, 0, 0]);
        assert!(l.width > 100 && l.height == 80);
        // the bar: reddest at the top, black at the bottom
        let x = 100 + 6 + 3;
        assert!(
            l.pixels[13 * l.width + x][0] > 240,
            "{:?}",
            l.pixels[13 * l.width + x]
        );
        assert!(l.pixels[(80 - 7) * l.width + x][0] < 10);
    }
}
