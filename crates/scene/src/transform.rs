//! Radiance transforms (`-t -rx -ry -rz -s -mx -my -mz -i N`): a 4×4 matrix in the
//! row-vector convention `p' = p·M`, plus the accumulated scale factor (negative when
//! the transform mirrors, which reverses surface orientation).
#![allow(clippy::needless_range_loop)] // matrix code reads best with explicit indices

use anyhow::{anyhow, bail, Result};

/// A 4×4 row-vector matrix.
pub type Mat4 = [[f64; 4]; 4];

/// The identity matrix.
pub const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// `a·b`.
pub fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j];
        }
    }
    m
}

/// A transform: matrix and scale factor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    /// The matrix (row vectors: `p' = p·m`).
    pub m: Mat4,
    /// Overall scale; negative when mirrored.
    pub sca: f64,
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            m: IDENTITY,
            sca: 1.0,
        }
    }
}

impl Transform {
    /// The identity transform.
    pub fn identity() -> Self {
        Transform::default()
    }

    /// True for the identity.
    pub fn is_identity(&self) -> bool {
        self.m == IDENTITY && self.sca == 1.0
    }

    /// True when orientation is reversed (mirror).
    pub fn mirrors(&self) -> bool {
        self.sca < 0.0
    }

    /// `self` followed by `other`.
    pub fn then(&self, other: &Transform) -> Transform {
        Transform {
            m: mul(&self.m, &other.m),
            sca: self.sca * other.sca,
        }
    }

    /// Transforms a point.
    pub fn point(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.m;
        let mut o = [0.0; 3];
        for (i, v) in o.iter_mut().enumerate() {
            *v = p[0] * m[0][i] + p[1] * m[1][i] + p[2] * m[2][i] + m[3][i];
        }
        o
    }

    /// Transforms a direction (no translation; scaled by the transform's scale).
    pub fn vector(&self, v: [f64; 3]) -> [f64; 3] {
        let m = &self.m;
        let mut o = [0.0; 3];
        for (i, x) in o.iter_mut().enumerate() {
            *x = v[0] * m[0][i] + v[1] * m[1][i] + v[2] * m[2][i];
        }
        o
    }

    /// The inverse transform (scale `1/sca`); `None` when the matrix is singular (`-s 0`).
    pub fn inverse(&self) -> Option<Transform> {
        let a = &self.m;
        let lin = [
            [a[0][0], a[0][1], a[0][2]],
            [a[1][0], a[1][1], a[1][2]],
            [a[2][0], a[2][1], a[2][2]],
        ];
        let det = det3(&lin);
        if det == 0.0 || !det.is_finite() || self.sca == 0.0 {
            return None;
        }
        let l = invert3(&lin);
        let mut inv = IDENTITY;
        for (row, lr) in inv.iter_mut().zip(&l) {
            row[..3].copy_from_slice(lr);
        }
        // p = (p' − t)·A⁻¹: the translation row is −t·A⁻¹.
        for j in 0..3 {
            inv[3][j] = -(a[3][0] * inv[0][j] + a[3][1] * inv[1][j] + a[3][2] * inv[2][j]);
        }
        Some(Transform {
            m: inv,
            sca: 1.0 / self.sca,
        })
    }

    /// Parses transform options from the start of `args` (`-t`, `-rx`, `-ry`, `-rz`, `-s`,
    /// `-mx`, `-my`, `-mz`, `-i N`), stopping at the first word that is not one of them.
    /// Returns the transform and the number of words used.
    pub fn parse(args: &[String]) -> Result<(Transform, usize)> {
        let mut total = Transform::identity();
        let mut group = Transform::identity();
        let mut reps: i64 = 1;
        let mut i = 0;
        let num = |k: usize, opt: &str| -> Result<f64> {
            let w = args
                .get(k)
                .ok_or_else(|| anyhow!("transform option {opt} needs a number"))?;
            crate::words::parse_real(w)
                .ok_or_else(|| anyhow!("transform option {opt}: expected a number, got '{w}'"))
        };
        while i < args.len() {
            let a = args[i].as_str();
            let step = match a {
                "-t" => {
                    let mut t = IDENTITY;
                    for k in 0..3 {
                        t[3][k] = num(i + 1 + k, a)?;
                    }
                    group.m = mul(&group.m, &t);
                    4
                }
                "-rx" | "-ry" | "-rz" => {
                    let d = num(i + 1, a)? * (std::f64::consts::PI / 180.0);
                    let (s, c) = (d.sin(), d.cos());
                    let (p, q) = match a {
                        "-rx" => (1, 2),
                        "-ry" => (2, 0),
                        _ => (0, 1),
                    };
                    let mut r = IDENTITY;
                    r[p][p] = c;
                    r[q][q] = c;
                    r[p][q] = s;
                    r[q][p] = -s;
                    group.m = mul(&group.m, &r);
                    2
                }
                "-s" => {
                    let f = num(i + 1, a)?;
                    let mut s = IDENTITY;
                    for k in 0..3 {
                        s[k][k] = f;
                    }
                    group.m = mul(&group.m, &s);
                    group.sca *= f;
                    2
                }
                "-mx" | "-my" | "-mz" => {
                    let k = match a {
                        "-mx" => 0,
                        "-my" => 1,
                        _ => 2,
                    };
                    let mut s = IDENTITY;
                    s[k][k] = -1.0;
                    group.m = mul(&group.m, &s);
                    group.sca = -group.sca;
                    1
                }
                "-i" => {
                    let w = args
                        .get(i + 1)
                        .ok_or_else(|| anyhow!("transform option -i needs a count"))?;
                    let n: i64 = w
                        .parse()
                        .map_err(|_| anyhow!("transform option -i: expected a count, got '{w}'"))?;
                    if n < 0 {
                        bail!("transform option -i: negative count {n}");
                    }
                    total = repeat(&total, &group, reps);
                    group = Transform::identity();
                    reps = n;
                    2
                }
                _ => break,
            };
            i += step;
        }
        total = repeat(&total, &group, reps);
        Ok((total, i))
    }

