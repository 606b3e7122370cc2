//! The matrices Radiance's `dctimestep` and `rmtxop` build from a BSDF XML file.
//!
//! Transmission (`rmtxop file.xml`, T of `dctimestep V T D s`):
//! * XML `Transmission Front` (Radiance `tb`, light from the exterior into the room) is used when
//!   present: `T[o][i] = BSDF[o][i] · λ_in(i)`, rows = outgoing (room side) patches of the
//!   RowAngleBasis, columns = incident patches of the ColumnAngleBasis.
//! * Otherwise XML `Transmission Back` (`tf`) by reciprocity:
//!   `T[r][c] = BSDF_tf[rot(c)][rot(r)] · λ(c)`, rot = the same-ring patch rotated by 180°;
//!   rows follow the tf incident basis, columns its outgoing basis.
//! * Neither (or only a Lambertian remainder, see below): a 145×145 matrix `m · λ_Full(c)`
//!   where `m` is the Lambertian (minimum) value, zero if there is no transmission at all.
//!
//! Radiance splits each component's minimum off as a Lambertian part when it exceeds 0.01/π and
//! drops the remainder when its largest hemispherical total is ≤ 0.001; only that last case
//! changes a transmission matrix (the split itself is added back), so it is what is reproduced.
//! Colour: with `CIE-X` and `CIE-Z` blocks Radiance keeps each element's CIE Y and stores its
//! chromaticity (u′, v′) quantised to steps of 1/410 with a dither: `k = floor(410·u′ + r)`,
//! r from the C library's `drand48()` in its unseeded state (two numbers per element, u′ then
//! v′). Found by experiment against the oracle's `rmtxop -ff`: the coloured components are
//! encoded in the order XML `Reflection Back`, `Reflection Front`, `Transmission Back`,
//! `Transmission Front` (Radiance rf, rb, tf, tb), each element of a component from the last
//! stored index (`o·n_in + i`) down to the first, zero elements included. The RGB value is the
//! XYZ → RGB transform (Radiance's standard primaries, equal-energy white) of (x/y·Y, Y,
//! (1−x−y)/y·Y) from the decoded chromaticity; grey Y without colour blocks.

use crate::klems::KlemsBasis;
use crate::model::{Bsdf, Direction, KlemsMatrix, Wavelength};

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
    let rgb2xyz = [
        [m[0][0] * s[0], m[0][1] * s[1], m[0][2] * s[2]],
        [m[1][0] * s[0], m[1][1] * s[1], m[1][2] * s[2]],
        [m[2][0] * s[0], m[2][1] * s[1], m[2][2] * s[2]],
    ];
    inv3(&rgb2xyz)
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

/// Dithered (u′, v′) lattice indices of every element of a coloured component, indexed
/// `o · n_in + i`; `None` where X + 15Y + 3Z is not positive.
fn encode_chroma(
    y: &KlemsMatrix,
    x: &KlemsMatrix,
    z: &KlemsMatrix,
    rng: &mut Drand48,
) -> Vec<Option<(f64, f64)>> {
    let (ni, no) = (y.incident.len(), y.outgoing.len());
    let mut out = vec![None; ni * no];
    for k in (0..ni * no).rev() {
        let (o, i) = (k / ni, k % ni);
        let (cx, cy, cz) = (x.get(o, i), y.get(o, i), z.get(o, i));
        let (r1, r2) = (rng.next_f64(), rng.next_f64());
        let d = cx + 15.0 * cy + 3.0 * cz;
        if d > 0.0 {
            let ub = (4.0 * cx / d * UV_STEPS + r1).floor().clamp(0.0, 255.0);
            let vb = (9.0 * cy / d * UV_STEPS + r2).floor().clamp(0.0, 255.0);
            out[k] = Some((ub, vb));
        }
    }
    out
}

/// Colour value (RGB) of element (o, i) of a component: grey Y, or Y with the component's
/// quantised chromaticity.
struct Component<'a> {
    y: &'a KlemsMatrix,
    chroma: Option<Vec<Option<(f64, f64)>>>,
    m: [[f64; 3]; 3],
}

impl Component<'_> {
    fn rgb(&self, o: usize, i: usize) -> [f64; 3] {
        let y = self.y.get(o, i);
        let Some(chroma) = &self.chroma else {
            return [y; 3];
        };
        let Some((ub, vb)) = chroma[o * self.y.incident.len() + i] else {
            return [y; 3];
        };
        let (u, v) = (ub / UV_STEPS, vb / UV_STEPS);
        let d = 6.0 * u - 16.0 * v + 12.0;
        let (cx, cy) = (9.0 * u / d, 4.0 * v / d);
        if cy <= 0.0 {
            return [y; 3];
        }
        let c = mul3(&self.m, [cx / cy * y, y, (1.0 - cx - cy) / cy * y]);
        [c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)]
    }
}

