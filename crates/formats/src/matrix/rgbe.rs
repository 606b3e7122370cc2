//! RGBE common-exponent colours and their scanline encodings (flat, old-style
//! repeat markers and new run-length encoding), as used by RGBE-coded matrices.

use std::io::{BufRead, Read, Write};

use anyhow::{bail, Result};

/// Shortest scanline written with the new run-length encoding.
const MIN_RLE_LEN: usize = 17;
/// Longest scanline the new encoding can describe.
const MAX_RLE_LEN: usize = 0x7fff;
/// Shortest run worth a run packet.
const MIN_RUN: usize = 4;

/// Encodes a colour as RGBE (truncating mantissas; negatives become 0).
pub fn encode(c: [f64; 3]) -> [u8; 4] {
    let d = c[0].max(c[1]).max(c[2]);
    if d.is_nan() || d <= 1e-32 {
        return [0; 4];
    }
    let (f, e) = frexp(d);
    let scale = f * 256.0 / d;
    let m = |v: f64| {
        if v > 0.0 {
            (v * scale) as i64 as u8
        } else {
            0
        }
    };
    [m(c[0]), m(c[1]), m(c[2]), (e + 128).clamp(0, 255) as u8]
}

/// Decodes an RGBE colour (`(m + 0.5)·2^(E−136)`; exponent 0 is black).
pub fn decode(p: [u8; 4]) -> [f64; 3] {
    if p[3] == 0 {
        return [0.0; 3];
    }
    let f = ldexp(1.0, p[3] as i32 - 136);
    [
        (p[0] as f64 + 0.5) * f,
        (p[1] as f64 + 0.5) * f,
        (p[2] as f64 + 0.5) * f,
    ]
}

/// `(f, e)` with `d = f·2^e`, `f` in [0.5, 1) (d > 0); infinity as the largest exponent.
fn frexp(d: f64) -> (f64, i32) {
    if d.is_infinite() {
        return (0.5, 1025);
    }
    crate::rgbe::frexp(d)
}

fn ldexp(x: f64, e: i32) -> f64 {
    x * 2f64.powi(e)
}

/// Reads one scanline of `out.len()` pixels in any of the three encodings.
pub fn read_scanline<R: BufRead + ?Sized>(
    r: &mut R,
    out: &mut [[u8; 4]],
    name: &str,
) -> Result<()> {
    let len = out.len();
    if len == 0 {
        return Ok(());
    }
    let mut first = [0u8; 4];
    read_exact(r, &mut first, name)?;
    if (MIN_RLE_LEN..=MAX_RLE_LEN).contains(&len)
        && first[0] == 2
        && first[1] == 2
        && first[2] & 0x80 == 0
    {
        let n = ((first[2] as usize) << 8) | first[3] as usize;
        if n != len {
            bail!("{name}: bad RGBE scanline (run-length encoded length {n}, expected {len})");
        }
        for comp in 0..4 {
            let mut j = 0;
            while j < len {
                let mut code = [0u8; 1];
                read_exact(r, &mut code, name)?;
                let code = code[0] as usize;
                if code > 128 {
                    let run = code & 127;
                    let mut v = [0u8; 1];
                    read_exact(r, &mut v, name)?;
                    if j + run > len {
                        bail!("{name}: bad RGBE scanline (run overruns the {len}-pixel row)");
                    }
                    for p in &mut out[j..j + run] {
                        p[comp] = v[0];
                    }
                    j += run;
                } else {
                    if j + code > len {
                        bail!("{name}: bad RGBE scanline (literal overruns the {len}-pixel row)");
                    }
                    let mut lit = [0u8; 128];
                    read_exact(r, &mut lit[..code], name)?;
                    for (p, b) in out[j..j + code].iter_mut().zip(&lit[..code]) {
                        p[comp] = *b;
                    }
                    j += code;
                }
            }
        }
        return Ok(());
    }
    // Flat pixels, possibly with old-style (1,1,1,n) repeat markers.
    let mut j = 0;
    let mut shift = 0u32;
    let mut px = first;
    loop {
        let repeat = if px[0] == 1 && px[1] == 1 && px[2] == 1 {
            if j == 0 {
                bail!("{name}: bad RGBE scanline (repeat marker before any pixel)");
            }
            let count = (px[3] as usize).checked_shl(shift).unwrap_or(usize::MAX);
            if count > len - j {
                bail!("{name}: bad RGBE scanline (repeat overruns the {len}-pixel row)");
            }
            Some(count)
        } else {
            None
        };
        (j, shift) = crate::picture_rle::flat_step(out, j, shift, px, repeat);
        if j >= len {
            return Ok(());
        }
        read_exact(r, &mut px, name)?;
    }
}

