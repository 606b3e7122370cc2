//! HDR pictures: our reader and writer against the oracle's pvalue, pflip and protate.

mod common;

use std::path::Path;

use fenestra_formats::picture::{write_picture, Picture, PictureHeader};
use fenestra_formats::rgbe;

fn read(path: &Path) -> Picture {
    let f = std::fs::File::open(path).unwrap();
    Picture::read(&mut std::io::BufReader::new(f), "test").unwrap()
}

fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_ne_bytes(c.try_into().unwrap()))
        .collect()
}

fn vimg() -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(common::fixture("picture/vimg"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "hdr"))
        .collect();
    v.sort();
    v
}

/// Values that RGBE represents exactly (largest mantissa >= 128), some zero.
fn exact_pixels(n: usize, seed: u32) -> Vec<[f32; 3]> {
    let mut s = seed.wrapping_mul(2_654_435_761).wrapping_add(1);
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s
    };
    (0..n)
        .map(|_| {
            let r = next();
            if r % 13 == 0 {
                return [0.0; 3];
            }
            let m = [128 + (r % 128) as u8, (r >> 8) as u8 % 128, (r >> 16) as u8];
            let big = (r % 3) as usize;
            let mut p = [m[1], m[2] / 2, m[1] / 3];
            p[big] = m[0];
            rgbe::decode([p[0], p[1], p[2], 100 + (r >> 24) as u8 % 60])
        })
        .collect()
}

#[test]
fn every_reference_picture_decodes() {
    let files = vimg();
    assert_eq!(files.len(), 145);
    for f in files {
        let p = read(&f);
        assert_eq!((p.res.xr, p.res.yr), (32, 26), "{}", f.display());
        assert_eq!(p.pixels.len(), 32 * 26);
    }
}

/// Exact equality: pvalue -df prints the decoded float32 values; so do we.
#[test]
fn oracle_reader_matches_pvalue_on_every_reference_picture() {
    let Some(o) = common::oracle() else { return };
    for f in vimg() {
        let want = floats(&common::run_ok(
            o.command("pvalue").args(["-h", "-H", "-df"]).arg(&f),
        ));
        let got: Vec<f32> = read(&f).pixels.iter().flatten().copied().collect();
        assert!(want == got, "{}: pixel values differ", f.display());
    }
}

