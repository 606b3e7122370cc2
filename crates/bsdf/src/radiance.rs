//! The matrices Radiance's `dctimestep` and `rmtxop` build from a BSDF XML file.
//!
//! Transmission (`rmtxop file.xml`, T of `dctimestep V T D s`):
//! * XML `Transmission Front` (light from the exterior into the room) is used when present and
//!   not all Lambertian (see below): `T[o][i] = BSDF[o][i] · λ_in(i)`, rows = outgoing (room
//!   side) patches of the RowAngleBasis, columns = incident patches of the ColumnAngleBasis.
//! * Otherwise XML `Transmission Back` by reciprocity:
//!   `T[r][c] = BSDF_back[rot(c)][rot(r)] · λ(c)`, rot = the same-ring patch rotated by 180°;
//!   rows follow the back block's incident basis, columns its outgoing basis (a front block that
//!   is all Lambertian is ignored then: found with the oracle).
//! * Neither (or only Lambertian parts): a 145×145 matrix `m · λ_Full(c)` where `m` is the
//!   Lambertian value (the front's when both are Lambertian; that case was not compared), zero if
//!   there is no transmission at all.
//!
//! Radiance splits each component's minimum off as a Lambertian part when it exceeds 0.01/π
//! (grey: the minimum of the position-scaled values (`jittered`), up to 3e-4 below the plain
//! minimum) and drops the remainder when its largest hemispherical total is ≤ 0.001. A kept
//! element is the part plus its remainder, a negative remainder (an element below the scaled
//! minimum) counted as zero: grey elements are `max(value, part)`.
//! Colour: with `CIE-X` and `CIE-Z` blocks Radiance keeps each element's CIE Y and stores its
//! chromaticity (u′, v′) quantised to steps of 1/410 with a dither: from the single-precision
//! (x, y) = (X, Y)/(X + Y + Z) of the float values, `k = trunc(410·u′ + r)` clamped to 0…255, r
//! from the C library's `drand48()` in its unseeded state (two numbers per element, u′ then v′).
//! The coloured components are encoded in the order XML `Reflection Back`, `Reflection Front`,
//! `Transmission Back`, `Transmission Front` (Radiance rf, rb, tf, tb), each element of a
//! component from the last stored index (`o·n_in + i`) down to the first, zero elements included
//! (as (1/3, 1/3)). The RGB value is the XYZ → RGB transform (Radiance's standard primaries,
//! equal-energy white) of (x/y·Y, Y, (1−x−y)/y·Y) from the decoded single-precision chromaticity;
//! grey Y without colour blocks. Colours outside the RGB gamut are desaturated towards the grey
//! of the same luminance until no channel is negative (found on remainders of a Lambertian split,
//! which the oracle shows clipped so).
//!
//! Coloured Lambertian split (Radiance's BSDF library, facts only): right after a coloured
//! component is encoded, every element's value (times Radiance's position factor
//! `1 + 6e-4·(d − ½)`) and decoded chromaticity are taken to Sharp RGB (the chromatic-adaptation
//! matrix of Süsstrunk, Holm and Finlayson, single precision) with each channel weighted by its
//! primary's luminance from Radiance's four-decimal Sharp → XYZ table. When the sum of the
//! per-channel minima exceeds 0.01/π, those minima are the Lambertian part (its colour through
//! that table, its Y their sum); every element keeps its value minus that sum as luminance, and
//! its remainder's colour is quantised again with two more `drand48()` numbers, incident patch in
//! the outer loop and outgoing patch in the inner one, unless the remainder's luminance is at
//! most 1e-5 (no numbers drawn). On `coloured_xml(dir, true)` (tests/bsdf_xml.rs) every channel
//! of every element agrees with the oracle within 4.1e-7. A remainder can be negative (an element
//! near the minimum with a position factor above 1): Radiance warns (`BTDF has 1 negatives`) and
//! counts it as zero, and so do we (a constant coloured matrix with one lowered element: within
//! 1.7e-7 of the oracle).
//!
//! Arithmetic of the oracle's build (read from its machine code; it is compiled with reordered
//! floating point and approximate reciprocals), reproduced because a quantised chromaticity can
//! sit on a code boundary: X + Y + Z in single precision and x, y = X, Y times [`fast_recip`] of
//! it; Sharp RGB → XYZ products and sums in single precision (a remainder near the smallest
//! position factor is a few float steps per channel: in double one element of a constant
//! coloured matrix got another u′ code, 1.5e-4 to 1.8e-3 off); the weighted green and blue
//! Sharp channels unweighted with [`fast_recip`], red with a division; decoding with
//! `(6u′ + 12) − 16v′`, Sharp RGB with `1 − (x + y)`, the position factor with
//! `(d − ½) − trunc(d)`. The Lambertian part's RGB is desaturated into the gamut like an
//! element's (constant colours outside the gamut: tests/bsdf_xml.rs). The reciprocal estimate
//! is the processor's own (`rcpss`, as the oracle's on the same machine); processors of
//! different makers differ in its last bits, so on a chromaticity exactly at a code boundary
//! the code (like Radiance's) can differ between machines; other architectures divide exactly.
//! Subnormal or huge sums, where the estimate is infinite or zero, are divided exactly.

