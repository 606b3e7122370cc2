//! From a Radiance picture's RGB radiances to 8-bit display colours: a global tone map
//! (log-average exposure, gamma) and a false-colour luminance scale.

/// Radiance's luminous efficacy of its RGB white (lm/W): cd/m² per unit of brightness.
pub const EFFICACY: f64 = 179.0;

/// Radiance's brightness of an RGB radiance (its primaries' luminance weights).
pub fn brightness(p: [f32; 3]) -> f64 {
    0.265_074_126 * f64::from(p[0])
        + 0.670_114_631 * f64::from(p[1])
        + 0.064_811_243 * f64::from(p[2])
}

/// The false-colour scale: blue → cyan → green → yellow → red for t in [0, 1].
pub fn ramp(t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, 1.0) * 4.0;
    let k = (t.floor() as usize).min(3);
    let f = t - k as f64;
    let stops = [
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
    ];
    let (a, b) = (stops[k], stops[k + 1]);
    [
        a[0] + f * (b[0] - a[0]),
        a[1] + f * (b[1] - a[1]),
        a[2] + f * (b[2] - a[2]),
    ]
}

/// A colour in [0, 1] as 8-bit values (rounded).
pub fn to_u8(c: [f64; 3]) -> [u8; 3] {
    c.map(|x| (x * 255.0 + 0.5) as u8)
}

/// The luminance (cd/m²) below which 99% of the pixels lie (at least 1e-9); 1e-9 for no pixels.
pub fn luminance_p99(pixels: &[[f32; 3]]) -> f64 {
    let mut v: Vec<f64> = pixels.iter().map(|p| brightness(*p) * EFFICACY).collect();
    if v.is_empty() {
        return 1e-9;
    }
    let k = (v.len() * 99 / 100).min(v.len() - 1);
    let (_, x, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    x.max(1e-9)
}

/// The exposure multiplier that maps the log-average brightness of the lit pixels to 18%
/// grey (1 over 0.18 for a black picture).
pub fn auto_multiplier(pixels: &[[f32; 3]]) -> f64 {
    let (sum, n) = pixels
        .iter()
        .map(|p| brightness(*p))
        .filter(|l| *l > 0.0)
        .fold((0.0, 0usize), |(s, n), l| (s + l.ln(), n + 1));
    let avg = if n > 0 { (sum / n as f64).exp() } else { 1.0 };
    0.18 / avg
}

/// Each pixel times `mult`, clipped to [0, 1], raised to 1/`gamma`, as 8-bit values.
pub fn tone_map(pixels: &[[f32; 3]], mult: f64, gamma: f64) -> Vec<[u8; 3]> {
    pixels
        .iter()
        .map(|p| to_u8(p.map(|v| (f64::from(v) * mult).clamp(0.0, 1.0).powf(1.0 / gamma))))
        .collect()
}

/// Each pixel's luminance on the false-colour scale from 0 (blue) to `max` cd/m² (red).
pub fn false_colour(pixels: &[[f32; 3]], max: f64) -> Vec<[u8; 3]> {
    pixels
        .iter()
        .map(|p| to_u8(ramp(brightness(*p) * EFFICACY / max)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn p99_is_the_sorted_value() {
        let px: Vec<[f32; 3]> = (0..1000).rev().map(|i| [i as f32; 3]).collect();
        let l = |i: f64| brightness([i as f32; 3]) * EFFICACY;
        assert_eq!(luminance_p99(&px), l(990.0));
        assert_eq!(luminance_p99(&[]), 1e-9);
    }

    #[test]
    fn ramp_ends_and_exposure() {
        assert_eq!(to_u8(ramp(0.0)), [0, 0, 255]);
        assert_eq!(to_u8(ramp(0.5)), [0, 255, 0]);
        assert_eq!(to_u8(ramp(2.0)), [255, 0, 0]);
        let m = auto_multiplier(&[[1.0; 3], [4.0; 3], [0.0; 3]]);
        assert!((m - 0.09).abs() < 1e-6, "{m}");
        assert_eq!(tone_map(&[[10.0, 0.25, 0.0]], 1.0, 1.0), vec![[255, 64, 0]]);
    }
}