#[test]
fn oracle_written_pictures_read_back_identically() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("picture-write");
    for (k, (w, h)) in [
        (1usize, 1usize),
        (1, 9),
        (9, 1),
        (16, 3),
        (17, 4),
        (33, 17),
        (300, 2),
    ]
    .into_iter()
    .enumerate()
    {
        let px = exact_pixels(w * h, k as u32);
        let hdr = PictureHeader {
            command: Some("picture-test".into()),
            ..Default::default()
        };
        let path = dir.join(format!("p{k}.hdr"));
        let mut buf = Vec::new();
        write_picture(&mut buf, Some(&hdr), w, h, &px).unwrap();
        std::fs::write(&path, &buf).unwrap();
        let want: Vec<f32> = px.iter().flatten().copied().collect();
        let got = floats(&common::run_ok(
            o.command("pvalue").args(["-h", "-H", "-df"]).arg(&path),
        ));
        assert!(want == got, "{w}x{h}: pvalue reads other values");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The run-length encoding is byte-identical to Radiance's writer (pvalue -r).
#[test]
fn oracle_encoding_is_byte_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("picture-bytes");
    for (k, (w, h)) in [(5usize, 3usize), (17, 2), (40, 5), (200, 2)]
        .into_iter()
        .enumerate()
    {
        // Runs and literals: repeat each value a varying number of times.
        let base = exact_pixels(w * h, 100 + k as u32);
        let px: Vec<[f32; 3]> = (0..w * h).map(|i| base[i / (1 + i % 7)]).collect();
        let raw: Vec<u8> = px.iter().flatten().flat_map(|v| v.to_ne_bytes()).collect();
        let rawpath = dir.join(format!("r{k}.f"));
        std::fs::write(&rawpath, &raw).unwrap();
        let theirs = common::run_ok(
            o.command("pvalue")
                .args([
                    "-r",
                    "-h",
                    "-H",
                    "-df",
                    "-y",
                    &h.to_string(),
                    "+x",
                    &w.to_string(),
                ])
                .arg(&rawpath),
        );
        let mut ours = Vec::new();
        fenestra_formats::picture::write_resolution_and_pixels(&mut ours, w, h, &px).unwrap();
        // pvalue -r writes a header and resolution line; compare from the resolution on.
        let body = theirs.windows(2).position(|p| p == b"\n\n").unwrap() + 2;
        assert_eq!(&theirs[body..], &ours[..], "{w}x{h}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// All eight orientations (made by the oracle's pflip/protate) reorient to the same
/// image-frame pixels.
#[test]
fn oracle_all_orientations_reorient() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("picture-orient");
    let (w, h) = (7usize, 5usize);
    let px = exact_pixels(w * h, 7);
    let src = dir.join("src.hdr");
    let mut buf = Vec::new();
    write_picture(&mut buf, Some(&PictureHeader::default()), w, h, &px).unwrap();
    std::fs::write(&src, &buf).unwrap();
    let run = |name: &str, cmd: &str, args: &[&str], input: &Path| {
        let out = common::run_ok(o.command(cmd).args(args).arg(input));
        let p = dir.join(name);
        std::fs::write(&p, out).unwrap();
        p
    };
    let rot = run("rot.hdr", "protate", &[], &src);
    let rotr = run("rotr.hdr", "protate", &["-r"], &src);
    let variants = [
        src.clone(),
        run("h.hdr", "pflip", &["-h"], &src),
        run("v.hdr", "pflip", &["-v"], &src),
        run("hv.hdr", "pflip", &["-h", "-v"], &src),
        rot.clone(),
        rotr.clone(),
        run("roth.hdr", "pflip", &["-h"], &rot),
        run("rotv.hdr", "pflip", &["-v"], &rot),
    ];
    let mut seen = std::collections::BTreeSet::new();
    for f in &variants {
        let p = read(f);
        seen.insert(p.res.orient);
        // pvalue prints image-frame coordinates "x y r g b" (y up) for each stored pixel.
        let text = String::from_utf8(common::run_ok(
            o.command("pvalue").args(["-h", "-H"]).arg(f),
        ))
        .unwrap();
        let (pw, ph, std) = p.to_standard();
        for line in text.lines() {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            let (x, y) = (v[0] as usize, v[1] as usize);
            let ours = std[(ph - 1 - y) * pw + x];
            for k in 0..3 {
                // pvalue prints 4 significant digits: compare to that precision.
                let d = (ours[k] as f64 - v[2 + k]).abs();
                assert!(
                    d <= 5e-4 * v[2 + k].abs() + 1e-30,
                    "{}: ({x},{y})",
                    f.display()
                );
            }
        }
    }
    assert_eq!(seen.len(), 8, "orientations produced: {seen:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn corrupt_run_length_is_a_clear_error() {
    // The reference pictures are stored flat (rcontrib writes no run-length encoding),
    // so encode one of them with our writer first.
    let p = read(&common::fixture("picture/vimg/v000.hdr"));
    let mut data = Vec::new();
    write_picture(
        &mut data,
        Some(&PictureHeader::default()),
        32,
        26,
        &p.pixels,
    )
    .unwrap();
    let start = data.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    let start = start + data[start..].iter().position(|&b| b == b'\n').unwrap() + 1;
    // Fourth scanline (index 3): find its 02 02 00 20 marker and corrupt the first run code after it.
    let mut pos = start;
    for _ in 0..3 {
        pos += 1 + data[pos + 1..]
            .windows(4)
            .position(|w| w == [2, 2, 0, 32])
            .unwrap();
    }
    data[pos + 4] = 128 + 100; // a run of 100 in a 32-pixel scanline
    let dir = common::scratch("picture-corrupt");
    let bad = dir.join("bad.hdr");
    std::fs::write(&bad, &data).unwrap();
    let e = Picture::read(&mut data.as_slice(), "t")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("scanline 3 of 26") && e.contains("overruns"),
        "{e}"
    );
    let out = common::fenestra("pcomb").arg(&bad).output().unwrap();
    assert!(!out.status.success());
    assert!(out.stdout.is_empty(), "no partial output");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("pcomb: fatal - ") && err.contains("bad.hdr") && err.contains("overruns"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