use crate::klems::KlemsBasis;
use crate::model::{Bsdf, Direction, KlemsMatrix, Wavelength};

/// Radiance's threshold for splitting a matrix minimum off as a Lambertian part (sr⁻¹).
pub const LAMBERTIAN_MIN: f64 = 0.01 / std::f64::consts::PI;

/// For tensor trees Radiance splits the minimum off only below this value (sr⁻¹): π·min must
/// stay under 1.5 (found with the oracle on 2×2×2×2 trees: minimum 0.4774 split off as 150.0%,
/// 0.4775 and above nothing; Klems matrices have no such limit: 154.5% split off).
pub const TREE_LAMBERTIAN_MAX: f64 = 1.5 / std::f64::consts::PI;

/// The minimum Radiance splits off a grey matrix: the smallest single-precision value times
/// Radiance's position factor `1 + 6e-4·(d − ½)` (d the fraction of
/// `2·n_in/(i + 0.22545) + 4·n_out/(o + 0.70281)`), so up to 3e-4 below the plain minimum (found
/// with the oracle: a constant matrix of π·value 12.351% prints 12.3).
pub fn radiance_min(m: &KlemsMatrix) -> f64 {
    let (ni, no) = (m.incident.len(), m.outgoing.len());
    let mut min = 1e10f32;
    for i in 0..ni {
        for o in 0..no {
            min = min.min(jittered(m, o, i));
        }
    }
    f64::from(min)
}

/// An RGB matrix, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbMatrix {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// Values, `data[r * cols + c]`.
    pub data: Vec<[f64; 3]>,
}

impl RgbMatrix {
    /// A zero matrix.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        RgbMatrix {
            rows,
            cols,
            data: vec![[0.0; 3]; rows * cols],
        }
    }

    /// Element at (r, c).
    pub fn get(&self, r: usize, c: usize) -> [f64; 3] {
        self.data[r * self.cols + c]
    }
}

/// Why a BSDF cannot be turned into a matrix.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MatrixError {
    /// The file holds tensor-tree transmission data.
    #[error("unsupported BSDF: tensor-tree data cannot be used as a Klems matrix")]
    TensorTree,
    /// A colour block's basis differs from its Visible block's.
    #[error("{0}: CIE-X/CIE-Z block bases differ from the Visible block's")]
    ColourBasis(&'static str),
}

/// CIE XYZ → RGB for Radiance's standard primaries (R .640 .330, G .290 .600, B .150 .060,
/// white = equal energy 1/3 1/3).
pub fn xyz_to_rgb_matrix() -> [[f64; 3]; 3] {
    inv3(&rgb_to_xyz_matrix())
}

/// RGB → CIE XYZ for the same primaries: rows X, Y, Z, each summing to 1 (a grey is X = Y = Z).
pub fn rgb_to_xyz_matrix() -> [[f64; 3]; 3] {
    let prim = [(0.640, 0.330), (0.290, 0.600), (0.150, 0.060)];
    let (wx, wy) = (1.0 / 3.0, 1.0 / 3.0);
    // Columns: XYZ of each primary with Y = 1, scaled so R+G+B = white (Y_w = 1).
    let col = |(x, y): (f64, f64)| [x / y, 1.0, (1.0 - x - y) / y];
    let p = [col(prim[0]), col(prim[1]), col(prim[2])];
    let m = [
        [p[0][0], p[1][0], p[2][0]],
        [p[0][1], p[1][1], p[2][1]],
        [p[0][2], p[1][2], p[2][2]],
    ];
    let w = [wx / wy, 1.0, (1.0 - wx - wy) / wy];
    let s = mul3(&inv3(&m), w);
    [
        [m[0][0] * s[0], m[0][1] * s[1], m[0][2] * s[2]],
        [m[1][0] * s[0], m[1][1] * s[1], m[1][2] * s[2]],
        [m[2][0] * s[0], m[2][1] * s[1], m[2][2] * s[2]],
    ]
}

fn mul3(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

fn inv3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let c = |a: usize, b: usize, c: usize, d: usize| m[a][b] * m[c][d];
    [
        [
            (c(1, 1, 2, 2) - c(1, 2, 2, 1)) / det,
            (c(0, 2, 2, 1) - c(0, 1, 2, 2)) / det,
            (c(0, 1, 1, 2) - c(0, 2, 1, 1)) / det,
        ],
        [
            (c(1, 2, 2, 0) - c(1, 0, 2, 2)) / det,
            (c(0, 0, 2, 2) - c(0, 2, 2, 0)) / det,
            (c(0, 2, 1, 0) - c(0, 0, 1, 2)) / det,
        ],
        [
            (c(1, 0, 2, 1) - c(1, 1, 2, 0)) / det,
            (c(0, 1, 2, 0) - c(0, 0, 2, 1)) / det,
            (c(0, 0, 1, 1) - c(0, 1, 1, 0)) / det,
        ],
    ]
}

