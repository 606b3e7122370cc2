//! RGBE / XYZE pixel codec: a shared 8-bit exponent for three 8-bit mantissas,
//! converted exactly as Radiance's `setcolr` / `colr_color` do.

/// One encoded pixel: three mantissas and the shared exponent byte.
pub type Rgbe = [u8; 4];

/// Encodes a colour: truncating mantissas, negatives to 0, below 1e-32 to all zeros.
pub fn encode(c: [f32; 3]) -> Rgbe {
    encode_f64([c[0] as f64, c[1] as f64, c[2] as f64])
}

/// Encodes a colour given in double precision (as Radiance's `setcolr` takes it).
pub fn encode_f64(c: [f64; 3]) -> Rgbe {
    let d = c[0].max(c[1]).max(c[2]);
    if d.is_nan() || d <= 1e-32 {
        return [0; 4];
    }
    let (f, e) = frexp(d);
    let scale = f * 256.0 / d;
    let m = |x: f64| -> u8 {
        if x > 0.0 {
            // Truncation toward zero as C's (int) conversion; clamp guards overflow.
            (x * scale).min(255.0) as u8
        } else {
            0
        }
    };
    let ex = e + 128;
    if ex > 255 {
        // Beyond RGBE's range: saturate rather than wrap.
        return [255, 255, 255, 255];
    }
    if ex <= 0 {
        return [0; 4];
    }
    [m(c[0]), m(c[1]), m(c[2]), ex as u8]
}

/// Decodes a pixel: `(m + 0.5) * 2^(E - 136)`, all zeros when `E == 0`.
pub fn decode(p: Rgbe) -> [f32; 3] {
    if p[3] == 0 {
        return [0.0; 3];
    }
    let f = ldexp1(p[3] as i32 - 136);
    [
        ((p[0] as f64 + 0.5) * f) as f32,
        ((p[1] as f64 + 0.5) * f) as f32,
        ((p[2] as f64 + 0.5) * f) as f32,
    ]
}

/// `2^e` as a double for any exponent RGBE can produce (-136..=119).
fn ldexp1(e: i32) -> f64 {
    if e >= -1022 {
        f64::from_bits(((e + 1023) as u64) << 52)
    } else {
        2f64.powi(e)
    }
}

/// C's `frexp`: `d = f * 2^e` with `f` in [0.5, 1), for finite positive `d`.
pub fn frexp(d: f64) -> (f64, i32) {
    if d == 0.0 || !d.is_finite() {
        return (d, 0);
    }
    let bits = d.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    if exp == 0 {
        // Subnormal: scale up first.
        let (f, e) = frexp(d * 2f64.powi(64));
        return (f, e - 64);
    }
    let e = exp - 1022;
    let f = f64::from_bits((bits & !(0x7ffu64 << 52)) | (1022u64 << 52));
    (f, e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_encodes_and_decodes_as_radiance() {
        assert_eq!(encode([1.0, 1.0, 1.0]), [128, 128, 128, 129]);
        assert_eq!(decode([128, 128, 128, 129]), [1.0 + 1.0 / 256.0; 3]);
    }

    #[test]
    fn tiny_and_negative_values() {
        assert_eq!(encode([1e-33, 0.0, -1.0]), [0; 4]);
        assert_eq!(encode([-1.0, 0.5, 0.25])[0], 0);
        assert_eq!(decode([10, 20, 30, 0]), [0.0; 3]);
    }

    #[test]
    fn frexp_matches_definition() {
        for &d in &[1.0, 0.75, 3.0, 1e-30, 1e30, 5e-320] {
            let (f, e) = frexp(d);
            assert!((0.5..1.0).contains(&f), "{d}: {f}");
            assert_eq!(f * 2f64.powi(e + 64) * 2f64.powi(-64), d);
        }
    }

    #[test]
    fn round_trip_is_within_one_mantissa_step() {
        for &v in &[0.001f32, 0.3, 1.0, 7.5, 1234.5, 1e-20, 1e20] {
            let d = decode(encode([v, v * 0.5, v * 0.25]));
            assert!((d[0] - v).abs() <= v / 128.0, "{v} -> {d:?}");
        }
    }
}