/// Writes one scanline: new run-length encoding for 17…32767 pixels, flat otherwise.
pub fn write_scanline<W: Write + ?Sized>(w: &mut W, px: &[[u8; 4]]) -> std::io::Result<()> {
    let len = px.len();
    if !(MIN_RLE_LEN..=MAX_RLE_LEN).contains(&len) {
        for p in px {
            w.write_all(p)?;
        }
        return Ok(());
    }
    let mut out = Vec::with_capacity(len * 4 + 4);
    out.extend_from_slice(&[2, 2, (len >> 8) as u8, (len & 0xff) as u8]);
    let mut plane = vec![0u8; len];
    for comp in 0..4 {
        for (b, p) in plane.iter_mut().zip(px) {
            *b = p[comp];
        }
        encode_plane(&plane, &mut out);
    }
    w.write_all(&out)
}

/// Run-length encodes one component plane the way Radiance's writer does.
fn encode_plane(b: &[u8], out: &mut Vec<u8>) {
    let len = b.len();
    let mut j = 0;
    while j < len {
        // Find the next run of at least MIN_RUN equal bytes.
        let mut beg = j;
        let mut cnt = 1;
        while beg < len {
            cnt = 1;
            while cnt < 127 && beg + cnt < len && b[beg + cnt] == b[beg] {
                cnt += 1;
            }
            if cnt >= MIN_RUN {
                break;
            }
            beg += cnt;
        }
        if beg - j > 1 && beg - j < MIN_RUN {
            // A short run just before the long one.
            if b[j + 1..beg].iter().all(|&x| x == b[j]) {
                out.push((128 + beg - j) as u8);
                out.push(b[j]);
                j = beg;
            }
        }
        while j < beg {
            let n = (beg - j).min(128);
            out.push(n as u8);
            out.extend_from_slice(&b[j..j + n]);
            j += n;
        }
        if cnt >= MIN_RUN && beg < len {
            out.push((128 + cnt) as u8);
            out.push(b[beg]);
            j = beg + cnt;
        }
    }
}

fn read_exact<R: Read + ?Sized>(r: &mut R, buf: &mut [u8], name: &str) -> Result<()> {
    match r.read_exact(buf) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            bail!("{name}: unexpected end of data inside an RGBE scanline")
        }
        Err(e) => Err(anyhow::Error::new(e).context(format!("{name}: read error"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_matches_radiance_examples() {
        assert_eq!(encode([1.0, 1.0, 1.0]), [128, 128, 128, 129]);
        assert_eq!(decode([128, 128, 128, 129]), [1.00390625; 3]);
        assert_eq!(encode([0.0, -1.0, 1e-40]), [0, 0, 0, 0]);
        assert_eq!(decode([0, 0, 0, 0]), [0.0; 3]);
    }

    #[test]
    fn scanlines_round_trip_in_all_lengths() {
        for len in [1usize, 5, 16, 17, 20, 200, 300] {
            let px: Vec<[u8; 4]> = (0..len)
                .map(|i| {
                    let v = if (i / 7) % 2 == 0 {
                        10
                    } else {
                        (i % 251) as u8
                    };
                    [v, v / 2, 3, 130]
                })
                .collect();
            let mut buf = Vec::new();
            write_scanline(&mut buf, &px).unwrap();
            let mut back = vec![[0u8; 4]; len];
            read_scanline(&mut &buf[..], &mut back, "t").unwrap();
            assert_eq!(back, px, "len {len}");
        }
    }

    #[test]
    fn radiance_plane_example_encodes_identically() {
        // G plane of a verified 20-pixel row: 04 80 80 40 40 | 84 20 | 88 10 | 84 08
        let plane = [
            0x80, 0x80, 0x40, 0x40, 0x20, 0x20, 0x20, 0x20, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10,
            0x10, 0x10, 0x08, 0x08, 0x08, 0x08,
        ];
        let mut out = Vec::new();
        encode_plane(&plane, &mut out);
        assert_eq!(
            out,
            [0x04, 0x80, 0x80, 0x40, 0x40, 0x84, 0x20, 0x88, 0x10, 0x84, 0x08]
        );
    }

    #[test]
    fn old_style_repeats_decode() {
        let data = [5u8, 6, 7, 130, 1, 1, 1, 3, 9, 9, 9, 129];
        let mut out = vec![[0u8; 4]; 5];
        read_scanline(&mut &data[..], &mut out, "t").unwrap();
        assert_eq!(out[3], [5, 6, 7, 130]);
        assert_eq!(out[4], [9, 9, 9, 129]);
    }

    #[test]
    fn corrupt_run_lengths_are_errors() {
        let mut data = vec![2u8, 2, 0, 20];
        data.extend_from_slice(&[200, 1]); // run of 72 > 20
        let mut out = vec![[0u8; 4]; 20];
        let e = read_scanline(&mut &data[..], &mut out, "t").unwrap_err();
        assert!(e.to_string().contains("overruns"), "{e}");
    }
}