/// Desaturates `rgb` towards the grey of luminance `y` until no channel is negative.
pub(crate) fn clip_gamut(rgb: [f64; 3], y: f64) -> [f64; 3] {
    let mut t = 1.0f64;
    for v in rgb {
        if v < 0.0 && y - v > 0.0 {
            t = t.min(y / (y - v));
        }
    }
    if t < 1.0 {
        rgb.map(|v| (y + t * (v - y)).max(0.0))
    } else {
        rgb
    }
}

/// CIE XYZ of a colour given as a quantised (u′, v′) pair and a luminance; `None` when the
/// chromaticity is degenerate.
fn chroma_xyz(code: (f64, f64), y: f64) -> Option<[f64; 3]> {
    let (cx, cy) = decode_xy(code);
    (cy > 0.0).then(|| {
        let (x, yy) = (f64::from(cx), f64::from(cy));
        [f64::from(cx / cy) * y, y, (1.0 - x - yy) / yy * y]
    })
}

/// The C library's `drand48()` generator (48-bit linear congruential, glibc's unseeded state 0).
#[derive(Clone, Debug, Default)]
pub struct Drand48 {
    state: u64,
}

impl Drand48 {
    /// The generator in its unseeded state.
    pub const fn new() -> Self {
        Drand48 { state: 0 }
    }

    /// The next number in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        const A: u64 = 0x5_DEEC_E66D;
        const MASK: u64 = (1 << 48) - 1;
        self.state = (A.wrapping_mul(self.state).wrapping_add(0xB)) & MASK;
        self.state as f64 / (1u64 << 48) as f64
    }
}

/// Steps per unit of u′ and v′ in Radiance's chromaticity encoding.
const UV_STEPS: f64 = 410.0;

/// Radiance's XYZ → Sharp RGB matrix, as it stores it (single precision).
const XYZ_TO_SHARP_F: [[f32; 3]; 3] = [
    [1.2694, -0.0988, -0.1706],
    [-0.8364, 1.8006, 0.0357],
    [0.0297, -0.0315, 1.0018],
];

/// Radiance's Sharp RGB → XYZ matrix: its own four-decimal table (single precision), not the
/// exact inverse of [`XYZ_TO_SHARP_F`].
pub(crate) const XYZ_FROM_SHARP_F: [[f32; 3]; 3] = [
    [0.8156, 0.0472, 0.1372],
    [0.3791, 0.5769, 0.0440],
    [-0.0123, 0.0167, 0.9955],
];

/// `1/s` as the oracle's build of Radiance's BSDF library computes it (compiled with
/// approximate reciprocals): the processor's `rcpss` estimate `r` refined by one Newton step
/// `2r − s·r·r`, in single precision. On x86-64 this uses the processor's own estimate, as the
/// oracle does on the same machine; elsewhere the exact quotient.
pub(crate) fn fast_recip(s: f32) -> f32 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtss_f32, _mm_rcp_ss, _mm_set_ss};
        // SAFETY: SSE is part of the x86-64 baseline, so these instructions always exist.
        let r = unsafe { _mm_cvtss_f32(_mm_rcp_ss(_mm_set_ss(s))) };
        (r + r) - (s * r) * r
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        1.0 / s
    }
}

/// Sharp RGB channels divided by their primaries' luminance weights as the oracle's build does
/// it: the red channel by a division, green and blue times [`fast_recip`] of the weight.
fn unweight(c: [f32; 3]) -> [f32; 3] {
    let w = XYZ_FROM_SHARP_F[1];
    [
        c[0] / w[0],
        c[1] * fast_recip(w[1]),
        c[2] * fast_recip(w[2]),
    ]
}

/// Quantised (u′, v′) indices of a CIE (x, y) chromaticity (single precision, as Radiance
/// keeps it) with two dither numbers, u′ first; indices truncated and clamped to 0…255.
fn encode_xy(cx: f32, cy: f32, rng: &mut Drand48) -> (f64, f64) {
    let (cx, cy) = (f64::from(cx), f64::from(cy));
    let df = UV_STEPS / (-2.0 * cx + 12.0 * cy + 3.0);
    let ub = (4.0 * cx * df + rng.next_f64()) as i32;
    let vb = (9.0 * cy * df + rng.next_f64()) as i32;
    (f64::from(ub.clamp(0, 255)), f64::from(vb.clamp(0, 255)))
}

