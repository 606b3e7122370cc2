//! OpenEXR output for pictures: wherever a tool writes a picture to a file named
//! `*.exr`, it writes 32-bit float RGB OpenEXR (lossless) instead of Radiance RGBE.

use std::io::Cursor;
use std::path::Path;

use exr::prelude::{
    Encoding, Image, Layer, LayerAttributes, SpecificChannels, Text, Vec2, WritableImage,
};

use crate::picture::PictureHeader;

/// Whether a file name asks for OpenEXR output (extension `.exr`, any case).
pub fn is_exr_path(path: impl AsRef<Path>) -> bool {
    path.as_ref()
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Encodes a standard-orientation picture (`height` rows of `width`, top row first)
/// as an OpenEXR file in memory. The header's command line and view go into the
/// layer's comments, so the provenance Radiance keeps in its header survives.
pub fn encode_exr(
    header: Option<&PictureHeader>,
    width: usize,
    height: usize,
    pixels: &[[f32; 3]],
) -> anyhow::Result<Vec<u8>> {
    anyhow::ensure!(
        width > 0 && height > 0,
        "an OpenEXR picture needs at least one pixel (got {width}x{height})"
    );
    anyhow::ensure!(
        pixels.len() == width * height,
        "picture has {} pixels, expected {width}x{height}",
        pixels.len()
    );
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let px = pixels[p.y() * width + p.x()];
        (px[0], px[1], px[2])
    });
    let mut attrs = LayerAttributes {
        software_name: Text::new_or_none("fenestra"),
        ..LayerAttributes::default()
    };
    if let Some(h) = header {
        let mut notes: Vec<String> = h.lines.clone();
        if let Some(c) = &h.command {
            notes.push(c.clone());
        }
        if let Some(v) = &h.view {
            notes.push(v.header_line());
        }
        let ascii: String = notes
            .join("\n")
            .chars()
            .map(|c| if c.is_ascii() { c } else { '?' })
            .collect();
        attrs.comments = Text::new_or_none(ascii.as_str());
    }
    let layer = Layer::new((width, height), attrs, Encoding::FAST_LOSSLESS, channels);
    let image = Image::from_layer(layer);
    let mut buf = Cursor::new(Vec::new());
    image
        .write()
        .to_buffered(&mut buf)
        .map_err(|e| anyhow::anyhow!("cannot encode OpenEXR: {e}"))?;
    Ok(buf.into_inner())
}

/// Writes a picture file: OpenEXR when the name ends in `.exr`, otherwise Radiance RGBE.
/// The file appears complete or not at all (written to a temporary file, then renamed).
pub fn write_picture_file(
    path: impl AsRef<Path>,
    header: Option<&PictureHeader>,
    width: usize,
    height: usize,
    pixels: &[[f32; 3]],
) -> anyhow::Result<()> {
    use anyhow::Context;
    use std::io::Write;
    let path = path.as_ref();
    let mut out = fenestra_io::output::AtomicFile::create(path)?;
    if is_exr_path(path) {
        let bytes = encode_exr(header, width, height, pixels)
            .with_context(|| format!("{}", path.display()))?;
        out.write_all(&bytes)
            .with_context(|| format!("cannot write {}", path.display()))?;
    } else {
        crate::picture::write_picture(&mut out, header, width, height, pixels)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    out.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_back(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
        use exr::prelude::*;
        let img = read_first_rgba_layer_from_file(
            path,
            |res, _| {
                (
                    res.width(),
                    res.height(),
                    vec![[0f32; 3]; res.width() * res.height()],
                )
            },
            |st: &mut (usize, usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                let w = st.0;
                st.2[pos.y() * w + pos.x()] = [r, g, b];
            },
        )
        .unwrap();
        img.layer_data.channel_data.pixels
    }

    #[test]
    fn exr_round_trip_is_exact_for_odd_sizes_and_extremes() {
        let dir = std::env::temp_dir().join(format!("fenestra_exr_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (w, h) in [(1, 1), (1, 7), (5, 1), (13, 9)] {
            let pixels: Vec<[f32; 3]> = (0..w * h)
                .map(|i| {
                    let x = i as f32;
                    [x * 0.25, 1e30 / (x + 1.0), 1e-38 * (x + 1.0)]
                })
                .collect();
            let p = dir.join(format!("p_{w}x{h}.exr"));
            write_picture_file(&p, None, w, h, &pixels).unwrap();
            let (rw, rh, got) = read_back(&p);
            assert_eq!((rw, rh), (w, h));
            assert_eq!(got, pixels, "{w}x{h}");
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn extension_chooses_the_format() {
        assert!(is_exr_path("a/b.EXR"));
        assert!(is_exr_path("x.exr"));
        assert!(!is_exr_path("x.hdr"));
        assert!(!is_exr_path("exr"));
        assert!(encode_exr(None, 0, 3, &[]).is_err());
    }
}
