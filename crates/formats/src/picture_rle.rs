//! Scanline coding of Radiance pictures: flat pixels, old-style repeat markers and
//! the newer per-component run-length encoding, read and written as Radiance does.
// Component-wise vector arithmetic reads most clearly with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::io::{self, Read, Write};

use crate::rgbe::Rgbe;

/// Shortest scanline written (and recognised) in the new run-length encoding.
pub const MINELEN: usize = 17;
/// Longest scanline the new encoding can describe.
pub const MAXELEN: usize = 0x7fff;
const MINRUN: usize = 4;

/// Why a scanline could not be decoded.
#[derive(Debug)]
pub enum ScanError {
    /// The data ended inside the scanline.
    Truncated,
    /// The run-length data does not fit the scanline (message says how).
    Corrupt(String),
    /// Reading failed.
    Io(io::Error),
}

impl std::fmt::Display for ScanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ScanError::Truncated => write!(f, "unexpected end of data"),
            ScanError::Corrupt(m) => write!(f, "{m}"),
            ScanError::Io(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for ScanError {}

fn byte(r: &mut impl Read) -> Result<u8, ScanError> {
    let mut b = [0u8; 1];
    match r.read_exact(&mut b) {
        Ok(()) => Ok(b[0]),
        Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => Err(ScanError::Truncated),
        Err(e) => Err(ScanError::Io(e)),
    }
}

fn pixel(r: &mut impl Read) -> Result<Rgbe, ScanError> {
    let mut b = [0u8; 4];
    match r.read_exact(&mut b) {
        Ok(()) => Ok(b),
        Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => Err(ScanError::Truncated),
        Err(e) => Err(ScanError::Io(e)),
    }
}

/// Reads one scanline of `scan.len()` pixels in whichever encoding it uses.
pub fn read_scanline(r: &mut impl Read, scan: &mut [Rgbe]) -> Result<(), ScanError> {
    let len = scan.len();
    if len == 0 {
        return Ok(());
    }
    if !(MINELEN..=MAXELEN).contains(&len) {
        return read_old(r, scan, 0);
    }
    let first = pixel(r)?;
    if first[0] != 2 || first[1] != 2 || first[2] & 0x80 != 0 {
        scan[0] = first;
        return read_old(r, scan, 1);
    }
    let n = (first[2] as usize) << 8 | first[3] as usize;
    if n != len {
        return Err(ScanError::Corrupt(format!(
            "scanline length {n} in run-length header, expected {len}"
        )));
    }
    for comp in 0..4 {
        let mut j = 0;
        while j < len {
            let code = byte(r)? as usize;
            if code > 128 {
                let cnt = code & 127;
                let val = byte(r)?;
                if j + cnt > len {
                    return Err(ScanError::Corrupt(format!(
                        "run of {cnt} at pixel {j} overruns scanline of {len}"
                    )));
                }
                for p in &mut scan[j..j + cnt] {
                    p[comp] = val;
                }
                j += cnt;
            } else {
                if j + code > len {
                    return Err(ScanError::Corrupt(format!(
                        "literal of {code} at pixel {j} overruns scanline of {len}"
                    )));
                }
                for p in &mut scan[j..j + code] {
                    p[comp] = byte(r)?;
                }
                j += code;
            }
        }
    }
    Ok(())
}

/// Flat pixels with `(1,1,1,n)` repeat markers, from position `start`.
fn read_old(r: &mut impl Read, scan: &mut [Rgbe], start: usize) -> Result<(), ScanError> {
    let len = scan.len();
    let mut j = start;
    let mut shift = 0u32;
    while j < len {
        let p = pixel(r)?;
        let repeat = if p[0] == 1 && p[1] == 1 && p[2] == 1 {
            if j == 0 {
                return Err(ScanError::Corrupt(
                    "repeat marker with no previous pixel".to_string(),
                ));
            }
            let cnt = if shift >= 24 {
                usize::MAX
            } else {
                (p[3] as usize) << shift
            };
            if cnt > len - j {
                return Err(ScanError::Corrupt(format!(
                    "repeat of {cnt} at pixel {j} overruns scanline of {len}"
                )));
            }
            Some(cnt)
        } else {
            None
        };
        (j, shift) = flat_step(scan, j, shift, p, repeat);
    }
    Ok(())
}

/// One step of decoding flat pixels at position `j` of `scan` with repeat shift `shift`:
/// for an old-style `(1,1,1,n)` marker (`repeat`, its checked count) the previous pixel
/// that many times, else pixel `p`. Returns the new position and shift.
#[inline]
pub(crate) fn flat_step(
    scan: &mut [Rgbe],
    j: usize,
    shift: u32,
    p: Rgbe,
    repeat: Option<usize>,
) -> (usize, u32) {
    match repeat {
        Some(count) => {
            let prev = scan[j - 1];
            scan[j..j + count].fill(prev);
            (j + count, shift + 8)
        }
        None => {
            scan[j] = p;
            (j + 1, 0)
        }
    }
}

/// Writes one scanline: new run-length encoding for 17..=32767 pixels, flat otherwise
/// (byte for byte what Radiance's writer produces).
pub fn write_scanline(w: &mut impl Write, scan: &[Rgbe]) -> io::Result<()> {
    let len = scan.len();
    if !(MINELEN..=MAXELEN).contains(&len) {
        let mut buf = Vec::with_capacity(len * 4);
        for p in scan {
            buf.extend_from_slice(p);
        }
        return w.write_all(&buf);
    }
    let mut out = Vec::with_capacity(len * 4 + 16);
    out.extend_from_slice(&[2, 2, (len >> 8) as u8, (len & 255) as u8]);
    for i in 0..4 {
        let c = |k: usize| scan[k][i];
        let mut j = 0;
        let mut cnt = 1;
        while j < len {
            let mut beg = j;
            while beg < len {
                cnt = 1;
                while cnt < 127 && beg + cnt < len && c(beg + cnt) == c(beg) {
                    cnt += 1;
                }
                if cnt >= MINRUN {
                    break;
                }
                beg += cnt;
            }
            if beg - j > 1 && beg - j < MINRUN && (j + 1..beg).all(|k| c(k) == c(j)) {
                out.push((128 + beg - j) as u8);
                out.push(c(j));
                j = beg;
            }
            while j < beg {
                let n = (beg - j).min(128);
                out.push(n as u8);
                for k in j..j + n {
                    out.push(c(k));
                }
                j += n;
            }
            if cnt >= MINRUN {
                out.push((128 + cnt) as u8);
                out.push(c(beg));
            } else {
                cnt = 0;
            }
            j += cnt;
        }
    }
    w.write_all(&out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(scan: &[Rgbe]) {
        let mut buf = Vec::new();
        write_scanline(&mut buf, scan).unwrap();
        let mut back = vec![[0u8; 4]; scan.len()];
        read_scanline(&mut buf.as_slice(), &mut back).unwrap();
        assert_eq!(back, scan);
    }

    #[test]
    fn radiance_example_green_plane() {
        // 20-pixel row from the format notes: G plane 04 80 80 40 40 | 84 20 | 88 10 | 84 08.
        let g = [
            0x80, 0x80, 0x40, 0x40, 0x20, 0x20, 0x20, 0x20, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10,
            0x10, 0x10, 0x08, 0x08, 0x08, 0x08,
        ];
        let scan: Vec<Rgbe> = g.iter().map(|&v| [0, v, 0, 0]).collect();
        let mut buf = Vec::new();
        write_scanline(&mut buf, &scan).unwrap();
        let gplane = &buf[4 + 2..4 + 2 + 12];
        assert_eq!(
            gplane,
            &[0x04, 0x80, 0x80, 0x40, 0x40, 0x84, 0x20, 0x88, 0x10, 0x84, 0x08, 0x94]
        );
        round_trip(&scan);
    }

    #[test]
    fn short_and_long_scanlines_round_trip() {
        for len in [1usize, 5, 16, 17, 18, 130, 300] {
            let scan: Vec<Rgbe> = (0..len)
                .map(|k| [(k / 7) as u8, (k % 3) as u8, 9, (k * 31 % 256) as u8])
                .collect();
            round_trip(&scan);
        }
    }

    #[test]
    fn old_style_repeats_decode() {
        let data = [5u8, 6, 7, 8, 1, 1, 1, 3, 9, 9, 9, 9];
        let mut scan = vec![[0u8; 4]; 5];
        read_scanline(&mut &data[..], &mut scan).unwrap();
        assert_eq!(
            scan,
            vec![[5, 6, 7, 8]; 4]
                .into_iter()
                .chain([[9, 9, 9, 9]])
                .collect::<Vec<_>>()
        );
    }

    #[test]
    fn corrupt_run_is_an_error() {
        let mut data = vec![2u8, 2, 0, 20, 128 + 30, 7];
        data.extend_from_slice(&[0; 40]);
        let mut scan = vec![[0u8; 4]; 20];
        let e = read_scanline(&mut data.as_slice(), &mut scan).unwrap_err();
        assert!(e.to_string().contains("overruns"), "{e}");
        let bad_len = [2u8, 2, 0, 21, 0];
        let e = read_scanline(&mut &bad_len[..], &mut scan).unwrap_err();
        assert!(e.to_string().contains("length"), "{e}");
        let short = [2u8, 2, 0, 20, 3, 1];
        assert!(matches!(
            read_scanline(&mut &short[..], &mut scan),
            Err(ScanError::Truncated)
        ));
    }
}