/// CIE (x, y) (single precision) of quantised (u′, v′) indices, as Radiance decodes them.
fn decode_xy((ub, vb): (f64, f64)) -> (f32, f32) {
    let (up, vp) = (ub * (1.0 / UV_STEPS), vb * (1.0 / UV_STEPS));
    // (6u′ + 12) − 16v′: the order of the oracle's build
    let df = 1.0 / ((6.0 * up + 12.0) - 16.0 * vp);
    ((9.0 * up * df) as f32, (4.0 * vp * df) as f32)
}

/// Sharp RGB (single precision) of chromaticity (x, y) at luminance `y`.
pub(crate) fn to_sharp((cx, cy): (f32, f32), y: f64) -> [f32; 3] {
    let xyz = [
        f64::from(cx / cy) * y,
        y,
        // 1 − (x + y): the order of the oracle's build
        (1.0 - (f64::from(cx) + f64::from(cy))) / f64::from(cy) * y,
    ];
    XYZ_TO_SHARP_F.map(|r| {
        (f64::from(r[0]) * xyz[0] + f64::from(r[1]) * xyz[1] + f64::from(r[2]) * xyz[2]) as f32
    })
}

/// Luminance and chromaticity of a Sharp RGB colour (Radiance's table); the chromaticity is
/// `None` (Radiance's default white) when the luminance is at most 1e-6.
pub(crate) fn from_sharp(c: [f32; 3]) -> (f64, Option<(f32, f32)>) {
    // Single-precision table times single-precision channels: Radiance's products and sums are
    // float arithmetic, widened to double only for the result.
    let row = |r: [f32; 3]| f64::from(r[0] * c[0] + r[1] * c[1] + r[2] * c[2]);
    let y = row(XYZ_FROM_SHARP_F[1]);
    if y <= 1e-6 {
        return (y, None);
    }
    let (x, z) = (row(XYZ_FROM_SHARP_F[0]), row(XYZ_FROM_SHARP_F[2]));
    let sf = 1.0 / (x + y + z);
    (y, Some(((x * sf) as f32, (y * sf) as f32)))
}

/// Dithered (u′, v′) lattice indices of every element of a coloured component, indexed
/// `o · n_in + i`: Radiance's chromaticity x/(X+Y+Z), y/(X+Y+Z) of the single-precision values
/// (1/3, 1/3 for a zero element), elements from the last stored index down to the first.
/// Single-precision sum and [`fast_recip`] as the oracle's build computes them: with a double
/// sum and division, constant XYZ (0.1, 0.2, 0.3) gives u′ 40.9999989·… instead of 41.0000005
/// and two elements get the u′ code 40 (found in the oracle's machine code).
fn encode_chroma(
    y: &KlemsMatrix,
    x: &KlemsMatrix,
    z: &KlemsMatrix,
    rng: &mut Drand48,
) -> Vec<(f64, f64)> {
    let (ni, no) = (y.incident.len(), y.outgoing.len());
    let mut out = vec![(0.0, 0.0); ni * no];
    for k in (0..ni * no).rev() {
        let (o, i) = (k / ni, k % ni);
        let [xv, yv, zv] = [x.get(o, i), y.get(o, i), z.get(o, i)].map(|v| v.max(0.0) as f32);
        // The oracle's build sums in single precision and divides by multiplying with the
        // processor's approximate reciprocal after one Newton step ([`fast_recip`]).
        let sum = xv + yv + zv;
        let (cx, cy) = if sum.is_normal() && sum < 1e37 {
            let r = fast_recip(sum);
            (xv * r, yv * r)
        } else if sum > 0.0 {
            // subnormal or huge sums (the estimate would be infinite or zero, and the Newton
            // step NaN): the exact quotient of the values as read
            let (xd, yd, zd) = (
                x.get(o, i).max(0.0),
                y.get(o, i).max(0.0),
                z.get(o, i).max(0.0),
            );
            let t = xd + yd + zd;
            ((xd / t) as f32, (yd / t) as f32)
        } else {
            ((1.0f64 / 3.0) as f32, (1.0f64 / 3.0) as f32)
        };
        out[k] = encode_xy(cx, cy, rng);
    }
    out
}

/// Element (o, i) of a Klems matrix as Radiance's loader holds it: the value (negative read as 0)
/// in single precision, times a position factor `1 + 6e-4·(d − ½)` that keeps equal elements
/// apart, d the fraction of `2·n_in/(i + 0.22545) + 4·n_out/(o + 0.70281)`, rounded to single
/// precision again (found with the oracle: a constant matrix of π·value 12.351% gives a
/// Lambertian 12.3%).
pub(crate) fn jittered(m: &KlemsMatrix, o: usize, i: usize) -> f32 {
    let (ni, no) = (m.incident.len(), m.outgoing.len());
    let d = (2 * ni) as f64 / (i as f64 + 0.22545) + (4 * no) as f64 / (o as f64 + 0.70281);
    // The oracle's build computes the fraction minus ½ as (d − ½) − trunc(d).
    let f = (d - 0.5) - d.trunc();
    (f64::from(m.get(o, i).max(0.0) as f32) * (1.0 + 6e-4 * f)) as f32
}

