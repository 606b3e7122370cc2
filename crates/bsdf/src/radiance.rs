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
//! Colour: with `CIE-X` and `CIE-Z` blocks the RGB value of each element is the XYZ → RGB
//! transform (Radiance's standard primaries, equal-energy white) of (X, Y, Z); grey otherwise.

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

/// Colour value (RGB) of element (o, i) of a component: grey Y, or XYZ → RGB with X and Z.
struct Component<'a> {
    y: &'a KlemsMatrix,
    x: Option<&'a KlemsMatrix>,
    z: Option<&'a KlemsMatrix>,
    m: [[f64; 3]; 3],
}

impl Component<'_> {
    fn rgb(&self, o: usize, i: usize) -> [f64; 3] {
        let y = self.y.get(o, i);
        match (self.x, self.z) {
            (Some(x), Some(z)) => {
                let c = mul3(&self.m, [x.get(o, i), y, z.get(o, i)]);
                [c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)]
            }
            _ => [y; 3],
        }
    }
}

fn component<'a>(b: &'a Bsdf, d: Direction) -> Result<Option<Component<'a>>, MatrixError> {
    let Some(blk) = b.block(d, &Wavelength::Visible) else {
        return Ok(None);
    };
    let y = match &blk.data {
        crate::model::BlockData::Klems(m) => m,
        crate::model::BlockData::Tree(_) => return Err(MatrixError::TensorTree),
    };
    let x = b.klems(d, &Wavelength::CieX);
    let z = b.klems(d, &Wavelength::CieZ);
    let same = |m: Option<&KlemsMatrix>| {
        m.is_none_or(|m| m.incident == y.incident && m.outgoing == y.outgoing)
    };
    if !same(x) || !same(z) {
        return Err(MatrixError::ColourBasis(d.xml_name()));
    }
    Ok(Some(Component {
        y,
        x,
        z,
        m: xyz_to_rgb_matrix(),
    }))
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

#[allow(clippy::needless_range_loop)] // index arithmetic mirrors the formulas
/// The transmission matrix Radiance's `dctimestep`/`rmtxop` build from this BSDF.
pub fn transmission_matrix(b: &Bsdf) -> Result<RgbMatrix, MatrixError> {
    if let Some(tb) = component(b, Direction::TransmissionFront)? {
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
    if let Some(tf) = component(b, Direction::TransmissionBack)? {
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
    let d = if front {
        Direction::ReflectionBack
    } else {
        Direction::ReflectionFront
    };
    let Some(r) = component(b, d)? else {
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