/// The order in which Radiance encodes the coloured components (rf, rb, tf, tb).
const ENCODE_ORDER: [Direction; 4] = [
    Direction::ReflectionBack,
    Direction::ReflectionFront,
    Direction::TransmissionBack,
    Direction::TransmissionFront,
];

/// Component `d` of `b`, encoding the colour of every coloured component with `rng` (as
/// Radiance's loader does whichever component is asked for).
fn component<'a>(
    b: &'a Bsdf,
    d: Direction,
    rng: &mut Drand48,
) -> Result<Option<Component<'a>>, MatrixError> {
    let mut found = None;
    for dir in ENCODE_ORDER {
        let Some(blk) = b.block(dir, &Wavelength::Visible) else {
            continue;
        };
        let y = match &blk.data {
            crate::model::BlockData::Klems(m) => m,
            crate::model::BlockData::Tree(_) if dir == d => return Err(MatrixError::TensorTree),
            crate::model::BlockData::Tree(_) => continue,
        };
        let x = b.klems(dir, &Wavelength::CieX);
        let z = b.klems(dir, &Wavelength::CieZ);
        let same = |m: Option<&KlemsMatrix>| {
            m.is_none_or(|m| m.incident == y.incident && m.outgoing == y.outgoing)
        };
        if !same(x) || !same(z) {
            if dir == d {
                return Err(MatrixError::ColourBasis(d.xml_name()));
            }
            continue;
        }
        let chroma = match (x, z) {
            (Some(x), Some(z)) => Some(encode_chroma(y, x, z, rng)),
            _ => None,
        };
        if dir == d {
            found = Some(Component {
                y,
                chroma,
                m: xyz_to_rgb_matrix(),
            });
        }
    }
    Ok(found)
}

/// Lambertian value Radiance would split off a matrix (its minimum if > 0.01/π), and whether
/// the remainder is kept (largest hemispherical total of the remainder > 0.001).
pub fn lambertian_split(m: &KlemsMatrix) -> (f64, bool) {
    let min = m.values.iter().copied().fold(f64::INFINITY, f64::min);
    let lamb = if min > 0.01 / std::f64::consts::PI {
        min
    } else {
        0.0
    };
    let keep = (0..m.incident.len()).any(|i| {
        let h: f64 = (0..m.outgoing.len())
            .map(|o| (m.get(o, i) - lamb) * m.outgoing.projected_solid_angle(o).unwrap_or(0.0))
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
    // Radiance encodes every component once on load: both look-ups start from the same state.
    let start = rng.clone();
    let tb = component(b, Direction::TransmissionFront, rng)?;
    let tf = match tb {
        None => component(b, Direction::TransmissionBack, &mut start.clone())?,
        Some(_) => None,
    };
    if let Some(tb) = tb {
        let (lamb, keep) = lambertian_split(tb.y);
        if keep {
            let (ni, no) = (tb.y.incident.len(), tb.y.outgoing.len());
            let lam = tb.y.incident.lambdas();
            let mut t = RgbMatrix::zeros(no, ni);
            for o in 0..no {
                for (i, l) in lam.iter().enumerate() {
                    let v = tb.rgb(o, i);
                    t.data[o * ni + i] = [v[0] * l, v[1] * l, v[2] * l];
                }
            }
            return Ok(t);
        }
        return Ok(lambertian_only(lamb));
    }
    if let Some(tf) = tf {
        let (lamb, keep) = lambertian_split(tf.y);
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
        return Ok(lambertian_only(lamb));
    }
    Ok(lambertian_only(0.0))
}

#[allow(clippy::needless_range_loop)]
fn lambertian_only(value: f64) -> RgbMatrix {
    let full = KlemsBasis::full();
    let lam = full.lambdas();
    let n = full.len();
    let mut t = RgbMatrix::zeros(n, n);
    for r in 0..n {
        for c in 0..n {
            t.data[r * n + c] = [value * lam[c]; 3];
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
    let Some(r) = component(b, d, rng)? else {
        return Ok(None);
    };
    let (ni, no) = (r.y.incident.len(), r.y.outgoing.len());
    let lam = r.y.incident.lambdas();
    let mut m = RgbMatrix::zeros(no, ni);
    for o in 0..no {
        for (i, l) in lam.iter().enumerate() {
            let v = r.rgb(o, i);
            m.data[o * ni + i] = [v[0] * l, v[1] * l, v[2] * l];
        }
    }
    Ok(Some(m))
}