/// A coloured component's Lambertian split, as Radiance does it: each element's value
/// ([`jittered`]) taken to Sharp RGB with each channel
/// weighted by its primary's luminance (Radiance's four-decimal table); the per-channel minima
/// are the Lambertian part when their sum exceeds 0.01/π. Each remainder (incident patch in the
/// outer loop) is quantised again with two dither numbers, unless its luminance is at most
/// 1e-5 (then its chromaticity is kept and nothing is drawn); its luminance is the value minus
/// that sum. `None` without a split; otherwise the remainders' luminances and the Lambertian
/// part's CIE XYZ.
fn split_colour(
    y: &KlemsMatrix,
    chroma: &mut [(f64, f64)],
    rng: &mut Drand48,
) -> Option<(Vec<f64>, [f64; 3])> {
    let w = XYZ_FROM_SHARP_F[1];
    let (ni, no) = (y.incident.len(), y.outgoing.len());
    let coef = |chroma: &[(f64, f64)], i: usize, o: usize| -> [f32; 3] {
        let k = o * ni + i;
        let v = jittered(y, o, i);
        let s = to_sharp(decode_xy(chroma[k]), f64::from(v));
        [s[0] * w[0], s[1] * w[1], s[2] * w[2]]
    };
    let mut min = [1e10f32; 3];
    for i in 0..ni {
        for o in 0..no {
            let c = coef(chroma, i, o);
            for ch in 0..3 {
                min[ch] = min[ch].min(c[ch]);
            }
        }
    }
    let ymin = 0.0f32 + min[2] + min[1] + min[0];
    if ymin.is_nan() || f64::from(ymin) <= 0.01 / std::f64::consts::PI {
        return None;
    }
    let mut rest = vec![0.0; ni * no];
    for i in 0..ni {
        for o in 0..no {
            let k = o * ni + i;
            let c = coef(chroma, i, o);
            let r = unweight([0, 1, 2].map(|ch| c[ch] - min[ch]));
            if let (lum, Some((cx, cy))) = from_sharp(r) {
                if lum > 1e-5 {
                    chroma[k] = encode_xy(cx, cy, rng);
                }
            }
            rest[k] = f64::from(y.values[k].max(0.0) as f32 - ymin);
        }
    }
    let (_, lxy) = from_sharp(unweight(min));
    let (cx, cy) = lxy.map_or((1.0 / 3.0, 1.0 / 3.0), |(x, y)| {
        (f64::from(x), f64::from(y))
    });
    let yl = f64::from(ymin);
    Some((rest, [cx / cy * yl, yl, (1.0 - cx - cy) / cy * yl]))
}

/// Colour of a component: quantised chromaticity per element and, after a Lambertian split,
/// the remainders' luminances and the Lambertian part's RGB.
struct Colour {
    chroma: Vec<(f64, f64)>,
    remainder: Option<Vec<f64>>,
    /// RGB of the Lambertian part, desaturated into the RGB gamut as Radiance converts it.
    lambertian: [f64; 3],
    /// CIE XYZ of the Lambertian part.
    lambertian_xyz: [f64; 3],
}

/// Colour value (RGB) of element (o, i) of a component: grey Y, or Y with the component's
/// quantised chromaticity (plus the Lambertian part split off a coloured component).
struct Component<'a> {
    y: &'a KlemsMatrix,
    colour: Option<Colour>,
    m: [[f64; 3]; 3],
    /// The Lambertian part split off a grey component (0 without a split).
    grey_lamb: f64,
}

