//! hdr2png: a Radiance picture as a PNG: size and layout of the file, the stored rows
//! (tone-mapped and false colour), and bad input.

mod common;

/// The IHDR size and the uncompressed scanlines of one of our PNGs (stored blocks).
fn decode(png: &[u8]) -> (u32, u32, Vec<u8>) {
    assert_eq!(&png[..8], &[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]);
    let w = u32::from_be_bytes(png[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(png[20..24].try_into().unwrap());
    assert_eq!(&png[24..29], &[8, 2, 0, 0, 0], "8-bit RGB");
    let idat_len = u32::from_be_bytes(png[33..37].try_into().unwrap()) as usize;
    assert_eq!(&png[37..41], b"IDAT");
    let z = &png[41..41 + idat_len];
    let mut raw = Vec::new();
    let mut k = 2;
    loop {
        let last = z[k] & 1 == 1;
        let len = u16::from_le_bytes([z[k + 1], z[k + 2]]) as usize;
        raw.extend_from_slice(&z[k + 5..k + 5 + len]);
        k += 5 + len;
        if last {
            break;
        }
    }
    (w, h, raw)
}

#[test]
fn pictures_become_pngs_of_the_same_size() {
    let pic = common::fixture("threephase/img_t1_mar21_1000_clear.hdr");
    let out = common::output_ok(common::fenestra("hdr2png").arg(&pic));
    assert!(String::from_utf8_lossy(&out.stderr).contains("exposure multiplier"));
    let (w, h, raw) = decode(&out.stdout);
    assert_eq!((w, h), (32, 26));
    assert_eq!(raw.len(), 26 * (1 + 3 * 32));
    assert!(
        raw.chunks(1 + 3 * 32).all(|row| row[0] == 0),
        "filter bytes"
    );
    // not all black, not all white
    let px: Vec<u8> = raw.chunks(97).flat_map(|r| r[1..].to_vec()).collect();
    assert!(px.iter().any(|&v| v > 20) && px.iter().any(|&v| v < 235));
    // false colour: the scale on stderr, a pure ramp colour in every pixel of the picture
    // (blue..red), and a legend strip to its right (the colour bar and black label text)
    let out = common::output_ok(common::fenestra("hdr2png").args(["-f", "1000"]).arg(&pic));
    assert!(String::from_utf8_lossy(&out.stderr).contains("1000.0000 (red) cd/m2"));
    let (w, h, raw) = decode(&out.stdout);
    assert!(w > 32 && h >= 26, "{w}×{h}");
    let stride = 1 + 3 * w as usize;
    let pixel = |x: usize, y: usize| {
        let k = y * stride + 1 + 3 * x;
        [raw[k], raw[k + 1], raw[k + 2]]
    };
    for y in 0..26 {
        for x in 0..32 {
            let p = pixel(x, y);
            // the ramp has at most two of red, green, blue lit together, never all three
            assert!(
                p.iter().filter(|&&v| v > 0).count() <= 2 || p[0] == 0 || p[2] == 0,
                "{p:?}"
            );
        }
    }
    let legend: Vec<[u8; 3]> = (0..h as usize)
        .flat_map(|y| (32..w as usize).map(move |x| (x, y)))
        .map(|(x, y)| pixel(x, y))
        .collect();
    assert!(legend.contains(&[0, 0, 0]), "label text");
    assert!(
        legend.iter().any(|p| p[0] > 200 && p[1] < 60 && p[2] < 60),
        "the red end of the bar"
    );
    assert!(
        legend.iter().any(|p| p[2] > 200 && p[0] < 60 && p[1] < 60),
        "the blue end of the bar"
    );
}

#[test]
fn bad_input_is_refused() {
    let dir = common::cli::scratch_files("hdr2png-bad", &[("not.hdr", "hello\n")]);
    let cases: [&[&str]; 4] = [
        &["not.hdr"],
        &["missing.hdr"],
        &["-g", "0", "not.hdr"],
        &["-q"],
    ];
    let outs = common::cli::failures("hdr2png", &dir, &cases);
    for (args, (stdout, _)) in cases.iter().zip(outs) {
        assert!(stdout.is_empty(), "{args:?}: nothing written");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