    /// Parses a whole word list as a transform; any word that is not a transform option is an error.
    pub fn parse_all(args: &[String]) -> Result<Transform> {
        let (t, n) = Transform::parse(args)?;
        if n != args.len() {
            bail!("bad transform option '{}'", args[n]);
        }
        Ok(t)
    }
}

/// Determinant of a 3×3 matrix.
pub(crate) fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Inverse of a 3×3 matrix (adjugate over determinant; the caller checks the determinant).
pub(crate) fn invert3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let d = det3(m);
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            let (a, b) = ((j + 1) % 3, (j + 2) % 3);
            let (c, e) = ((i + 1) % 3, (i + 2) % 3);
            *v = (m[a][c] * m[b][e] - m[a][e] * m[b][c]) / d;
        }
    }
    r
}

/// `total` followed by `group` applied `reps` times, one product at a time (Radiance's
/// order of operations, so the digits are Radiance's). xform's arrays (`-a N` becomes
/// `-i 0`, `-i 1`, … `-i N-1`) repeat the same group ever more often: the last products
/// are remembered and continued, which keeps the digits and makes an array linear in N.
fn repeat(total: &Transform, group: &Transform, reps: i64) -> Transform {
    thread_local! {
        static LAST: std::cell::RefCell<Vec<(Transform, Transform, i64, Transform)>> =
            const { std::cell::RefCell::new(Vec::new()) };
    }
    let (mut t, done) = LAST.with(|c| {
        c.borrow()
            .iter()
            .filter(|(a, g, n, _)| a == total && g == group && *n <= reps)
            .max_by_key(|e| e.2)
            .map_or((*total, 0), |e| (e.3, e.2))
    });
    for _ in done..reps {
        t = t.then(group);
    }
    if reps > 1 {
        LAST.with(|c| {
            let mut c = c.borrow_mut();
            c.retain(|(a, g, _, _)| !(a == total && g == group));
            if c.len() >= 8 {
                c.remove(0);
            }
            c.push((*total, *group, reps, t));
        });
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_undoes_the_transform() {
        let args: Vec<String> = "-rz 30 -t 1 2 3 -s 2 -rx 20 -my"
            .split_whitespace()
            .map(String::from)
            .collect();
        let f = Transform::parse_all(&args).unwrap();
        let b = f.inverse().unwrap();
        assert!((b.sca * f.sca - 1.0).abs() < 1e-15);
        let p = [0.3, -1.7, 2.5];
        let q = b.point(f.point(p));
        let v = b.vector(f.vector(p));
        for k in 0..3 {
            assert!((q[k] - p[k]).abs() < 1e-12, "{q:?}");
            assert!((v[k] - p[k]).abs() < 1e-12, "{v:?}");
        }
        let zero: Vec<String> = ["-s", "0"].iter().map(|s| s.to_string()).collect();
        assert!(Transform::parse_all(&zero).unwrap().inverse().is_none());
    }

    fn w(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn rotations_follow_the_right_hand_rule() {
        let t = Transform::parse_all(&w("-rz 90")).unwrap();
        let p = t.point([1.0, 0.0, 0.0]);
        assert!((p[0]).abs() < 1e-15 && (p[1] - 1.0).abs() < 1e-15);
        let t = Transform::parse_all(&w("-rx 90")).unwrap();
        let p = t.point([0.0, 1.0, 0.0]);
        assert!((p[2] - 1.0).abs() < 1e-15);
        let t = Transform::parse_all(&w("-ry 90")).unwrap();
        let p = t.point([0.0, 0.0, 1.0]);
        assert!((p[0] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn order_scale_mirror_and_repeat() {
        let t = Transform::parse_all(&w("-s 2 -t 1 0 0 -mx")).unwrap();
        assert_eq!(t.point([1.0, 0.0, 0.0]), [-3.0, 0.0, 0.0]);
        assert_eq!(t.sca, -2.0);
        let t = Transform::parse_all(&w("-t 1 0 0 -i 3 -t 0 1 0")).unwrap();
        assert_eq!(t.point([0.0, 0.0, 0.0]), [1.0, 3.0, 0.0]);
        let t = Transform::parse_all(&w("-i 0 -t 0 1 0")).unwrap();
        assert!(t.is_identity());
        assert!(Transform::parse_all(&w("-t 1 0")).is_err());
        assert!(Transform::parse_all(&w("-q")).is_err());
    }
}