impl Component<'_> {
    /// The matrix `M[o][i] = RGB[o][i] · λ_in(i)` (rows outgoing, columns incident patches).
    fn weighted_matrix(&self) -> RgbMatrix {
        let (ni, no) = (self.y.incident.len(), self.y.outgoing.len());
        let lam = self.y.incident.lambdas();
        let mut m = RgbMatrix::zeros(no, ni);
        for o in 0..no {
            for (i, l) in lam.iter().enumerate() {
                let v = self.rgb(o, i);
                m.data[o * ni + i] = [v[0] * l, v[1] * l, v[2] * l];
            }
        }
        m
    }

    fn rgb(&self, o: usize, i: usize) -> [f64; 3] {
        let k = o * self.y.incident.len() + i;
        let y = self.y.values[k];
        let Some(c) = &self.colour else {
            // Lambertian part plus the remainder, a negative remainder counted as zero.
            return [y.max(self.grey_lamb); 3];
        };
        let yr = c.remainder.as_ref().map_or(y, |r| r[k]);
        // A remainder below zero (the split-off minimum is taken over position-scaled values, the
        // remainder from the plain one) counts as zero, as Radiance 6.0a sets it ("BTDF has 1
        // negatives" on stderr; tests/bsdf_xml.rs).
        let base = if yr <= 0.0 {
            [0.0; 3]
        } else {
            match chroma_xyz(c.chroma[k], yr) {
                Some(xyz) => clip_gamut(mul3(&self.m, xyz), yr),
                None => [yr; 3],
            }
        };
        [
            base[0] + c.lambertian[0],
            base[1] + c.lambertian[1],
            base[2] + c.lambertian[2],
        ]
    }

    /// RGB of the Lambertian part split off (grey: the matrix minimum when above 0.01/π;
    /// coloured: from the sharp-RGB minima), with whether the remainder is kept (its largest
    /// hemispherical total exceeds 0.001).
    fn split(&self) -> ([f64; 3], bool) {
        match &self.colour {
            Some(Colour {
                remainder: Some(rest),
                lambertian,
                ..
            }) => {
                let m = self.y;
                let keep = (0..m.incident.len()).any(|i| {
                    let h: f64 = (0..m.outgoing.len())
                        .map(|o| {
                            rest[o * m.incident.len() + i].max(0.0)
                                * m.outgoing.projected_solid_angle(o).unwrap_or(0.0)
                        })
                        .sum();
                    h > 0.001
                });
                (*lambertian, keep)
            }
            _ => {
                let (lamb, keep) = lambertian_split(self.y);
                ([lamb; 3], keep)
            }
        }
    }
}

/// The order in which Radiance encodes the coloured components (rf, rb, tf, tb).
const ENCODE_ORDER: [Direction; 4] = [
    Direction::ReflectionBack,
    Direction::ReflectionFront,
    Direction::TransmissionBack,
    Direction::TransmissionFront,
];

/// What Radiance's loader makes of one direction of a BSDF.
enum Slot<'a> {
    /// No visible-light Klems or tree block.
    Absent,
    /// A tensor tree (no matrix).
    Tree,
    /// CIE-X/CIE-Z blocks on other bases than the Y block.
    BadBasis,
    /// A Klems component.
    Klems(Component<'a>),
}

/// Every component of `b` as Radiance's loader prepares it, encoding the colour of each
/// coloured component with `rng` in rf rb tf tb order (whichever component is asked for
/// afterwards); indexed like [`ENCODE_ORDER`].
fn encode_all<'a>(b: &'a Bsdf, rng: &mut Drand48) -> [Slot<'a>; 4] {
    ENCODE_ORDER.map(|dir| {
        let Some(blk) = b.block(dir, &Wavelength::Visible) else {
            return Slot::Absent;
        };
        let y = match &blk.data {
            crate::model::BlockData::Klems(m) => m,
            crate::model::BlockData::Tree(_) => return Slot::Tree,
        };
        let x = b.klems(dir, &Wavelength::CieX);
        let z = b.klems(dir, &Wavelength::CieZ);
        let same = |m: Option<&KlemsMatrix>| {
            m.is_none_or(|m| m.incident == y.incident && m.outgoing == y.outgoing)
        };
        if !same(x) || !same(z) {
            return Slot::BadBasis;
        }
        let m = xyz_to_rgb_matrix();
        let colour = match (x, z) {
            (Some(x), Some(z)) => {
                let mut chroma = encode_chroma(y, x, z, rng);
                let (remainder, lambertian_xyz) = match split_colour(y, &mut chroma, rng) {
                    Some((rest, xyz)) => (Some(rest), xyz),
                    None => (None, [0.0; 3]),
                };
                // Radiance turns the Lambertian part into RGB with the same gamut clipping as an
                // element's colour (an out-of-gamut constant colour: channels near zero, not
                // negative, in the oracle's matrix).
                let lambertian = clip_gamut(mul3(&m, lambertian_xyz), lambertian_xyz[1]);
                Some(Colour {
                    chroma,
                    remainder,
                    lambertian,
                    lambertian_xyz,
                })
            }
            _ => None,
        };
        let grey_lamb = if colour.is_none() {
            lambertian_split(y).0
        } else {
            0.0
        };
        Slot::Klems(Component {
            y,
            colour,
            m,
            grey_lamb,
        })
    })
}

/// A Klems component as Radiance's renderer holds it after loading: the Lambertian part split
/// off (RGB and Y, BSDF values in sr⁻¹) and the remainder (Y per element, `o·n_in + i`,
/// negatives as zero; `None` when Radiance drops it) with each remainder element's RGB
/// (`None` for a grey component).
#[derive(Debug, Clone, PartialEq)]
pub struct RenderComponent {
    /// RGB of the Lambertian part (sr⁻¹).
    pub lambertian: [f64; 3],
    /// CIE Y of the Lambertian part (sr⁻¹).
    pub lambertian_y: f64,
    /// The non-diffuse remainder's Y.
    pub remainder: Option<KlemsMatrix>,
    /// The remainder's RGB per element (same order as its values).
    pub rgb: Option<Vec<[f64; 3]>>,
}

/// The four components of `b` as Radiance's renderer loads them (colour dither from a fresh
/// generator), in Radiance's rf rb tf tb order (XML `Reflection Back`, `Reflection Front`,
/// `Transmission Back`, `Transmission Front`); `None` where there is no Klems block. Colour
/// blocks on another basis than the Y block are ignored (grey).
pub fn render_components(b: &Bsdf) -> [Option<RenderComponent>; 4] {
    let slots = encode_all(b, &mut Drand48::default());
    let mut out: [Option<RenderComponent>; 4] = [None, None, None, None];
    for (k, slot) in slots.into_iter().enumerate() {
        let y = match &slot {
            Slot::Klems(c) => c.y,
            Slot::BadBasis => match b.klems(ENCODE_ORDER[k], &Wavelength::Visible) {
                Some(y) => y,
                None => continue,
            },
            _ => continue,
        };
        let colour = match &slot {
            Slot::Klems(c) => c.colour.as_ref().map(|col| (c, col)),
            _ => None,
        };
        out[k] = Some(match colour {
            None => {
                let (lamb, keep) = lambertian_split(y);
                let remainder = keep.then(|| {
                    let mut r = y.clone();
                    for v in &mut r.values {
                        *v = (*v - lamb).max(0.0);
                    }
                    r
                });
                RenderComponent {
                    lambertian: [lamb; 3],
                    lambertian_y: lamb,
                    remainder,
                    rgb: None,
                }
            }
            Some((c, col)) => {
                let (_, keep) = c.split();
                let split = col.remainder.is_some();
                let rest: Vec<f64> = col
                    .remainder
                    .clone()
                    .unwrap_or_else(|| y.values.clone())
                    .into_iter()
                    .map(|v| v.max(0.0))
                    .collect();
                let rgb: Vec<[f64; 3]> = rest
                    .iter()
                    .enumerate()
                    .map(|(k, &yr)| {
                        if yr <= 0.0 {
                            return [0.0; 3];
                        }
                        match chroma_xyz(col.chroma[k], yr) {
                            Some(xyz) => clip_gamut(mul3(&c.m, xyz), yr),
                            None => [yr; 3],
                        }
                    })
                    .collect();
                let remainder = keep.then(|| {
                    let mut r = y.clone();
                    r.values = rest;
                    r
                });
                RenderComponent {
                    lambertian: if split { col.lambertian } else { [0.0; 3] },
                    lambertian_y: if split { col.lambertian_xyz[1] } else { 0.0 },
                    rgb: remainder.as_ref().map(|_| rgb),
                    remainder,
                }
            }
        });
    }
    out
}

/// Component `d` out of [`encode_all`]'s result.
fn take<'a>(slots: &mut [Slot<'a>; 4], d: Direction) -> Result<Option<Component<'a>>, MatrixError> {
    let k = ENCODE_ORDER.iter().position(|&e| e == d).unwrap_or(0);
    match std::mem::replace(&mut slots[k], Slot::Absent) {
        Slot::Absent => Ok(None),
        Slot::Tree => Err(MatrixError::TensorTree),
        Slot::BadBasis => Err(MatrixError::ColourBasis(d.xml_name())),
        Slot::Klems(c) => Ok(Some(c)),
    }
}

/// Radiance's load sequence for `b` (colour encoding and Lambertian split of every coloured Klems
/// component, rf rb tf tb order) with the dither drawn from `rng`: per XML direction, the CIE XYZ
/// (sr⁻¹) of the coloured Lambertian part split off. `rng` ends where Radiance's would after
/// loading the file (a process keeps one generator for all the files it loads).
pub fn colour_lambertians(b: &Bsdf, rng: &mut Drand48) -> Vec<(Direction, [f64; 3])> {
    let slots = encode_all(b, rng);
    let mut out = Vec::new();
    for (d, slot) in ENCODE_ORDER.into_iter().zip(&slots) {
        let Slot::Klems(c) = slot else { continue };
        if let Some(col) = c.colour.as_ref().filter(|c| c.remainder.is_some()) {
            out.push((d, col.lambertian_xyz));
        }
    }
    out
}

/// Lambertian value Radiance splits off a grey matrix (the minimum of the position-scaled
/// values, [`radiance_min`], when above 0.01/π), and whether the remainder is kept
/// (largest hemispherical total of the remainder, negative elements counted as zero, above
/// 0.001).
pub fn lambertian_split(m: &KlemsMatrix) -> (f64, bool) {
    let min = radiance_min(m);
    let lamb = if min > LAMBERTIAN_MIN { min } else { 0.0 };
    let keep = (0..m.incident.len()).any(|i| {
        let h: f64 = (0..m.outgoing.len())
            .map(|o| {
                (m.get(o, i) - lamb).max(0.0) * m.outgoing.projected_solid_angle(o).unwrap_or(0.0)
            })
            .sum();
        h > 0.001
    });
    (lamb, keep)
}

/// The transmission matrix Radiance's `dctimestep`/`rmtxop` build from this BSDF (colour
/// dither from a fresh generator, as the first BSDF a Radiance process loads).
pub fn transmission_matrix(b: &Bsdf) -> Result<RgbMatrix, MatrixError> {
    transmission_matrix_with(b, &mut Drand48::default())
}

#[allow(clippy::needless_range_loop)] // index arithmetic mirrors the formulas
/// [`transmission_matrix`] with the colour dither drawn from `rng` (a Radiance process keeps
/// one generator for all the BSDFs it loads).
pub fn transmission_matrix_with(b: &Bsdf, rng: &mut Drand48) -> Result<RgbMatrix, MatrixError> {
    // Radiance encodes every component once on load
    let mut slots = encode_all(b, rng);
    let tb = take(&mut slots, Direction::TransmissionFront)?;
    let mut tb_lamb = None;
    if let Some(tb) = tb {
        let (lamb, keep) = tb.split();
        if keep {
            return Ok(tb.weighted_matrix());
        }
        tb_lamb = Some(lamb);
    }
    // Without `Transmission Front`, or with one that is all Lambertian (Radiance then takes
    // `Transmission Back` alone: found with the oracle on a constant grey front block).
    if let Some(tf) = take(&mut slots, Direction::TransmissionBack)? {
        let (lamb, keep) = tf.split();
        if keep {
            let (ni, no) = (tf.y.incident.len(), tf.y.outgoing.len());
            // Rows of T: tf incident patches; columns: tf outgoing patches.
            let lam = tf.y.outgoing.lambdas();
            let rot_in: Vec<usize> = (0..ni)
                .map(|r| tf.y.incident.rotate180(r).unwrap_or(r))
                .collect();
            let rot_out: Vec<usize> = (0..no)
                .map(|c| tf.y.outgoing.rotate180(c).unwrap_or(c))
                .collect();
            let mut t = RgbMatrix::zeros(ni, no);
            for r in 0..ni {
                for c in 0..no {
                    let v = tf.rgb(rot_out[c], rot_in[r]);
                    let l = lam[c];
                    t.data[r * no + c] = [v[0] * l, v[1] * l, v[2] * l];
                }
            }
            return Ok(t);
        }
        // Both all Lambertian: the front's part (not compared with Radiance).
        return Ok(lambertian_only(tb_lamb.unwrap_or(lamb)));
    }
    Ok(lambertian_only(tb_lamb.unwrap_or([0.0; 3])))
}

#[allow(clippy::needless_range_loop)]
fn lambertian_only(value: [f64; 3]) -> RgbMatrix {
    let full = KlemsBasis::full();
    let lam = full.lambdas();
    let n = full.len();
    let mut t = RgbMatrix::zeros(n, n);
    for r in 0..n {
        for c in 0..n {
            t.data[r * n + c] = value.map(|v| v * lam[c]);
        }
    }
    t
}

/// The reflection matrix of `rmtxop -rf` (`front` = Radiance front = room side = XML
/// `Reflection Back`) or `-rb` (XML `Reflection Front`): `R[o][i] = BSDF[o][i] · λ_in(i)`.
/// `None` when the file has no such block.
pub fn reflection_matrix(b: &Bsdf, front: bool) -> Result<Option<RgbMatrix>, MatrixError> {
    reflection_matrix_with(b, front, &mut Drand48::default())
}

/// [`reflection_matrix`] with the colour dither drawn from `rng`.
pub fn reflection_matrix_with(
    b: &Bsdf,
    front: bool,
    rng: &mut Drand48,
) -> Result<Option<RgbMatrix>, MatrixError> {
    let d = if front {
        Direction::ReflectionBack
    } else {
        Direction::ReflectionFront
    };
    let Some(r) = take(&mut encode_all(b, rng), d)? else {
        return Ok(None);
    };
    Ok(Some(r.weighted_matrix()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::KlemsBasis;

    fn constant(v: f64) -> KlemsMatrix {
        let b = KlemsBasis::quarter();
        KlemsMatrix {
            incident: b.clone(),
            outgoing: b.clone(),
            values: vec![v; b.len() * b.len()],
        }
    }

    /// Subnormal and huge X+Y+Z sums give the grey codes of ordinary values (no NaN, no
    /// silent zero chromaticity from an infinite or flushed reciprocal estimate).
    #[test]
    fn extreme_sums_give_finite_codes() {
        let (x, y, z) = (constant(0.3), constant(0.3), constant(0.3));
        let want = encode_chroma(&y, &x, &z, &mut Drand48::new());
        for v in [1e-40, 1e-44, 3e38, 1e300] {
            let (x, y, z) = (constant(v), constant(v), constant(v));
            let got = encode_chroma(&y, &x, &z, &mut Drand48::new());
            assert_eq!(got, want, "X = Y = Z = {v:e}");
        }
    }
}
